#version 450
// Exact-sum averaging, second pass (inject.average=exact-sum): one invocation per voxel fragment
// divides its voxel's fixed-point sums by the fragment count and stores the mean radiance, alpha =
// min(count, 255) / 255 as in the compare-and-swap mode. Fragments of one voxel all store the
// same value, so the order does not matter.
#include "common/shared.h"
#include "common/packing.glsl"
// The radiance grids' image format: rgba8 unless the stage builds the program with
// "#define VOXLAB_GRID_FORMAT rgba16f" (voxel.format=rgba16f).
#ifndef VOXLAB_GRID_FORMAT
#define VOXLAB_GRID_FORMAT rgba8
#endif
layout(local_size_x = 64) in;
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(r32ui, binding = 1) uniform readonly uimage3D u_sumR;
layout(r32ui, binding = 2) uniform readonly uimage3D u_sumG;
layout(r32ui, binding = 3) uniform readonly uimage3D u_sumB;
layout(r32ui, binding = 4) uniform readonly uimage3D u_count;
layout(VOXLAB_GRID_FORMAT, binding = 0) uniform writeonly image3D u_radiance;
uniform uint u_fragmentCount;
const float kFixedPointScale = 4096.0;  // as in inject.comp.glsl
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_fragmentCount) return;
  ivec3 voxel = ivec3(unpackVoxel10(fragments[i].position));
  float count = float(imageLoad(u_count, voxel).r);
  vec3 sum = vec3(imageLoad(u_sumR, voxel).r, imageLoad(u_sumG, voxel).r, imageLoad(u_sumB, voxel).r);
  imageStore(u_radiance, voxel, vec4(sum / (count * kFixedPointScale), min(count, 255.0) / 255.0));
}
