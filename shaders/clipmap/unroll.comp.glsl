#version 450
// Every level in logical order (levels along y): texel (x, k N + y, z) = cell o_k + (x, y, z) of
// level k, read from its toroidal address in the atlas (face u_face). Side by side with the
// atlas, it shows where the physical seam cuts the region.
#include "clipmap/clipmap.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(CLIPMAP_ATLAS_FORMAT, binding = 0) uniform readonly image3D u_atlas;
layout(CLIPMAP_ATLAS_FORMAT, binding = 1) uniform writeonly image3D u_logical;
uniform int u_face;

void main() {
  ivec3 g = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(g, imageSize(u_logical)))) return;
  int k = g.y / u_clipN;
  ivec3 j = ivec3(g.x, g.y % u_clipN, g.z);
  imageStore(u_logical, g, imageLoad(u_atlas, atlasTexel(u_face, k, toroidalAddress(u_clipOrigin[k] + j))));
}
