#version 450
// Light injection, one invocation per voxel fragment: Lambertian direct light from the scene's
// light (shadow-mapped), plus emission, averaged into the voxel with a compare-and-swap loop on
// the r32ui view of the RGBA8 grid. While averaging, alpha holds how many fragments have been
// averaged in (saturating at 255: later fragments are ignored); the occlusion fix stage then
// sets alpha to 1 in every non-empty voxel.
#include "common/shared.h"
#include "common/voxel_space.glsl"
#include "common/packing.glsl"
#include "common/lights.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(r32ui, binding = 0) uniform coherent uimage3D u_radianceAtomic;
layout(binding = 2) uniform sampler2D u_shadowMap;
uniform uint u_fragmentCount;
uniform int u_mode;               // 0 = direct light, 1 = uniform radiance (furnace tests)
uniform vec3 u_uniformRadiance;
const float PI = 3.14159265358979;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_fragmentCount) return;
  VoxelFragment f = fragments[i];
  ivec3 voxel = ivec3(unpackVoxel10(f.position));
  vec3 albedo = unpackUnorm4x8(f.albedo).rgb;
  vec3 n = normalize(unpackSnorm4x8(f.normal).xyz);
  vec3 radiance;
  if (u_mode == 1) {
    radiance = u_uniformRadiance;
  } else {
    vec3 p = voxelToWorld(vec3(voxel) + 0.5);
    vec3 toLight; float dist;
    lightDirection(p, toLight, dist);
    float cosine = max(dot(n, toLight), 0.0);
    vec3 irradiance = lightIrradiance(p) * cosine * shadowVisibility(u_shadowMap, p, n);
    radiance = albedo / PI * irradiance + unpackUnorm4x8(f.emission).rgb;
  }
  radiance = clamp(radiance, 0.0, 1.0);

  uint expected = 0u;
  uint desired = packUnorm4x8(vec4(radiance, 1.0 / 255.0));
  for (int attempt = 0; attempt < 512; ++attempt) {
    uint seen = imageAtomicCompSwap(u_radianceAtomic, voxel, expected, desired);
    if (seen == expected) break;
    expected = seen;
    vec4 previous = unpackUnorm4x8(seen);
    float count = floor(previous.a * 255.0 + 0.5);
    if (count >= 255.0) break;
    vec3 average = (previous.rgb * count + radiance) / (count + 1.0);
    desired = packUnorm4x8(vec4(average, (count + 1.0) / 255.0));
  }
}
