#version 450
// Composite: direct light (Lambert, shadow map) + emission + indirect diffuse + specular weight *
// indirect specular ("combined", linear radiance), then exposure and x / (1 + x) ("final").
#include "common/shared.h"
#include "common/lights.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 1) uniform sampler2D u_position;
layout(binding = 2) uniform sampler2D u_normal;
layout(binding = 3) uniform sampler2D u_albedo;
layout(binding = 4) uniform sampler2D u_emission;
layout(binding = 5) uniform sampler2D u_indirectDiffuse;
layout(binding = 6) uniform sampler2D u_indirectSpecular;
layout(binding = 8) uniform sampler2D u_shadowMap;
layout(rgba16f, binding = 0) uniform writeonly image2D u_direct;
layout(rgba16f, binding = 1) uniform writeonly image2D u_combined;
layout(rgba8, binding = 2) uniform writeonly image2D u_final;
uniform float u_specularWeight;
uniform float u_indirectWeight;
uniform float u_exposure;
const float PI = 3.14159265358979;

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(px, textureSize(u_position, 0)))) return;
  vec4 pos = texelFetch(u_position, px, 0);
  vec3 direct = vec3(0.0), combined = vec3(0.0);
  if (pos.w != 0.0) {
    vec3 n = normalize(texelFetch(u_normal, px, 0).xyz);
    vec3 albedo = texelFetch(u_albedo, px, 0).rgb;
    vec3 toLight; float dist;
    lightDirection(pos.xyz, toLight, dist);
    direct = albedo / PI * lightIrradiance(pos.xyz) * max(dot(n, toLight), 0.0) * shadowVisibility(u_shadowMap, pos.xyz, n)
           + texelFetch(u_emission, px, 0).rgb;
    combined = direct + u_indirectWeight * texelFetch(u_indirectDiffuse, px, 0).rgb
             + u_specularWeight * texelFetch(u_indirectSpecular, px, 0).rgb;
  }
  vec3 mapped = u_exposure * combined;
  imageStore(u_direct, px, vec4(direct, 1.0));
  imageStore(u_combined, px, vec4(combined, 1.0));
  imageStore(u_final, px, vec4(mapped / (1.0 + mapped), 1.0));
}
