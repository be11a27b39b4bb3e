// The material of the draw range being rasterized (set by GpuScene::draw).
#include "common/shared.h"
layout(std430, binding = VOXLAB_BINDING_MATERIALS) readonly buffer Materials { GpuMaterial materials[]; };
layout(binding = VOXLAB_UNIT_ALBEDO) uniform sampler2D u_albedoTexture;
layout(binding = VOXLAB_UNIT_EMISSIVE) uniform sampler2D u_emissiveTexture;
uniform int u_materialIndex;

vec4 materialAlbedo(vec2 uv) { return materials[u_materialIndex].baseColor * texture(u_albedoTexture, uv); }
// The same at an explicit mip level (compute passes have no derivatives).
vec4 materialAlbedoLod(vec2 uv, float lod) {
  return materials[u_materialIndex].baseColor * textureLod(u_albedoTexture, uv, lod);
}
vec3 materialEmissionLod(vec2 uv, float lod) {
  vec4 e = materials[u_materialIndex].emissive;
  return e.a > 0.5 ? e.rgb * textureLod(u_emissiveTexture, uv, lod).rgb : e.rgb;
}
vec3 materialEmission(vec2 uv) {
  vec4 e = materials[u_materialIndex].emissive;
  return e.a > 0.5 ? e.rgb * texture(u_emissiveTexture, uv).rgb : e.rgb;
}
// alphaMode MASK: true where the surface is cut away (baseColor.a x texture alpha < alphaCutoff);
// camera and light rasterization discard such fragments. Voxelization uses alpha_coverage.glsl.
bool materialCutAway(vec2 uv) {
  vec4 alpha = materials[u_materialIndex].alpha;
  return alpha.y > 0.5 && materialAlbedo(uv).a < alpha.x;
}
