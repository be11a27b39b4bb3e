#version 450
// Composite: direct light (Lambert, shadow map or soft-shadow cone) + emission + indirect diffuse
// + specular weight * indirect specular, in linear radiance ("combined"), then exposure and the
// Reinhard operator x / (1 + x) per channel ("final", linear; PNGs are sRGB-encoded on export).
#include "common/shared.h"
#include "common/lights.glsl"

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

// A cone-trace result for full-resolution pixel px. At half resolution: the four nearest traced
// pixels, bilinear weights times a weight for lying on the same surface (plane distance and
// normal agreement), so indirect light does not bleed across depth or normal edges.
vec4 traced(sampler2D image, ivec2 px, vec3 p, vec3 n) {
  if (u_traceScale == 1) return texelFetch(image, px, 0);
  ivec2 lowSize = textureSize(image, 0);
  vec2 f = (vec2(px) + 0.5) / float(u_traceScale) - 0.5;
  ivec2 base = ivec2(floor(f));
  vec2 w = f - vec2(base);
  vec4 sum = vec4(0.0);
  float total = 0.0, bestWeight = -1.0;
  vec4 best = vec4(0.0);
  for (int i = 0; i < 4; ++i) {
    ivec2 q = clamp(base + ivec2(i & 1, i >> 1), ivec2(0), lowSize - 1);
    ivec2 g = min(q * u_traceScale, textureSize(u_position, 0) - 1);
    vec4 qp = texelFetch(u_position, g, 0);
    if (qp.w == 0.0) continue;
    vec3 qn = texelFetch(u_normal, g, 0).xyz;
    float bilinear = ((i & 1) == 1 ? w.x : 1.0 - w.x) * ((i >> 1) == 1 ? w.y : 1.0 - w.y);
    float plane = max(0.0, 1.0 - abs(dot(n, qp.xyz - p)) / u_edgeDistance);
    float facing = pow(max(dot(n, qn), 0.0), 8.0);
    float weight = bilinear * plane * facing;
    vec4 value = texelFetch(image, q, 0);
    sum += weight * value;
    total += weight;
    float similarity = plane * facing;
    if (similarity > bestWeight) { bestWeight = similarity; best = value; }
  }
  return total > 1e-4 ? sum / total : best;
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
  vec3 direct = vec3(0.0), combined = vec3(0.0);
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
