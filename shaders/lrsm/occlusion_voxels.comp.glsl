#version 450
// Binary occlusion voxels: 1 at every voxel of the fragment list (R8, 1 byte per voxel). Every
// writer of a voxel stores the same value, so plain stores suffice (no atomics).
#include "common/shared.h"
layout(local_size_x = 64) in;
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(r8, binding = 0) uniform writeonly image3D u_voxels;
uniform int u_resolution;
uniform uint u_fragmentCount;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_fragmentCount) return;
  uint key = fragments[i].position;
  ivec3 v = ivec3(key & 1023u, (key >> 10) & 1023u, (key >> 20) & 1023u);
  if (any(greaterThanEqual(v, ivec3(u_resolution)))) return;
  imageStore(u_voxels, v, vec4(1.0));
}
