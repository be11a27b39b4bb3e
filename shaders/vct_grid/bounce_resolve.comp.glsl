#version 450
// Bounce resolve (vct-grid/bounce), one invocation per voxel fragment: level 0 of the next
// bounce's grid = the injected radiance (radiance-opaque, alpha 1) + the mean of what the voxel's
// fragments reflected (bounce_gather.comp.glsl's sums over the count). Clamped at u_maxRadiance
// (RGBA8 grids: 1). Fragments of one voxel all store the same value.
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
layout(r32ui, binding = 1) uniform readonly uimage3D u_sumR;
layout(r32ui, binding = 2) uniform readonly uimage3D u_sumG;
layout(r32ui, binding = 3) uniform readonly uimage3D u_sumB;
layout(r32ui, binding = 4) uniform readonly uimage3D u_count;
layout(VOXLAB_GRID_FORMAT, binding = 0) uniform writeonly image3D u_radiance;
uniform uint u_fragmentCount;
uniform float u_maxRadiance;  // 1 for RGBA8 grids (they clamp anyway), higher for RGBA16F
const float kFixedPointScale = 4096.0;  // as in bounce_gather.comp.glsl
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_fragmentCount) return;
  ivec3 voxel = ivec3(unpackVoxel10(fragments[i].position));
  float count = float(imageLoad(u_count, voxel).r);
  vec3 sum = vec3(imageLoad(u_sumR, voxel).r, imageLoad(u_sumG, voxel).r, imageLoad(u_sumB, voxel).r);
  vec4 injected = texelFetch(u_injected, voxel, 0);
  imageStore(u_radiance, voxel, vec4(min(injected.rgb + sum / (count * kFixedPointScale), u_maxRadiance), injected.a));
}
