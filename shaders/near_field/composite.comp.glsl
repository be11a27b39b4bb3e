#version 450
// Composite: direct light (Lambert, shadow map) + emission + the near-field indirect light,
// upsampled from the traced resolution along surfaces (common/traced_composite.glsl). A pixel that
// sees no surface shows the sky (common/sky.glsl; 0 without one).
#include "common/traced_composite.glsl"

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = textureSize(u_position, 0);
  if (any(greaterThanEqual(px, size))) return;
  vec4 pos = texelFetch(u_position, px, 0);
  vec3 direct = skyBackground(), combined = direct;
  if (pos.w != 0.0) {
    vec3 n = normalize(texelFetch(u_normal, px, 0).xyz);
    direct = directAt(px, pos.xyz, n, shadowVisibility(u_shadowMap, pos.xyz, n));
    combined = direct + u_indirectWeight * tracedAt(u_indirect, px, pos.xyz, n);
  }
  storeComposite(px, direct, combined);
}
