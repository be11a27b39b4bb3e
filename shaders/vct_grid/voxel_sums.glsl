// The exact-sum inject's per-voxel scratch (inject.average=exact-sum): each occupied voxel has one
// slot, the index of the fragment that claimed it first (u_owner holds it per voxel, kNoOwner
// where no fragment fell), and the slot holds what all the voxel's fragments add up to. Integer
// sums, so neither the order of the fragments nor which of them claimed the voxel changes a bit of
// the result. The slots live in a buffer sized from the fragment count (one per fragment: every
// claiming fragment is a different one), not from the grid.
#ifndef VOXLAB_VOXEL_SUMS_GLSL
#define VOXLAB_VOXEL_SUMS_GLSL
#include "common/shared.h"

struct VoxelSums {
  uint red;     // fixed-point radiance sums, kFixedPointScale steps per unit
  uint green;
  uint blue;
  uint count;   // fragments added
  uint facing;  // OR of their facing codes (common/facing.glsl)
};
layout(std430, binding = VOXLAB_BINDING_VOXEL_SUMS) VOXLAB_VOXEL_SUMS_ACCESS buffer VoxelSumSlots { VoxelSums slots[]; };
// The occupied voxels, as their slots, in the order they were claimed (not reproducible, and no
// pass depends on it): the resolve and the occlusion fix visit each voxel once through it.
layout(std430, binding = VOXLAB_BINDING_VOXEL_LIST) VOXLAB_VOXEL_SUMS_ACCESS buffer VoxelList {
  uint claimedVoxels;  // entries of the list
  uint claimedSlots[];
};

const uint kNoOwner = 0xffffffffu;       // u_owner of a voxel no fragment claimed
const float kFixedPointScale = 4096.0;   // radiance units per integer step of the sums
#endif
