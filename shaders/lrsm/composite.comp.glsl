#version 450
// Composite of lrsm: direct light (Lambert, shadowed by the shadow cone's transmittance or the
// shadow map) + emission + the gathered indirect diffuse light, upsampled from the traced
// resolution along surfaces (the shadow cone's transmittance the same way;
// common/traced_composite.glsl). A pixel that sees no surface shows the sky (common/sky.glsl;
// 0 without one).
#include "common/traced_composite.glsl"
layout(binding = 7) uniform sampler2D u_softShadow;
uniform int u_coneShadow;

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = textureSize(u_position, 0);
  if (any(greaterThanEqual(px, size))) return;
  vec4 pos = texelFetch(u_position, px, 0);
  vec3 direct = skyBackground(), combined = direct;
  if (pos.w != 0.0) {
    vec3 n = normalize(texelFetch(u_normal, px, 0).xyz);
    float visibility = u_coneShadow == 1 ? tracedAt(u_softShadow, px, pos.xyz, n).r : shadowVisibility(u_shadowMap, pos.xyz, n);
    direct = directAt(px, pos.xyz, n, visibility);
    combined = direct + u_indirectWeight * tracedAt(u_indirect, px, pos.xyz, n);
  }
  storeComposite(px, direct, combined);
}
