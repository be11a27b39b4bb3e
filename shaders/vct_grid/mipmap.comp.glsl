#version 450
// Isotropic mipmapping: each texel of level L is built from its 8 children at level L-1.
//  - u_opacityRule 0 ("isotropic"): the average of the children (premultiplied radiance and
//    opacity alike). A one-voxel wall averaged with the empty space beside it keeps half its
//    opacity per level, so wide cones see through the coarse levels of thin walls.
//  - u_opacityRule 1 ("max-opacity"): opacity is that of the block seen along its most opaque
//    axis: for each axis, the two children of each of the four columns along it are composited
//    (a = a0 + (1 - a0) a1, the same either way round), the four columns averaged, and the
//    largest of the three axes kept. A wall seen face-on stays opaque at every level (as with
//    anisotropic mips); seen edge-on it is too opaque (1 instead of the half it covers), which
//    the cone sees only when it runs along the wall. Radiance keeps the isotropic colour (the
//    opacity-weighted mean of the children) at the new opacity.
// The radiance grids' image format: rgba8 unless the stage builds the program with
// "#define VOXLAB_GRID_FORMAT rgba16f" (voxel.format=rgba16f).
#ifndef VOXLAB_GRID_FORMAT
#define VOXLAB_GRID_FORMAT rgba8
#endif
layout(local_size_x = 64) in;  // one invocation per listed texel (vct_grid/mip_blocks.glsl)
#include "vct_grid/mip_blocks.glsl"
layout(binding = 0) uniform sampler3D u_source;   // the same texture, read at level u_sourceLevel
layout(VOXLAB_GRID_FORMAT, binding = 0) uniform writeonly image3D u_target;
uniform int u_sourceLevel;
uniform int u_opacityRule;
void main() {
  ivec3 v;
  if (!listedTexel(v)) return;
  vec4 child[8];
  vec4 sum = vec4(0.0);
  for (int i = 0; i < 8; ++i) {
    child[i] = texelFetch(u_source, 2 * v + ivec3(i & 1, (i >> 1) & 1, (i >> 2) & 1), u_sourceLevel);
    sum += child[i];
  }
  if (u_opacityRule == 0 || sum.a <= 0.0) {
    imageStore(u_target, v, sum * 0.125);
    return;
  }
  // Child i sits at offset (i & 1, (i >> 1) & 1, (i >> 2) & 1): along axis k its column partner
  // is i ^ (1 << k).
  float opacity = 0.0;
  for (int k = 0; k < 3; ++k) {
    float columns = 0.0;
    for (int i = 0; i < 8; ++i) {
      if ((i & (1 << k)) != 0) continue;
      float a0 = child[i].a, a1 = child[i | (1 << k)].a;
      columns += a0 + (1.0 - a0) * a1;
    }
    opacity = max(opacity, 0.25 * columns);
  }
  imageStore(u_target, v, vec4(sum.rgb / sum.a * opacity, opacity));
}
