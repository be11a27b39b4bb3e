// The shared part of the composites that add a traced indirect image to the direct light
// (near-field's and lrsm's composite.comp.glsl): the G-buffer and traced-image bindings, the three
// outputs, the surface-aware upsampling of a traced image, the Lambert direct term and the
// tonemapped store. "combined" is linear radiance, "final" the Reinhard operator x / (1 + x) of
// exposure * combined.
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
layout(rgba16f, binding = 0) uniform writeonly image2D u_direct;
layout(rgba16f, binding = 1) uniform writeonly image2D u_combined;
layout(rgba8, binding = 2) uniform writeonly image2D u_final;
uniform int u_traceScale;
uniform float u_planeDistance;  // metres: traced pixels farther than this from the pixel's plane get no weight
uniform float u_indirectWeight, u_exposure;
const float PI = 3.14159265358979;

// A traced image at full-resolution pixel px, upsampled along surfaces (common/upsample.glsl).
vec3 tracedAt(sampler2D traced, ivec2 px, vec3 p, vec3 n) {
  return upsampleAlongSurface(traced, u_position, u_normal, px, p, n, u_traceScale, u_planeDistance).rgb;
}

// Lambert direct light times 'visibility', plus emission, at G-buffer pixel px (position p, normal n).
vec3 directAt(ivec2 px, vec3 p, vec3 n, float visibility) {
  vec3 albedo = texelFetch(u_albedo, px, 0).rgb;
  vec3 toLight; float dist;
  lightDirection(p, toLight, dist);
  return albedo / PI * lightIrradiance(p) * max(dot(n, toLight), 0.0) * visibility + texelFetch(u_emission, px, 0).rgb;
}

void storeComposite(ivec2 px, vec3 direct, vec3 combined) {
  vec3 mapped = u_exposure * combined;
  imageStore(u_direct, px, vec4(direct, 1.0));
  imageStore(u_combined, px, vec4(combined, 1.0));
  imageStore(u_final, px, vec4(mapped / (1.0 + mapped), 1.0));
}
