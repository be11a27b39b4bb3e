// The material of the draw range being rasterized (set by GpuScene::draw).
#include "common/shared.h"
layout(std430, binding = VOXLAB_BINDING_MATERIALS) readonly buffer Materials { GpuMaterial materials[]; };
layout(binding = VOXLAB_UNIT_ALBEDO) uniform sampler2D u_albedoTexture;
layout(binding = VOXLAB_UNIT_EMISSIVE) uniform sampler2D u_emissiveTexture;
uniform int u_materialIndex;
// A program built for one kind of material (GpuScene::materialKindDefines: VOXLAB_MATERIAL_KIND,
// with VOXLAB_MATERIAL_ALBEDO_TEXTURE, VOXLAB_MATERIAL_EMISSIVE_TEXTURE, VOXLAB_MATERIAL_ALPHA_MASK
// where the material has them) reads no texture the material lacks: its white stand-in multiplies
// by exactly 1, so the values are the general program's. Without VOXLAB_MATERIAL_KIND every
// texture is read.
#if !defined(VOXLAB_MATERIAL_KIND) || defined(VOXLAB_MATERIAL_ALBEDO_TEXTURE)
#define VOXLAB_READS_ALBEDO_TEXTURE 1
#endif
#if !defined(VOXLAB_MATERIAL_KIND) || defined(VOXLAB_MATERIAL_EMISSIVE_TEXTURE)
#define VOXLAB_READS_EMISSIVE_TEXTURE 1
#endif

vec4 materialAlbedo(vec2 uv) {
#ifdef VOXLAB_READS_ALBEDO_TEXTURE
  return materials[u_materialIndex].baseColor * texture(u_albedoTexture, uv);
#else
  return materials[u_materialIndex].baseColor;
#endif
}
// The same at an explicit mip level (compute passes have no derivatives).
vec4 materialAlbedoLod(vec2 uv, float lod) {
#ifdef VOXLAB_READS_ALBEDO_TEXTURE
  return materials[u_materialIndex].baseColor * textureLod(u_albedoTexture, uv, lod);
#else
  return materials[u_materialIndex].baseColor;
#endif
}
vec3 materialEmissionLod(vec2 uv, float lod) {
  vec4 e = materials[u_materialIndex].emissive;
#ifdef VOXLAB_READS_EMISSIVE_TEXTURE
  return e.a > 0.5 ? e.rgb * textureLod(u_emissiveTexture, uv, lod).rgb : e.rgb;
#else
  return e.rgb;
#endif
}
vec3 materialEmission(vec2 uv) {
  vec4 e = materials[u_materialIndex].emissive;
#ifdef VOXLAB_READS_EMISSIVE_TEXTURE
  return e.a > 0.5 ? e.rgb * texture(u_emissiveTexture, uv).rgb : e.rgb;
#else
  return e.rgb;
#endif
}
// alphaMode MASK: true where the surface is cut away (baseColor.a x texture alpha < alphaCutoff);
// camera and light rasterization discard such fragments. Voxelization uses alpha_coverage.glsl.
bool materialCutAway(vec2 uv) {
#if defined(VOXLAB_MATERIAL_KIND) && !defined(VOXLAB_MATERIAL_ALPHA_MASK)
  return false;  // with nothing to cut away, a depth-only pass runs no fragment code at all
#else
  vec4 alpha = materials[u_materialIndex].alpha;
  return alpha.y > 0.5 && materialAlbedo(uv).a < alpha.x;
#endif
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
