#version 450
// The dense view of one octree level, one invocation per node of that level (u_start, u_count):
// the node's centre value goes to texel 'its cell' of mip D - level. The caller clears the mip
// first, so texels without a node stay 0. A scatter from the level's nodes instead of a descent
// per texel: at 256^3 the finest level has about 1 M nodes against 16.8 M texels.
#include "common/packing.glsl"
#include "svo/svo_shared.h"

layout(local_size_x = 64) in;
// common/invocation.glsl reads gl_WorkGroupSize, so it comes after the layout line.
#include "common/invocation.glsl"
layout(std430, binding = SVO_BINDING_NODES) readonly buffer Nodes { SvoNode nodes[]; };
layout(std430, binding = SVO_BINDING_VALUES) readonly buffer Values { vec4 values[]; };
// The bricks' format: rgba8 unless the stage defines VOXLAB_GRID_FORMAT (voxel.format=rgba16f).
#ifndef VOXLAB_GRID_FORMAT
#define VOXLAB_GRID_FORMAT rgba8
#endif
layout(VOXLAB_GRID_FORMAT, binding = 0) uniform writeonly image3D u_dense;
uniform uint u_start;
uniform uint u_count;

void main() {
  uint i = linearInvocation();
  if (i >= u_count) return;
  uint n = u_start + i;
  imageStore(u_dense, ivec3(unpackVoxel10(nodes[n].coords)), values[n]);
}
