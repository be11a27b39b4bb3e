#version 450
// GI lookup per pixel (seed 000 section 4.3.5, Listings 4.35/4.36, with K&D's radiance reading):
// each cascade's SH is read trilinearly at p + n * offset cells; incident radiance is taken as
// scale * intensity / cell^2; irradiance E = max(0, <L, lobe(sign * n)>) with sign = -1 for light
// arriving at the surface (the consistent reading) or +1 (the thesis listings). The cascades blend
// in a shell of u_blendWidth fine cells ending half a cell inside the fine grid (max norm from its
// snapped centre); outgoing radiance = albedo / pi * E.
#include "common/sh.glsl"
#include "lpv/lpv_shared.h"
layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = LPV_BINDING_GRIDS) readonly buffer Grids { LpvGrid grids[2]; };
layout(binding = 0) uniform sampler2D u_position;
layout(binding = 1) uniform sampler2D u_normal;
layout(binding = 2) uniform sampler2D u_albedo;
layout(binding = 3) uniform sampler3D u_light[6];  // fine r,g,b then coarse r,g,b
layout(rgba32f, binding = 0) uniform writeonly image2D u_fine;
layout(rgba32f, binding = 1) uniform writeonly image2D u_coarse;
layout(r32f, binding = 2) uniform writeonly image2D u_blend;
layout(rgba32f, binding = 3) uniform writeonly image2D u_indirect;
layout(rgba16f, binding = 4) uniform writeonly image2D u_glossy;
layout(binding = 9) uniform sampler3D u_reflection;  // over the fine cascade's box, with mips
uniform float u_reflectionVoxel;   // metres
uniform float u_reflectionLevels;
uniform float u_glossyTan;         // tan(half aperture)
uniform float u_glossyDistance;    // metres
uniform vec3 u_cameraPos;
uniform int u_glossyOn;
uniform int u_glossyWanted;  // 0: the glossy image is not wanted (composite.glossy = 0 and no view of it)
uniform float u_lookupSign;
uniform float u_lookupOffset;
uniform float u_radianceScale;
uniform float u_blendWidth;
const float PI = 3.14159265358979;

vec3 irradiance(int c, vec3 p, vec3 n) {
  vec3 origin = grids[c].originCell.xyz;
  float s = grids[c].originCell.w, res = grids[c].centreRes.w;
  vec3 uvw = (p + n * (u_lookupOffset * s) - origin) / (s * res);
  if (any(lessThan(uvw, vec3(0.0))) || any(greaterThan(uvw, vec3(1.0)))) return vec3(0.0);
  vec3 e;
  for (int ch = 0; ch < 3; ++ch) e[ch] = max(0.0, shDotLobe(texture(u_light[c * 3 + ch], uvw), u_lookupSign * n));
  return e * (u_radianceScale / (s * s));
}

// One cone along the mirrored view direction through the reflection grid (the glossy half of
// Listing 4.37): starts one voxel off the surface, samples every half diameter at the mip level
// whose voxel equals the diameter, composites front to back, stops when opaque, outside the grid
// or past u_glossyDistance. (The thesis' listing uses log2(diameter / 0.25), two levels finer, and
// fades samples in with distance: not reproduced.)
vec3 glossyCone(vec3 p, vec3 n) {
  vec3 v = normalize(p - u_cameraPos);
  vec3 r = reflect(v, n);
  vec3 origin = grids[0].originCell.xyz;
  float edge = grids[0].originCell.w * grids[0].centreRes.w;
  vec3 colour = vec3(0.0);
  float alpha = 0.0;
  float t = u_reflectionVoxel;
  for (int i = 0; i < 256 && alpha < 1.0 && t < u_glossyDistance; ++i) {
    float diameter = max(u_reflectionVoxel, 2.0 * u_glossyTan * t);
    vec3 uvw = (p + n * u_reflectionVoxel + r * t - origin) / edge;
    if (any(lessThan(uvw, vec3(0.0))) || any(greaterThan(uvw, vec3(1.0)))) break;
    float lod = min(log2(diameter / u_reflectionVoxel), u_reflectionLevels - 1.0);
    vec4 s = textureLod(u_reflection, uvw, lod);
    colour += (1.0 - alpha) * s.rgb;
    alpha += (1.0 - alpha) * s.a;
    t += 0.5 * diameter;
  }
  return colour;
}

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = textureSize(u_position, 0);
  if (px.x >= size.x || px.y >= size.y) return;
  vec4 pos = texelFetch(u_position, px, 0);
  vec3 ef = vec3(0.0), ec = vec3(0.0), indirect = vec3(0.0), glossy = vec3(0.0);
  float t = 0.0;
  if (pos.w != 0.0) {
    vec3 n = normalize(texelFetch(u_normal, px, 0).xyz);
    ef = irradiance(0, pos.xyz, n);
    ec = irradiance(1, pos.xyz, n);
    float s = grids[0].originCell.w, res = grids[0].centreRes.w;
    vec3 centre = grids[0].originCell.xyz + 0.5 * res * s;
    vec3 q = abs(pos.xyz - centre) / s;
    float d = max(q.x, max(q.y, q.z));
    t = clamp((d - (0.5 * res - 0.5 - u_blendWidth)) / u_blendWidth, 0.0, 1.0);
    indirect = texelFetch(u_albedo, px, 0).rgb / PI * mix(ef, ec, t);
    if (u_glossyOn == 1 && u_glossyWanted == 1) glossy = glossyCone(pos.xyz, n);
  }
  imageStore(u_fine, px, vec4(ef, 1.0));
  imageStore(u_coarse, px, vec4(ec, 1.0));
  imageStore(u_blend, px, vec4(t));
  imageStore(u_indirect, px, vec4(indirect, 1.0));
  if (u_glossyWanted == 1) imageStore(u_glossy, px, vec4(glossy, 1.0));
}
