#version 450
// Exact-sum averaging, second pass (inject.average=exact-sum): one invocation per occupied voxel
// (the list of claimed slots, vct_grid/voxel_sums.glsl) divides the slot's fixed-point sums by the
// fragment count and stores the mean radiance, alpha = min(count, 255) / 255 as in the
// compare-and-swap mode, and the voxel's facing code: each voxel is written once. Built with
// VOXLAB_RESOLVE_FACING_ONLY where nothing wants the averaged grid (the occlusion fix takes the
// means from the slots), it writes the facing codes alone.
#include "common/shared.h"
#include "common/packing.glsl"
// The radiance grids' image format: rgba8 unless the stage builds the program with
// "#define VOXLAB_GRID_FORMAT rgba16f" (voxel.format=rgba16f).
#ifndef VOXLAB_GRID_FORMAT
#define VOXLAB_GRID_FORMAT rgba8
#endif
layout(local_size_x = 64) in;
#include "common/invocation.glsl"
#define VOXLAB_VOXEL_SUMS_ACCESS readonly
#include "vct_grid/voxel_sums.glsl"
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(VOXLAB_GRID_FORMAT, binding = 0) uniform writeonly image3D u_radiance;
layout(r32ui, binding = 5) uniform writeonly uimage3D u_facing;
uniform uint u_voxelCount;  // entries of the voxel list
void main() {
  uint e = linearInvocation();
  if (e >= u_voxelCount) return;
  uint slot = claimedSlots[e];
  ivec3 voxel = ivec3(unpackVoxel10(fragments[slot].position));
  VoxelSums s = slots[slot];
#ifndef VOXLAB_RESOLVE_FACING_ONLY
  float count = float(s.count);
  vec3 sum = vec3(s.red, s.green, s.blue);
  imageStore(u_radiance, voxel, vec4(sum / (count * kFixedPointScale), min(count, 255.0) / 255.0));
#endif
  imageStore(u_facing, voxel, uvec4(s.facing));
}
