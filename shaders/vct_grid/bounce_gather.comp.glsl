#version 450
// Bounce gather (vct-grid/bounce), one invocation per voxel fragment: the fragment reflects what
// its diffuse cones gather from the previous bounce's grid, albedo * sum_i w_i L_i (the weights sum
// to 1, as in cone_trace.comp.glsl), and adds it in fixed point (1/4096 steps, as the injection's
// exact sums) to its voxel's sums with a count; bounce_resolve.comp.glsl divides. Integer sums do
// not depend on the order of the fragments.
#include "common/shared.h"
#include "common/voxel_space.glsl"
#include "common/packing.glsl"
#include "common/cone_trace.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(r32ui, binding = 1) uniform uimage3D u_sumR;
layout(r32ui, binding = 2) uniform uimage3D u_sumG;
layout(r32ui, binding = 3) uniform uimage3D u_sumB;
layout(r32ui, binding = 4) uniform uimage3D u_count;
// Totals over the stage: cone samples taken, volume fetches.
layout(std430, binding = VOXLAB_BINDING_CONE_TRACE_COUNTS) buffer BounceCounts { uint bounceCounts[2]; };
uniform uint u_fragmentCount;
uniform int u_coneCount;
uniform vec4 u_cones[VOXLAB_MAX_CONES];  // xyz: direction in tangent space (z = normal), w: weight
uniform float u_aperture;                // radians
uniform float u_startOffset;             // metres from the voxel centre, along the normal
uniform float u_maxDistance;             // metres
uniform float u_maxRadiance;             // 1 for RGBA8 grids, higher for RGBA16F
const float kFixedPointScale = 4096.0;   // as in inject.comp.glsl

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_fragmentCount) return;
  VoxelFragment f = fragments[i];
  ivec3 voxel = ivec3(unpackVoxel10(f.position));
  vec3 albedo = unpackUnorm4x8(f.albedo).rgb;
  vec3 n = normalize(unpackSnorm4x8(f.normal).xyz);
  vec3 origin = voxelToWorld(vec3(voxel) + 0.5) + n * u_startOffset;
  vec3 t = normalize(abs(n.y) < 0.9 ? cross(n, vec3(0, 1, 0)) : cross(n, vec3(1, 0, 0)));
  vec3 b = cross(n, t);
  vec3 incoming = vec3(0.0);
  for (int c = 0; c < u_coneCount; ++c) {
    vec3 d = normalize(u_cones[c].x * t + u_cones[c].y * b + u_cones[c].z * n);
    ConeResult r = traceRadianceCone(origin, d, u_aperture, u_voxelSize, u_maxDistance, c, false);
    incoming += u_cones[c].w * r.radiance;
  }
  vec3 reflected = clamp(albedo * incoming, 0.0, u_maxRadiance);
  uvec3 fixedPoint = uvec3(reflected * kFixedPointScale + 0.5);
  imageAtomicAdd(u_sumR, voxel, fixedPoint.r);
  imageAtomicAdd(u_sumG, voxel, fixedPoint.g);
  imageAtomicAdd(u_sumB, voxel, fixedPoint.b);
  imageAtomicAdd(u_count, voxel, 1u);
  atomicAdd(bounceCounts[0], g_samples);
  atomicAdd(bounceCounts[1], g_fetches);
}
