#version 450
// Counts the fragments of every voxel of the fragment list (one per triangle touching the voxel),
// so that the fragments of one voxel share its surface area (bin.comp.glsl, inject_fragments).
// atomicAdd of integers: the counts do not depend on the order of the fragments.
#include "common/shared.h"
#include "common/voxel_space.glsl"
#include "common/packing.glsl"
#include "lpv/lpv_shared.h"
layout(local_size_x = 64) in;
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(std430, binding = LPV_BINDING_VOXEL_FRAGMENTS) buffer Counts { uint counts[]; };
uniform uint u_fragmentCount;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_fragmentCount) return;
  uvec3 v = unpackVoxel10(fragments[i].position);
  atomicAdd(counts[(v.z * uint(u_resolution) + v.y) * uint(u_resolution) + v.x], 1u);
}
