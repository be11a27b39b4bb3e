#version 450
// Occlusion fix: while averaging, alpha counted fragments; set it to 1 in every non-empty voxel so
// a voxel is fully opaque to cones. The target was cleared to zero, so only the occupied voxels
// are visited (~1e5 instead of resolution^3):
//  - with exact sums, one invocation per entry of the inject stage's voxel list: the voxel's mean
//    radiance again from its slot (vct_grid/voxel_sums.glsl), the value the resolve stored, so
//    the texel gets the same bits, without reading the injected grid back;
//  - with compare-and-swap averaging (program built with "#define VOXLAB_OCCLUSION_FROM_GRID"),
//    one invocation per voxel fragment, copying its voxel of the injected grid.
#include "common/shared.h"
#include "common/packing.glsl"
// The radiance grids' image format: rgba8 unless the stage builds the program with
// "#define VOXLAB_GRID_FORMAT rgba16f" (voxel.format=rgba16f).
#ifndef VOXLAB_GRID_FORMAT
#define VOXLAB_GRID_FORMAT rgba8
#endif
layout(local_size_x = 64) in;
#include "common/invocation.glsl"
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(VOXLAB_GRID_FORMAT, binding = 0) uniform writeonly image3D u_opaque;
uniform uint u_itemCount;  // voxel list entries, or fragments (VOXLAB_OCCLUSION_FROM_GRID)
#ifdef VOXLAB_OCCLUSION_FROM_GRID
layout(binding = 0) uniform sampler3D u_injected;
void main() {
  uint i = linearInvocation();
  if (i >= u_itemCount) return;
  ivec3 v = ivec3(unpackVoxel10(fragments[i].position));
  vec4 c = texelFetch(u_injected, v, 0);
  if (c.a > 0.0) imageStore(u_opaque, v, vec4(c.rgb, 1.0));
}
#else
#define VOXLAB_VOXEL_SUMS_ACCESS readonly
#include "vct_grid/voxel_sums.glsl"
void main() {
  uint e = linearInvocation();
  if (e >= u_itemCount) return;
  uint slot = claimedSlots[e];
  VoxelSums s = slots[slot];
  vec3 sum = vec3(s.red, s.green, s.blue);
  imageStore(u_opaque, ivec3(unpackVoxel10(fragments[slot].position)), vec4(sum / (float(s.count) * kFixedPointScale), 1.0));
}
#endif
