// (Included after the layout(local_size_x) declaration.) The mip passes visit only the texels that can be non-empty: one invocation per entry of a list
// of texels (packVoxel10), built per level by mip_blocks.comp.glsl from the voxel fragments or from
// the list of the level below. A texel with no occupied voxel under it keeps the zero its level
// was cleared to, which is what averaging eight empty children gives: the result is the same as
// visiting every texel. On llvmpipe a skipped invocation still costs its whole shader (both sides
// of a branch run), so the empty ones (about nine in ten at level 1 of the Cornell box) are not
// dispatched at all.
#ifndef VOXLAB_MIP_BLOCKS_GLSL
#define VOXLAB_MIP_BLOCKS_GLSL
#include "common/shared.h"
#include "common/packing.glsl"
#include "common/invocation.glsl"
layout(std430, binding = VOXLAB_BINDING_MIP_BLOCKS) readonly buffer MipBlocks { uint mipBlocks[]; };
uniform uint u_blockOffset;  // the level's list starts here
uniform uint u_blockCount;   // its length

// This invocation's texel, or false past the end of the list.
bool listedTexel(out ivec3 texel) {
  uint i = linearInvocation();
  if (i >= u_blockCount) return false;
  texel = ivec3(unpackVoxel10(mipBlocks[u_blockOffset + i]));
  return true;
}
#endif
