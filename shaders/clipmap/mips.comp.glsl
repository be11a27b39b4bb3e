#version 450
// The mip chain of the coarsest clip level, in logical (unrolled) order, every face side by side
// along x (face f of mip m at x in [f n_m, (f + 1) n_m), n_m = N / 2^m): mip 0 copies level
// L-1's faces from their toroidal addresses (texel j = cell o_{L-1} + j), every further mip
// reduces each 2x2x2 block of mip m-1: the isotropic face by the mean, the six
// directional faces by the under operator along their direction (common/anisotropic_mip.glsl, as
// the covered blocks, filter.comp.glsl). It covers the same volume at every mip.
#include "clipmap/clipmap.glsl"
#include "common/anisotropic_mip.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(CLIPMAP_ATLAS_FORMAT, binding = 0) uniform readonly image3D u_atlas;
layout(CLIPMAP_ATLAS_FORMAT, binding = 1) uniform readonly image3D u_source;
layout(CLIPMAP_ATLAS_FORMAT, binding = 2) uniform writeonly image3D u_target;
// CLIPMAP_MIP_COPY 1: mip 0, a copy of the coarsest clip level; 0: mip m from mip m - 1. A define,
// two programs: llvmpipe runs both sides of a branch on a uniform, so mip 0's copy also paid for
// the eight loads and the reduction of the others.
#ifndef CLIPMAP_MIP_COPY
#error "clipmap/mips.comp.glsl needs CLIPMAP_MIP_COPY (clipmap/mips_stages.cpp)"
#endif

void main() {
  ivec3 g = ivec3(gl_GlobalInvocationID);
  ivec3 size = imageSize(u_target);
  if (any(greaterThanEqual(g, size))) return;
  int n = size.y;  // the mip's edge; its x holds the faces side by side
  int face = g.x / n;
  ivec3 j = ivec3(g.x % n, g.y, g.z);
  int last = u_clipLevels - 1;
  vec4 value = vec4(0.0);
  if (CLIPMAP_MIP_COPY == 1) {
    value = imageLoad(u_atlas, atlasTexel(face, last, toroidalAddress(u_clipOrigin[last] + j)));
  } else {
    vec4 child[8];
    for (int i = 0; i < 8; ++i)
      child[i] = imageLoad(u_source, ivec3(face * 2 * n, 0, 0) + 2 * j + ivec3(i & 1, (i >> 1) & 1, i >> 2));
    if (face == 0) {
      for (int i = 0; i < 8; ++i) value += child[i];
      value *= 0.125;
    } else {
      value = anisotropicReduce(child, face - 1);
    }
  }
  imageStore(u_target, g, value);
}
