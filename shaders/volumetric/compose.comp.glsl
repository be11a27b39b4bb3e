#version 450
// Compose: the surface radiance, attenuated by the medium in front of it, plus the light the
// medium scatters towards the camera: L = L_surface * T + L_in (linear, "combined"), then
// exposure and x / (1 + x) per channel ("final"). The surface term is this technique's direct
// light (Lambert, shadow map with 3x3 PCF, plus emission), an input image, or black. A pixel that
// sees no surface shows the scene's own sky (the background, r = 0 in the reference), as every
// composite does; volumetric gathers no sky light on surfaces.
#include "common/shared.h"
#include "common/lights.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 1) uniform sampler2D u_position;
layout(binding = 2) uniform sampler2D u_normal;
layout(binding = 3) uniform sampler2D u_albedo;
layout(binding = 4) uniform sampler2D u_emission;
layout(binding = 5) uniform sampler2D u_shadowMap;
layout(binding = 6) uniform sampler2D u_inscatter;
layout(binding = 7) uniform sampler2D u_transmittance;
layout(binding = 8) uniform sampler2D u_surfaceInput;
layout(rgba32f, binding = 0) uniform writeonly image2D u_surface;
layout(rgba32f, binding = 1) uniform writeonly image2D u_combined;
layout(rgba8, binding = 2) uniform writeonly image2D u_final;
uniform int u_surfaceSource;   // 0 direct light, 1 none (black), 2 u_surfaceInput
uniform float u_exposure;
uniform vec3 u_skyRadiance;  // the scene's sky (Scene::skyRadiance), the background
const float PI = 3.14159265358979;

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = textureSize(u_position, 0);
  if (px.x >= size.x || px.y >= size.y) return;
  vec4 pos = texelFetch(u_position, px, 0);
  vec3 surface = vec3(0.0);
  if (u_surfaceSource == 2) {
    surface = texelFetch(u_surfaceInput, px, 0).rgb;
  } else if (u_surfaceSource == 0 && pos.w != 0.0) {
    vec3 n = normalize(texelFetch(u_normal, px, 0).xyz);
    vec3 toLight; float dist;
    lightDirection(pos.xyz, toLight, dist);
    surface = texelFetch(u_albedo, px, 0).rgb / PI * lightIrradiance(pos.xyz) * max(dot(n, toLight), 0.0)
            * shadowVisibility(u_shadowMap, pos.xyz, n) + texelFetch(u_emission, px, 0).rgb;
  } else if (u_surfaceSource == 0) {
    surface = u_skyRadiance;
  }
  vec3 combined = surface * texelFetch(u_transmittance, px, 0).r + texelFetch(u_inscatter, px, 0).rgb;
  vec3 mapped = u_exposure * combined;
  imageStore(u_surface, px, vec4(surface, 1.0));
  imageStore(u_combined, px, vec4(combined, 1.0));
  imageStore(u_final, px, vec4(mapped / (1.0 + mapped), 1.0));
}
