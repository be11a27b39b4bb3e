#version 450
// Occlusion fix: while averaging, alpha counted fragments; set it to 1 in every non-empty voxel so
// a voxel is fully opaque to cones. Runs once per voxel fragment (only those voxels can be
// non-empty; the target was cleared to zero), so it visits ~1e5 voxels instead of resolution^3.
#include "common/shared.h"
#include "common/packing.glsl"
// The radiance grids' image format: rgba8 unless the stage builds the program with
// "#define VOXLAB_GRID_FORMAT rgba16f" (voxel.format=rgba16f).
#ifndef VOXLAB_GRID_FORMAT
#define VOXLAB_GRID_FORMAT rgba8
#endif
layout(local_size_x = 64) in;
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(binding = 0) uniform sampler3D u_injected;
layout(VOXLAB_GRID_FORMAT, binding = 0) uniform writeonly image3D u_opaque;
uniform uint u_fragmentCount;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_fragmentCount) return;
  ivec3 v = ivec3(unpackVoxel10(fragments[i].position));
  vec4 c = texelFetch(u_injected, v, 0);
  if (c.a > 0.0) imageStore(u_opaque, v, vec4(c.rgb, 1.0));
}
