#version 450
// svo-pick, one invocation: the node of level u_level at cell u_cell (the probe), its flags,
// children, neighbour links, brick and the brick's 27 texels, for the viewer's picked-node view.
#include "common/packing.glsl"
#include "svo/svo_shared.h"

layout(local_size_x = 1) in;
layout(std430, binding = SVO_BINDING_NODES) readonly buffer Nodes { SvoNode nodes[]; };
layout(std430, binding = SVO_BINDING_NEIGHBOURS) readonly buffer Neighbours { uint links[]; };
layout(std430, binding = SVO_BINDING_BRICK_INDEX) readonly buffer BrickIndex { uint brickIndex[]; };
layout(std430, binding = SVO_BINDING_PICKED) writeonly buffer Picked { SvoPickedNode picked; };
layout(std430, binding = SVO_BINDING_BRICK_SCALES) readonly buffer BrickScales { float brickScales[]; };  // 1 unless HDR
layout(binding = 0) uniform sampler3D u_brickPool;
uniform ivec3 u_cell;
uniform int u_level;
uniform int u_depth;
uniform ivec3 u_bricksPerAxis;
#include "svo/octree.glsl"

void main() {
  uint n = svoFind(uvec3(u_cell), u_level);
  picked.node = n;
  picked.level = uint(u_level);
  picked.coords = packVoxel10(uvec3(u_cell));
  picked.word = n == SVO_ABSENT ? 0u : nodes[n].word;
  uint first = n == SVO_ABSENT ? 0u : nodes[n].word & SVO_CHILD_MASK;
  for (uint k = 0u; k < 8u; ++k) picked.children[k] = first == 0u ? SVO_ABSENT : first + k;
  for (int d = 0; d < 6; ++d) picked.neighbours[d] = n == SVO_ABSENT ? SVO_ABSENT : links[6u * n + uint(d)];
  uint b = n == SVO_ABSENT ? 0u : brickIndex[n];
  picked.brick = b;
  picked.pad = 0u;
  uint bx = uint(u_bricksPerAxis.x), by = uint(u_bricksPerAxis.y);
  ivec3 origin = 3 * ivec3(b % bx, (b / bx) % by, b / (bx * by));
  for (int t = 0; t < 27; ++t) {
    vec4 v = b == 0u ? vec4(0.0) : texelFetch(u_brickPool, origin + ivec3(t % 3, (t / 3) % 3, t / 9), 0);
    v.rgb *= b == 0u ? 0.0 : brickScales[8u * b];
    for (int c = 0; c < 4; ++c) picked.texels[4 * t + c] = v[c];
  }
}
