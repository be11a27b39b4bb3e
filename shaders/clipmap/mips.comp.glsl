#version 450
// The mip chain of the coarsest clip level, in logical (unrolled) order: mode 0 copies level
// L-1's isotropic face from its toroidal addresses into mip 0 (texel j = cell o_{L-1} + j),
// mode 1 averages each 2x2x2 block of mip m-1 into mip m. It covers the same volume at every mip.
#include "clipmap/clipmap.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(CLIPMAP_ATLAS_FORMAT, binding = 0) uniform readonly image3D u_atlas;
layout(CLIPMAP_ATLAS_FORMAT, binding = 1) uniform readonly image3D u_source;
layout(CLIPMAP_ATLAS_FORMAT, binding = 2) uniform writeonly image3D u_target;
uniform int u_mode;

void main() {
  ivec3 j = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(j, imageSize(u_target)))) return;
  int last = u_clipLevels - 1;
  vec4 value = vec4(0.0);
  if (u_mode == 0) {
    value = imageLoad(u_atlas, atlasTexel(0, last, toroidalAddress(u_clipOrigin[last] + j)));
  } else {
    for (int i = 0; i < 8; ++i) value += imageLoad(u_source, 2 * j + ivec3(i & 1, (i >> 1) & 1, i >> 2));
    value *= 0.125;
  }
  imageStore(u_target, j, value);
}
