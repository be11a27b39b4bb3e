#version 450
// Per voxel of the fragment list: an albedo and a normal for path vertices the RSM does not see
// (seed 000 section 3.2.4: "normal and BRDF from the 3D voxel texture"). Each is an atomic max of
// the packed RGBA8 value over the voxel's fragments, so the result does not depend on the order
// fragments arrive in (for a voxel shared by surfaces it is one of theirs, not an average).
#include "common/shared.h"
#include "common/packing.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(r32ui, binding = 0) uniform uimage3D u_albedo;  // r32ui view of RGBA8: linear albedo, a = 1
layout(r32ui, binding = 1) uniform uimage3D u_normal;  // r32ui view of RGBA8: n * 0.5 + 0.5, a = 1
uniform uint u_fragmentCount;
uniform int u_resolution;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_fragmentCount) return;
  uvec3 v = unpackVoxel10(fragments[i].position);
  if (any(greaterThanEqual(v, uvec3(u_resolution)))) return;
  vec4 a = unpackUnorm4x8(fragments[i].albedo);
  vec3 n = unpackSnorm4x8(fragments[i].normal).xyz;
  n = n / max(length(n), 1e-6);
  imageAtomicMax(u_albedo, ivec3(v), packUnorm4x8(vec4(a.rgb, 1.0)));
  imageAtomicMax(u_normal, ivec3(v), packUnorm4x8(vec4(n * 0.5 + 0.5, 1.0)));
}
