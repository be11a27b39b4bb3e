#version 450
// Guard texels of every block (face, level) of the atlas: guard -1 holds physical N-1 and guard
// N holds physical 0 on every axis, edges and corners included, so a trilinear fetch anywhere in
// [0, N) physical reads the wrapped neighbour across the seam (and never the next block).
// One invocation per guard texel, not per atlas texel: a block of B = N + 2 texels a side has
// B^3 - N^3 = 2 (B^2 + B N + N^2) guards, numbered shell by shell: the two z slabs (B x B each),
// then the two y slabs of the rows z in [0, N) (B x N), then the two x slabs of the rest (N x N).
// (A dispatch over the whole atlas left 86 % of its invocations nothing to do at N = 64.)
#include "clipmap/clipmap.glsl"
layout(local_size_x = 64) in;
// common/invocation.glsl reads gl_WorkGroupSize, so it comes after the layout line.
#include "common/invocation.glsl"
layout(std430, binding = CLIPMAP_BINDING_COUNTERS) buffer Counters { uint counters[]; };
layout(CLIPMAP_ATLAS_FORMAT, binding = 0) uniform image3D u_atlas;

// Guard s (0 <= s < 2 (B^2 + B N + N^2)) of a block, as a local coordinate in -1 .. N.
ivec3 guardLocal(int s, int n) {
  int b = n + 2;
  if (s < 2 * b * b) {
    int rest = s % (b * b);
    return ivec3(rest % b - 1, rest / b - 1, s < b * b ? -1 : n);
  }
  s -= 2 * b * b;
  if (s < 2 * b * n) {
    int rest = s % (b * n);
    return ivec3(rest % b - 1, s < b * n ? -1 : n, rest / b);
  }
  s -= 2 * b * n;
  int rest = s % (n * n);
  return ivec3(s < n * n ? -1 : n, rest % n, rest / n);
}

void main() {
  int n = u_clipN, b = n + 2;
  int perBlock = 2 * (b * b + b * n + n * n);
  ivec3 size = imageSize(u_atlas);
  int blocksX = size.x / b, blocks = blocksX * (size.y / b);
  uint i = linearInvocation();
  if (i >= uint(blocks * perBlock)) return;
  int block = int(i) / perBlock;
  ivec3 local = guardLocal(int(i) % perBlock, n);
  ivec3 origin = ivec3((block % blocksX) * b, (block / blocksX) * b, 0);
  ivec3 texel = origin + local + 1;
  ivec3 source = origin + ((local + n) & ivec3(n - 1)) + 1;
  imageStore(u_atlas, texel, imageLoad(u_atlas, source));
  atomicAdd(counters[5 * (block / blocksX) + 4], 1u);
}
