#version 450
// Composite: direct light (Lambert, shadow map or soft-shadow cone) + emission + indirect diffuse
// + specular weight * indirect specular, in linear radiance ("combined"), then exposure and the
// Reinhard operator x / (1 + x) per channel ("final", linear; PNGs are sRGB-encoded on export).
// A pixel that sees no surface shows the sky (common/sky.glsl; 0 without one) in all three.
#include "common/shared.h"
#include "common/lights.glsl"
#include "common/upsample.glsl"
#include "common/sky.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 1) uniform sampler2D u_position;
layout(binding = 2) uniform sampler2D u_normal;
layout(binding = 3) uniform sampler2D u_albedo;
layout(binding = 4) uniform sampler2D u_emission;
layout(binding = 5) uniform sampler2D u_indirectDiffuse;
layout(binding = 6) uniform sampler2D u_indirectSpecular;
layout(binding = 7) uniform sampler2D u_softShadow;
layout(binding = 8) uniform sampler2D u_shadowMap;
layout(rgba16f, binding = 0) uniform writeonly image2D u_direct;
layout(rgba16f, binding = 1) uniform writeonly image2D u_combined;
layout(rgba8, binding = 2) uniform writeonly image2D u_final;
uniform int u_shadowSource;     // 0 = shadow map, 1 = soft-shadow cone
uniform int u_traceScale;       // G-buffer pixels per traced pixel along each axis (1 or 2)
uniform float u_edgeDistance;   // metres: traced samples farther than this from the pixel's plane get no weight

// A cone-trace result for full-resolution pixel px, upsampled along surfaces (common/upsample.glsl).
vec4 traced(sampler2D image, ivec2 px, vec3 p, vec3 n) {
  return upsampleAlongSurface(image, u_position, u_normal, px, p, n, u_traceScale, u_edgeDistance);
}
uniform float u_specularWeight;
uniform float u_indirectWeight;
uniform float u_exposure;
const float PI = 3.14159265358979;

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = textureSize(u_position, 0);
  if (px.x >= size.x || px.y >= size.y) return;
  vec4 pos = texelFetch(u_position, px, 0);
  vec3 direct = skyBackground(), combined = direct;
  if (pos.w != 0.0) {
    vec3 n = normalize(texelFetch(u_normal, px, 0).xyz);
    vec3 albedo = texelFetch(u_albedo, px, 0).rgb;
    vec3 toLight; float dist;
    lightDirection(pos.xyz, toLight, dist);
    float visibility = u_shadowSource == 0 ? shadowVisibility(u_shadowMap, pos.xyz, n)
                                           : traced(u_softShadow, px, pos.xyz, n).r;
    direct = albedo / PI * lightIrradiance(pos.xyz) * max(dot(n, toLight), 0.0) * visibility
           + texelFetch(u_emission, px, 0).rgb;
    combined = direct + u_indirectWeight * traced(u_indirectDiffuse, px, pos.xyz, n).rgb
             + u_specularWeight * traced(u_indirectSpecular, px, pos.xyz, n).rgb;
  }
  vec3 mapped = u_exposure * combined;
  imageStore(u_direct, px, vec4(direct, 1.0));
  imageStore(u_combined, px, vec4(combined, 1.0));
  imageStore(u_final, px, vec4(mapped / (1.0 + mapped), 1.0));
}
