#version 450
// Guard texels of every block (face, level) of the atlas: guard -1 holds physical N-1 and guard
// N holds physical 0 on every axis, edges and corners included, so a trilinear fetch anywhere in
// [0, N) physical reads the wrapped neighbour across the seam (and never the next block).
#include "clipmap/clipmap.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(std430, binding = CLIPMAP_BINDING_COUNTERS) buffer Counters { uint counters[]; };
layout(CLIPMAP_ATLAS_FORMAT, binding = 0) uniform image3D u_atlas;

void main() {
  ivec3 texel = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(texel, imageSize(u_atlas)))) return;
  int b = u_clipN + 2;
  ivec3 local = texel % b - 1;  // -1 .. N
  if (all(greaterThanEqual(local, ivec3(0))) && all(lessThan(local, ivec3(u_clipN)))) return;
  ivec3 source = texel - local + ((local + u_clipN) & ivec3(u_clipN - 1));
  imageStore(u_atlas, texel, imageLoad(u_atlas, source));
  atomicAdd(counters[5 * (texel.y / b) + 4], 1u);
}
