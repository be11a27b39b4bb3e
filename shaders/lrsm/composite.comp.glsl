#version 450
// Composite of lrsm: direct light (Lambert, shadowed by the shadow cone's transmittance or the
// shadow map) + emission + the gathered indirect diffuse light, upsampled from the traced
// resolution along surfaces (the shadow cone's transmittance the same way); "combined" is linear radiance, "final"
// the Reinhard operator x / (1 + x) of exposure * combined. A pixel that sees no surface shows the
// sky (common/sky.glsl; 0 without one).
#include "common/shared.h"
#include "common/lights.glsl"
#include "common/upsample.glsl"
#include "common/sky.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 1) uniform sampler2D u_position;
layout(binding = 2) uniform sampler2D u_normal;
layout(binding = 3) uniform sampler2D u_albedo;
layout(binding = 4) uniform sampler2D u_emission;
layout(binding = 5) uniform sampler2D u_indirect;
layout(binding = 6) uniform sampler2D u_shadowMap;
layout(binding = 7) uniform sampler2D u_softShadow;
layout(rgba16f, binding = 0) uniform writeonly image2D u_direct;
layout(rgba16f, binding = 1) uniform writeonly image2D u_combined;
layout(rgba8, binding = 2) uniform writeonly image2D u_final;
uniform int u_traceScale;
uniform float u_planeDistance;  // metres: traced pixels farther than this from the pixel's plane get no weight
uniform float u_indirectWeight, u_exposure;
uniform int u_coneShadow;
const float PI = 3.14159265358979;

// A traced image (indirect light, shadow-cone transmittance) at full-resolution pixel px, upsampled
// along surfaces (common/upsample.glsl).
vec3 tracedAt(sampler2D traced, ivec2 px, vec3 p, vec3 n) {
  return upsampleAlongSurface(traced, u_position, u_normal, px, p, n, u_traceScale, u_planeDistance).rgb;
}

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = textureSize(u_position, 0);
  if (any(greaterThanEqual(px, size))) return;
  vec4 pos = texelFetch(u_position, px, 0);
  vec3 direct = skyBackground(), combined = direct;
  if (pos.w != 0.0) {
    vec3 n = normalize(texelFetch(u_normal, px, 0).xyz);
    vec3 albedo = texelFetch(u_albedo, px, 0).rgb;
    vec3 toLight; float dist;
    float visibility = u_coneShadow == 1 ? tracedAt(u_softShadow, px, pos.xyz, n).r : shadowVisibility(u_shadowMap, pos.xyz, n);
    lightDirection(pos.xyz, toLight, dist);
    direct = albedo / PI * lightIrradiance(pos.xyz) * max(dot(n, toLight), 0.0) * visibility
           + texelFetch(u_emission, px, 0).rgb;
    combined = direct + u_indirectWeight * tracedAt(u_indirect, px, pos.xyz, n);
  }
  vec3 mapped = u_exposure * combined;
  imageStore(u_direct, px, vec4(direct, 1.0));
  imageStore(u_combined, px, vec4(combined, 1.0));
  imageStore(u_final, px, vec4(mapped / (1.0 + mapped), 1.0));
}
