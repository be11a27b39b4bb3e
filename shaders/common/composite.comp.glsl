#version 450
// The composite every technique ends with (src/techniques/common/composite_stage.h): direct light
// (Lambert, shadowed by the shadow map or by a traced visibility image) + emission, plus each
// indirect term times its weight, in linear radiance ("combined"), then exposure and the Reinhard
// operator x / (1 + x) per channel ("final", linear; PNGs are sRGB-encoded on export). Traced
// images are upsampled along surfaces (common/upsample.glsl); a term of scale 1 is read one texel
// per pixel. A pixel that sees no surface shows the sky (common/sky.glsl; 0 without one). The
// probed pixel writes each step of its sum to the probe chain (PROBE_CHAIN_* in common/shared.h).
#include "common/shared.h"
#include "common/lights.glsl"
#include "common/upsample.glsl"
#include "common/sky.glsl"

#define COMPOSITE_MAX_TERMS 4  // kMaxCompositeTerms in src/techniques/common/composite_stage.h

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 1) uniform sampler2D u_position;
layout(binding = 2) uniform sampler2D u_normal;
layout(binding = 3) uniform sampler2D u_albedo;
layout(binding = 4) uniform sampler2D u_emission;
layout(binding = 5) uniform sampler2D u_shadowMap;
layout(binding = 6) uniform sampler2D u_visibility;  // traced, read when kTracedVisibility = 1
layout(binding = 7) uniform sampler2D u_terms[COMPOSITE_MAX_TERMS];
layout(rgba16f, binding = 0) uniform writeonly image2D u_direct;
layout(rgba16f, binding = 1) uniform writeonly image2D u_combined;
layout(rgba8, binding = 2) uniform writeonly image2D u_final;
uniform int u_traceScale;       // G-buffer pixels per traced pixel along each axis (1 or 2)
uniform float u_planeDistance;  // metres: traced pixels farther than this from the pixel's plane get no weight
// Which visibility and how many terms, fixed per program (CompositeStage's defines): the term
// loop is unrolled to the technique's own terms, each slot a constant sampler, and the visibility
// not chosen is not computed (llvmpipe runs both sides of a branch on a uniform, and every one of
// the four term slots when the loop ran to COMPOSITE_MAX_TERMS).
const int kTracedVisibility = COMPOSITE_TRACED_VISIBILITY;  // 0: the shadow map, 1: u_visibility's red channel
const int kTermCount = COMPOSITE_TERMS;
uniform float u_termWeight[COMPOSITE_MAX_TERMS];
uniform int u_termScale[COMPOSITE_MAX_TERMS];  // G-buffer pixels per texel of each term: u_traceScale or 1
uniform float u_exposure;
uniform ivec2 u_probePixel;  // the pixel whose chain is recorded (GL rows, from the bottom)
layout(std430, binding = VOXLAB_BINDING_PROBE_CHAIN) writeonly buffer ProbeChain { vec4 chain[]; };
const float PI = 3.14159265358979;

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = textureSize(u_position, 0);
  if (any(greaterThanEqual(px, size))) return;
  const bool probed = px == u_probePixel;
  vec4 pos = texelFetch(u_position, px, 0);
  vec3 direct = skyBackground(), combined = direct;
  if (probed) {
    for (int i = 0; i < PROBE_CHAIN_SLOTS; ++i) chain[i] = vec4(0.0);
    chain[PROBE_CHAIN_PIXEL] = vec4(float(px.x), float(size.y - 1 - px.y), pos.w != 0.0 ? 1.0 : 0.0, 0.0);
    chain[PROBE_CHAIN_REFLECTED] = vec4(direct, 0.0);
  }
  if (pos.w != 0.0) {
    vec3 n = normalize(texelFetch(u_normal, px, 0).xyz);
    vec3 albedo = texelFetch(u_albedo, px, 0).rgb;
    vec3 emission = texelFetch(u_emission, px, 0).rgb;
    vec3 toLight; float dist;
    lightDirection(pos.xyz, toLight, dist);
    ShadowTest shadow = shadowTest(u_shadowMap, pos.xyz, n);
    // Every traced image (the visibility, the traced terms) is upsampled with the same taps.
    UpsampleTaps taps = upsampleTaps(u_position, u_normal, (size + u_traceScale - 1) / u_traceScale, px, pos.xyz, n,
                                     u_traceScale, u_planeDistance);
    float visibility = kTracedVisibility == 1 ? upsampleWith(u_visibility, taps, u_traceScale, px).r : shadow.visibility;
    vec3 irradiance = lightIrradiance(pos.xyz);
    float cosine = max(dot(n, toLight), 0.0);
    vec3 reflected = albedo / PI * irradiance * cosine * visibility;
    direct = reflected + emission;
    combined = direct;
    if (probed) {
      chain[PROBE_CHAIN_POSITION] = vec4(pos.xyz, 1.0);
      chain[PROBE_CHAIN_NORMAL] = vec4(n, 0.0);
      chain[PROBE_CHAIN_ALBEDO] = vec4(albedo, 0.0);
      chain[PROBE_CHAIN_EMISSION] = vec4(emission, 0.0);
      chain[PROBE_CHAIN_TO_LIGHT] = vec4(toLight, dist);
      chain[PROBE_CHAIN_IRRADIANCE] = vec4(irradiance, cosine);
      chain[PROBE_CHAIN_SHADOW] = vec4(shadow.receiverDepth, shadow.mapDepth, shadow.litTaps, visibility);
      chain[PROBE_CHAIN_REFLECTED] = vec4(reflected, 0.0);
    }
    for (int i = 0; i < kTermCount; ++i) {
      vec3 term = upsampleWith(u_terms[i], taps, u_termScale[i], px).rgb;
      combined += u_termWeight[i] * term;
      if (probed) {
        chain[PROBE_CHAIN_TERMS + 2 * i] = vec4(term, u_termWeight[i]);
        chain[PROBE_CHAIN_TERMS + 2 * i + 1] = vec4(u_termWeight[i] * term, 0.0);
      }
    }
  }
  vec3 mapped = u_exposure * combined;
  vec3 tonemapped = mapped / (1.0 + mapped);
  imageStore(u_direct, px, vec4(direct, 1.0));
  imageStore(u_combined, px, vec4(combined, 1.0));
  imageStore(u_final, px, vec4(tonemapped, 1.0));
  if (probed) {
    chain[PROBE_CHAIN_COMBINED] = vec4(combined, u_exposure);
    chain[PROBE_CHAIN_EXPOSED] = vec4(mapped, 0.0);
    chain[PROBE_CHAIN_TONEMAPPED] = vec4(tonemapped, 0.0);
    chain[PROBE_CHAIN_STORED] = vec4(round(clamp(tonemapped, 0.0, 1.0) * 255.0) / 255.0, 0.0);
  }
}
