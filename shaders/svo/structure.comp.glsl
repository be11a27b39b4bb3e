#version 450
// The octree's structure as a volume (svo-build's "svo-structure"), one invocation per node of
// level l (u_start, u_count): texel 'its cell' of mip D - l says what the node is: 1 = non-empty,
// 0.6 = tagged for dilation only, 0.3 = an empty sibling (allocated, never subdivided). Texels
// without a node keep the 0 the stage cleared them to.
#include "common/packing.glsl"
#include "svo/svo_shared.h"

layout(local_size_x = 64) in;
// common/invocation.glsl reads gl_WorkGroupSize, so it comes after the layout line.
#include "common/invocation.glsl"
layout(std430, binding = SVO_BINDING_NODES) readonly buffer Nodes { SvoNode nodes[]; };
layout(r8, binding = 0) uniform writeonly image3D u_structure;
uniform uint u_start;
uniform uint u_count;

void main() {
  uint i = linearInvocation();
  if (i >= u_count) return;
  uint n = u_start + i;
  uint word = nodes[n].word;
  float code = (word & SVO_NON_EMPTY) != 0u ? 1.0 : (word & SVO_TAG) != 0u ? 0.6 : 0.3;
  imageStore(u_structure, ivec3(unpackVoxel10(nodes[n].coords)), vec4(code));
}
