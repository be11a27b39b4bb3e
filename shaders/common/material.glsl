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
// The albedo texture's mip level whose texel is about one voxel over a triangle (p: its corners
// in voxels, t: their texture coordinates): log2 of texels per voxel along one side (a triangle
// whose area rounds to 0 takes the coarsest level).
float voxelTextureLod(vec3 p0, vec3 p1, vec3 p2, vec2 t0, vec2 t1, vec2 t2) {
  vec2 du = t1 - t0, dv = t2 - t0;
  vec2 texels = vec2(textureSize(u_albedoTexture, 0));
  float texelRatio = abs(du.x * dv.y - du.y * dv.x) * texels.x * texels.y / max(length(cross(p1 - p0, p2 - p0)), 1e-20);
  return max(0.5 * log2(max(texelRatio, 1e-8)), 0.0);
}
