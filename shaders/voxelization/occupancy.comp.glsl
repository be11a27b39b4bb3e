#version 450
// Occupancy from the voxel fragment list, one invocation per fragment: count the fragments of
// each voxel with an image atomic; the invocation that finds a voxel empty counts it as unique,
// so duplicates = fragments - unique voxels.
#include "common/shared.h"
#include "common/packing.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(std430, binding = VOXLAB_BINDING_CLASS_COUNTS) buffer UniqueCount { uint uniqueVoxels; };
layout(binding = 0, r32ui) uniform uimage3D u_occupancy;
uniform uint u_fragmentCount;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_fragmentCount) return;
  ivec3 voxel = ivec3(unpackVoxel10(fragments[i].position));
  uint before = imageAtomicAdd(u_occupancy, voxel, 1u);
  if (before == 0u) atomicAdd(uniqueVoxels, 1u);
}
