#version 450
// svo-bricks, one invocation per node. u_pass 0: count the tagged nodes of each work group of 64
// (the CPU makes exclusive prefix sums of them). u_pass 1: every tagged node (non-empty, or
// dilated) takes the 3x3x3 brick (Layout N: node-centred, borders included) whose number is 1 +
// its rank among the tagged nodes (brick 0 is the reserved all-zero brick; ranks instead of an
// atomic counter keep the pool identical on every run), after checking the pool's capacity. Texel t in {0,1,2}^3 lies at
// node.min + t * size / 2; it gets the mean of the centre values of the 1, 2, 4 or 8 same-level
// cells that share that point, found by position (a gather: exact where the separable x, y, z
// transfer of Basgier and Gomes is not, source error P3; absent cells count 0; cells beyond the
// volume are clamped to the edge, as vct-grid's CLAMP_TO_EDGE sampling is). Trilinear filtering
// inside the brick then reproduces the dense grid's trilinear sample exactly inside the node.
#include "common/packing.glsl"
#include "svo/svo_shared.h"

layout(local_size_x = 64) in;
layout(std430, binding = SVO_BINDING_NODES) readonly buffer Nodes { SvoNode nodes[]; };
layout(std430, binding = SVO_BINDING_VALUES) readonly buffer Values { vec4 values[]; };
layout(std430, binding = SVO_BINDING_COUNTERS) coherent buffer Counters { uint counters[]; };
layout(std430, binding = SVO_BINDING_BRICK_INDEX) writeonly buffer BrickIndex { uint brickIndex[]; };
layout(std430, binding = SVO_BINDING_GROUPS) coherent buffer Groups { uint groups[]; };
layout(rgba8, binding = 0) uniform writeonly image3D u_brickPool;
uniform uint u_nodeCount;
uniform uint u_brickCapacity;  // bricks the pool holds, the zero brick included
uniform ivec3 u_bricksPerAxis;
uniform int u_depth;
uniform int u_pass;
#include "svo/octree.glsl"

ivec3 brickOrigin(uint b) {
  uint bx = uint(u_bricksPerAxis.x), by = uint(u_bricksPerAxis.y);
  return 3 * ivec3(b % bx, (b / bx) % by, b / (bx * by));
}

void main() {
  uint n = gl_GlobalInvocationID.x;
  if (n >= u_nodeCount) return;
  bool tagged = (nodes[n].word & SVO_TAG) != 0u;
  if (u_pass == 0) {
    if (tagged) {
      atomicAdd(groups[gl_WorkGroupID.x], 1u);
      atomicAdd(counters[SVO_COUNTER_BRICKS], 1u);
    }
    return;
  }
  if (!tagged) { brickIndex[n] = 0u; return; }
  uint rank = groups[gl_WorkGroupID.x];
  for (uint m = gl_WorkGroupID.x * 64u; m < n; ++m)
    if ((nodes[m].word & SVO_TAG) != 0u) ++rank;
  uint brick = 1u + rank;
  if (brick >= u_brickCapacity) {
    atomicMax(counters[SVO_COUNTER_OVERFLOW], 1u);
    brickIndex[n] = 0u;
    return;
  }
  brickIndex[n] = brick;
  int level = int(nodes[n].level);
  ivec3 c = ivec3(unpackVoxel10(nodes[n].coords));
  int cells = 1 << level;
  vec4 around[27];  // centre values of the 3x3x3 same-level cells around the node (clamped)
  for (int k = 0; k < 27; ++k) {
    ivec3 m = clamp(c + ivec3(k % 3, (k / 3) % 3, k / 9) - 1, ivec3(0), ivec3(cells - 1));
    uint other = svoNeighbour(n, uvec3(c), uvec3(m));
    around[k] = other == SVO_ABSENT ? vec4(0.0) : values[other];
  }
  ivec3 origin = brickOrigin(brick);
  for (int t = 0; t < 27; ++t) {
    ivec3 tx = ivec3(t % 3, (t / 3) % 3, t / 9);
    // Cells sharing the texel's point, per axis: texel 0 -> offsets {-1, 0}, 1 -> {0}, 2 -> {0, +1}.
    ivec3 lo = min(tx - 1, ivec3(0)), hi = max(tx - 1, ivec3(0));
    vec4 sum = vec4(0.0);
    float count = 0.0;
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
          sum += around[(x + 1) + 3 * (y + 1) + 9 * (z + 1)];
          count += 1.0;
        }
    imageStore(u_brickPool, origin + tx, sum / count);
  }
}
