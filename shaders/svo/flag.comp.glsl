#version 450
// svo-build step 1 (flag), one invocation per voxel fragment: descend to the fragment's node at
// level u_level and set its TAG and NON-EMPTY bits with atomicOr (not Basgier's "toggle", which
// cancels when two fragments share a node: source error P12).
#include "common/shared.h"
#include "common/packing.glsl"
#include "svo/svo_shared.h"

layout(local_size_x = 64) in;
// common/invocation.glsl reads gl_WorkGroupSize, so it comes after the layout line.
#include "common/invocation.glsl"
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(std430, binding = SVO_BINDING_NODES) coherent buffer Nodes { SvoNode nodes[]; };
uniform uint u_fragmentCount;
uniform int u_depth;
uniform int u_level;
#include "svo/octree.glsl"

void main() {
  uint i = linearInvocation();
  if (i >= u_fragmentCount) return;
  uvec3 voxel = unpackVoxel10(fragments[i].position);
  uint node = svoFind(voxel >> uint(u_depth - u_level), u_level);
  if (node != SVO_ABSENT) atomicOr(nodes[node].word, SVO_TAG | SVO_NON_EMPTY);
}
