// The outgoing radiance a voxel fragment carries into the voxels (vct-grid's inject, svo's
// leaves): Lambertian direct light from the scene's light, shadow-mapped, plus emission; or one
// uniform radiance (furnace tests). The shadow map is read u_shadowOffset metres from the voxel
// centre along the fragment's normal: the fragment's surface passes up to half a voxel from the
// centre (axis-aligned), and a centre behind it would be shadowed by the surface itself (on
// Sponza at 128^3 that blackened half the floor). Set by setFragmentLightUniforms()
// (src/techniques/common/fragment_light.cpp) from inject.mode, inject.uniform-radiance and
// inject.shadow-offset. Needs common/shared.h, voxel_space.glsl, packing.glsl and lights.glsl.
#ifndef VOXLAB_FRAGMENT_LIGHT_GLSL
#define VOXLAB_FRAGMENT_LIGHT_GLSL

uniform int u_mode;               // 0 = direct light, 1 = uniform radiance (furnace tests)
uniform vec3 u_uniformRadiance;
uniform float u_shadowOffset;     // metres

vec3 fragmentRadiance(VoxelFragment f, sampler2D shadowMap) {
  if (u_mode == 1) return u_uniformRadiance;
  const float PI = 3.14159265358979;
  ivec3 voxel = ivec3(unpackVoxel10(f.position));
  vec3 albedo = unpackUnorm4x8(f.albedo).rgb;
  vec3 n = normalize(unpackSnorm4x8(f.normal).xyz);
  vec3 p = voxelToWorld(vec3(voxel) + 0.5);
  vec3 toLight; float dist;
  lightDirection(p, toLight, dist);
  float cosine = max(dot(n, toLight), 0.0);
  vec3 irradiance = lightIrradiance(p) * cosine * shadowVisibility(shadowMap, p + n * u_shadowOffset, n);
  return albedo / PI * irradiance + unpackUnorm4x8(f.emission).rgb;
}
#endif
