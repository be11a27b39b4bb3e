#version 450
// The texels of the next mip level that can be non-empty (vct_grid/mip_blocks.glsl): the parents
// of the voxel fragments' voxels (program built with "#define VOXLAB_BLOCKS_FROM_FRAGMENTS"), or
// of the previous level's list. Each parent is listed once: the first child to set its bit in
// u_occupied (cleared before the first level) appends it.
#include "common/shared.h"
#include "common/packing.glsl"
layout(local_size_x = 64) in;
#include "common/invocation.glsl"
#ifdef VOXLAB_BLOCKS_FROM_FRAGMENTS
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
#endif
layout(std430, binding = VOXLAB_BINDING_MIP_BLOCKS) buffer MipBlocks { uint mipBlocks[]; };
layout(std430, binding = VOXLAB_BINDING_MIP_BLOCK_COUNT) buffer MipBlockCount { uint appended; };
layout(r32ui, binding = 0) uniform uimage3D u_occupied;  // the level of the parents
uniform uint u_sourceCount;   // fragments, or entries of the previous list
uniform uint u_sourceOffset;  // the previous list's first entry
uniform uint u_targetOffset;  // where this list starts
void main() {
  uint i = linearInvocation();
  if (i >= u_sourceCount) return;
#ifdef VOXLAB_BLOCKS_FROM_FRAGMENTS
  uvec3 child = unpackVoxel10(fragments[i].position);
#else
  uvec3 child = unpackVoxel10(mipBlocks[u_sourceOffset + i]);
#endif
  uvec3 parent = child >> 1u;
  if (imageAtomicOr(u_occupied, ivec3(parent), 1u) != 0u) return;
  mipBlocks[u_targetOffset + atomicAdd(appended, 1u)] = packVoxel10(parent);
}
