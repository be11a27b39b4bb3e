#version 450
// svo-neighbours, one invocation per node: the node's six same-level face neighbours (+x, -x, +y,
// -y, +z, -z), found through the closest common ancestor (svoNeighbour: up the parent links, then
// down along the neighbour cell's bits). SVO_ABSENT where the neighbour cell lies outside the
// volume or has no node (a node on the way down has no children). Every link is found from both
// sides by the same descent, so the links are symmetric: n's +x neighbour has n as its -x one.
#include "common/packing.glsl"
#include "svo/svo_shared.h"

layout(local_size_x = 64) in;
#include "common/invocation.glsl"
layout(std430, binding = SVO_BINDING_NODES) readonly buffer Nodes { SvoNode nodes[]; };
layout(std430, binding = SVO_BINDING_NEIGHBOURS) writeonly buffer Neighbours { uint links[]; };
uniform uint u_nodeCount;
uniform int u_depth;
#include "svo/octree.glsl"

void main() {
  uint n = linearInvocation();
  if (n >= u_nodeCount) return;
  ivec3 c = ivec3(unpackVoxel10(nodes[n].coords));
  int cells = 1 << int(nodes[n].level);
  for (int d = 0; d < 6; ++d) {
    ivec3 o = ivec3(0);
    o[d >> 1] = (d & 1) == 0 ? 1 : -1;
    ivec3 m = c + o;
    uint link = any(lessThan(m, ivec3(0))) || any(greaterThanEqual(m, ivec3(cells))) ? SVO_ABSENT
                                                                                    : svoNeighbour(n, uvec3(c), uvec3(m));
    links[6u * n + uint(d)] = link;
  }
}
