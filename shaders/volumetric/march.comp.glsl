#version 450
// Single-scattering ray march, one sample per dispatch (sample index u_sample of u_steps), after
// seed 000 Listings 4.51-4.52 with the physics the thesis leaves out (docs in volumetric.cpp):
//   L_in = sum_i T(t_i) sigma_s(x_i) p(mu_i) E(x_i) V(x_i) dt,  t_i = t0 + (i + u) dt,  dt = (t1 - t0) / N
// over the part [t0, t1] of the camera ray inside the density grid and before the surface,
// with u the pixel's dither offset, T(t_i) = exp(-(sum_{j<i} sigma_t(x_j) dt + sigma_t(x_i) u dt)),
// and after the last sample T(t1) = exp(-sum_j sigma_t(x_j) dt) for the surface behind.
#include "common/shared.h"
#include "common/lights.glsl"
#include "common/voxel_space.glsl"
#include "volumetric/volumetric_shared.h"
#include "volumetric/phase.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 1) uniform sampler2D u_position;
layout(binding = 2) uniform sampler3D u_scattering;   // particles' sigma_s (1/m), zero border
layout(binding = 3) uniform sampler2D u_shadowMap;
layout(binding = 4) uniform usampler3D u_counts;
layout(rgba32f, binding = 0) uniform image2D u_inscatter;      // rgb: L_in so far
layout(r32f, binding = 1) uniform image2D u_opticalDepth;      // sum_{j<i} sigma_t dt
layout(r32f, binding = 2) uniform writeonly image2D u_transmittance;
layout(r32f, binding = 3) uniform writeonly image2D u_rayLength;
layout(std430, binding = VOXLAB_BINDING_RAY_RECORDS) writeonly buffer Records { RaySample records[]; };
layout(std430, binding = VOXLAB_BINDING_RAY_RECORD_COUNT) buffer RecordCount { uint recordCount; };
uniform int u_sample;
uniform int u_steps;
uniform int u_scale;            // G-buffer pixels per marched pixel along each axis
uniform mat4 u_invViewProj;
uniform vec3 u_cameraPos;
uniform int u_dither;           // 0 Bayer 4x4, 1 off (offset 0), 2 the thesis' matrix with 0.22
uniform int u_phaseModel;       // 0 Henyey-Greenstein, 1 the thesis' (1-g)^2 numerator
uniform float u_g;
uniform float u_hazeScattering; // sigma_s of the uniform haze inside the grid (1/m)
uniform float u_extinctionRatio;  // sigma_t = ratio * sigma_s
uniform ivec2 u_probePixel;

const int BAYER[16] = int[16](VOXLAB_BAYER4_X16);

float ditherOffset(ivec2 q) {
  if (u_dither == 1) return 0.0;
  int x = q.x & 3, y = q.y & 3;  // pixel x indexes the first dimension, as Listing 4.51
  if (u_dither == 2 && x == 1 && y == 1) return VOXLAB_THESIS_BAYER_11;
  return float(BAYER[4 * x + y]) / 16.0;
}

// Lit (1) or shadowed (0) by the shadow map, one hard compare; 1 without a shadow map. A spot's
// map covers its cone: outside its frustum 0. A directional light's map covers the scene's bounds,
// not the whole medium: shadowMapDecides (common/lights.glsl) decides outside them.
float visibility(vec3 p) {
  if (u_light.spot.w < 0.5) return 1.0;
  vec4 clip = u_light.shadowViewProj * vec4(p, 1.0);
  if (clip.w <= 0.0) return 0.0;
  vec3 uvz = clip.xyz / clip.w * 0.5 + 0.5;
  if (!shadowMapDecides(uvz)) return u_light.positionType.w == VOXLAB_LIGHT_DIRECTIONAL ? 1.0 : 0.0;
  return texture(u_shadowMap, uvz.xy).r >= uvz.z - 1e-4 ? 1.0 : 0.0;
}

void main() {
  ivec2 q = ivec2(gl_GlobalInvocationID.xy);
  ivec2 lowSize = imageSize(u_inscatter);
  if (q.x >= lowSize.x || q.y >= lowSize.y) return;
  ivec2 fullSize = textureSize(u_position, 0);
  ivec2 g = min(q * u_scale, fullSize - 1);
  vec4 surface = texelFetch(u_position, g, 0);

  // The camera ray through the centre of G-buffer pixel g, ending at its surface point.
  vec2 ndc = (vec2(g) + 0.5) / vec2(fullSize) * 2.0 - 1.0;
  vec4 farPoint = u_invViewProj * vec4(ndc, 1.0, 1.0);
  vec3 dir = normalize(farPoint.xyz / farPoint.w - u_cameraPos);
  float D = 1e30;
  if (surface.w != 0.0) {
    D = length(surface.xyz - u_cameraPos);
    dir = (surface.xyz - u_cameraPos) / max(D, 1e-6);
  }
  // Clip to the density grid (slab test); nothing scatters outside it.
  vec3 lo = u_volumeOrigin, hi = u_volumeOrigin + vec3(u_voxelSize * float(u_resolution));
  vec3 inv = 1.0 / vec3(abs(dir.x) > 1e-8 ? dir.x : 1e-8, abs(dir.y) > 1e-8 ? dir.y : 1e-8, abs(dir.z) > 1e-8 ? dir.z : 1e-8);
  vec3 ta = (lo - u_cameraPos) * inv, tb = (hi - u_cameraPos) * inv;
  vec3 tmin = min(ta, tb), tmax = max(ta, tb);
  float t0 = max(max(max(tmin.x, tmin.y), tmin.z), 0.0);
  float t1 = min(min(min(tmax.x, tmax.y), tmax.z), D);
  float len = max(t1 - t0, 0.0);
  float dt = len / float(u_steps);
  float u = ditherOffset(q);

  vec3 sum = u_sample == 0 ? vec3(0.0) : imageLoad(u_inscatter, q).rgb;
  float depthBefore = u_sample == 0 ? 0.0 : imageLoad(u_opticalDepth, q).r;
  float t = t0 + (float(u_sample) + u) * dt;
  vec3 x = u_cameraPos + dir * t;
  float sigmaS = 0.0, lit = 0.0, mu = 0.0, phase = 0.0, T = 1.0;
  vec3 E = vec3(0.0), contribution = vec3(0.0);
  if (len > 0.0) {
    sigmaS = texture(u_scattering, worldToVolumeUV(x)).r + u_hazeScattering;
    float sigmaT = u_extinctionRatio * sigmaS;
    T = exp(-(depthBefore + sigmaT * u * dt));
    vec3 toLight; float dist;
    lightDirection(x, toLight, dist);
    mu = dot(dir, toLight);
    phase = u_phaseModel == 0 ? phaseHenyeyGreenstein(mu, u_g) : phaseThesis(mu, u_g);
    E = lightIrradiance(x);
    lit = visibility(x);
    contribution = T * sigmaS * phase * E * lit * dt;
    sum += contribution;
    depthBefore += sigmaT * dt;
  }
  imageStore(u_inscatter, q, vec4(sum, 1.0));
  imageStore(u_opticalDepth, q, vec4(depthBefore));
  imageStore(u_transmittance, q, vec4(exp(-depthBefore)));
  imageStore(u_rayLength, q, vec4(len));

  if (q == u_probePixel) {
    vec3 v = worldToVoxel(x);
    records[u_sample].voxel = vec4(v, t);
    records[u_sample].world = vec4(x, u);
    float count = len > 0.0 ? float(texelFetch(u_counts, clamp(ivec3(floor(v)), ivec3(0), ivec3(u_resolution - 1)), 0).r) : 0.0;
    records[u_sample].medium = vec4(lit, sigmaS, u_extinctionRatio * sigmaS, count);
    records[u_sample].phase = vec4(mu, phase, dot(E, vec3(0.2126, 0.7152, 0.0722)), T);
    records[u_sample].contribution = vec4(contribution, dot(sum, vec3(0.2126, 0.7152, 0.0722)));
    recordCount = uint(u_sample + 1);
  }
}
