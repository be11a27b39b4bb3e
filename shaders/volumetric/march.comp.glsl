#version 450
// Single-scattering ray march, one sample per dispatch (sample index u_sample of u_steps), after
// seed 000 Listings 4.51-4.52 with the physics the thesis leaves out (docs in volumetric.cpp):
//   L_in = sum_i T(t_i) sigma_s(x_i) p(mu_i) E(x_i) V(x_i) dt,  t_i = t0 + (i + u) dt,  dt = (t1 - t0) / N
// over the part [t0, t1] of the camera ray inside the density grid and before the surface (with
// march.clip=spot-cone the samples cover only its part inside a spot light's cone, see below),
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
uniform int u_clipToCone;       // 1: in-scattering samples only where a spot light's cone is (Vos 2014, 3.2.1)

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
  const int face = lightMapFace(p);
  if (face >= 0) {  // a point light's cube faces see every direction: the face decides
    vec3 uvz;
    if (!lightMapCoord(p, face, textureSize(u_shadowMap, 0), uvz)) return 1.0;
    return texture(u_shadowMap, uvz.xy).r >= uvz.z - 1e-4 ? 1.0 : 0.0;
  }
  vec4 clip = u_light.shadowViewProj * vec4(p, 1.0);
  if (clip.w <= 0.0) return 0.0;
  vec3 uvz = clip.xyz / clip.w * 0.5 + 0.5;
  if (!shadowMapDecides(uvz)) return lightType() == VOXLAB_LIGHT_DIRECTIONAL ? 1.0 : 0.0;
  return texture(u_shadowMap, uvz.xy).r >= uvz.z - 1e-4 ? 1.0 : 0.0;
}

// The part [a, b] of [t0, t1] of the ray o + t d (d unit) inside the spot light's cone: the
// forward nappe of half-angle acos(cos outer) around its axis, widened by 0.01 rad so that float
// rounding at the rim cannot cut a sample whose irradiance is not 0 (outside the outer cone it is
// exactly 0, common/lights.glsl). For an outer angle under 90 degrees the cone is convex, so the
// ray meets it in one interval: inside(t) = f(t) >= 0 (the double cone) and on the axis' side of
// the apex. false: the segment misses the cone.
bool clipToSpotCone(vec3 o, vec3 d, float t0, float t1, out float a, out float b) {
  vec3 apex = u_light.positionType.xyz, axis = u_light.directionRange.xyz;
  float c = cos(min(acos(clamp(u_light.spot.y, -1.0, 1.0)) + 0.01, 1.5));
  float c2 = c * c;
  vec3 v = o - apex;
  float dA = dot(d, axis), vA = dot(v, axis);
  float qa = dA * dA - c2, qb = 2.0 * (dA * vA - c2 * dot(d, v)), qc = vA * vA - c2 * dot(v, v);
  float lo = -1e30, hi = 1e30;
  if (abs(dA) > 1e-8) {
    if (dA > 0.0) lo = -vA / dA; else hi = -vA / dA;
  } else if (vA < 0.0) {
    return false;  // parallel to the apex plane, behind it
  }
  float disc = qb * qb - 4.0 * qa * qc;
  if (abs(qa) < 1e-8) {  // along the rim's direction: f is linear
    if (abs(qb) < 1e-12) {
      if (qc < 0.0) return false;
    } else if (qb > 0.0) lo = max(lo, -qc / qb); else hi = min(hi, -qc / qb);
  } else if (disc < 0.0) {
    if (qa < 0.0) return false;  // outside the double cone everywhere
  } else {
    float sq = sqrt(disc);
    float r0 = min((-qb - sq) / (2.0 * qa), (-qb + sq) / (2.0 * qa));
    float r1 = max((-qb - sq) / (2.0 * qa), (-qb + sq) / (2.0 * qa));
    if (qa < 0.0) {  // crosses the cone: inside between the roots
      lo = max(lo, r0);
      hi = min(hi, r1);
    } else if (dA > 0.0) {  // ends up inside the forward nappe: after the later root
      lo = max(lo, r1);
    } else {  // came from inside the forward nappe: before the earlier root
      hi = min(hi, r0);
    }
  }
  a = max(t0, lo);
  b = min(t1, hi);
  return a < b;
}

// Optical depth sum sigma_t dt over [ta, tb] (midpoint rule, n samples) of the ray: the parts a
// clipped march does not sample for in-scattering still attenuate.
float opticalDepthOver(vec3 o, vec3 d, float ta, float tb, int n) {
  if (tb <= ta) return 0.0;
  float h = (tb - ta) / float(n), sum = 0.0;
  for (int i = 0; i < n; ++i) {
    vec3 x = o + d * (ta + (float(i) + 0.5) * h);
    sum += u_extinctionRatio * (texture(u_scattering, worldToVolumeUV(x)).r + u_hazeScattering) * h;
  }
  return sum;
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
  // The sampled segment [sa, sb]: the whole of [t0, t1], or with u_clipToCone under a spot light
  // its part inside the cone (elsewhere nothing scatters towards the camera). The parts before and
  // after still attenuate: their optical depth is added at the first and after the last sample.
  float sa = t0, sb = t1;
  bool clipped = u_clipToCone == 1 && lightType() == VOXLAB_LIGHT_SPOT && len > 0.0;
  bool sampled = len > 0.0;
  if (clipped) sampled = clipToSpotCone(u_cameraPos, dir, t0, t1, sa, sb);
  if (!sampled) sa = sb = t1;
  float dt = sampled ? (sb - sa) / float(u_steps) : 0.0;
  float u = ditherOffset(q);

  vec3 sum = u_sample == 0 ? vec3(0.0) : imageLoad(u_inscatter, q).rgb;
  float depthBefore = u_sample == 0 ? 0.0 : imageLoad(u_opticalDepth, q).r;
  if (clipped && u_sample == 0) depthBefore = opticalDepthOver(u_cameraPos, dir, t0, sa, u_steps);
  float t = sa + (float(u_sample) + u) * dt;
  vec3 x = u_cameraPos + dir * t;
  float sigmaS = 0.0, lit = 0.0, mu = 0.0, phase = 0.0, T = 1.0;
  vec3 E = vec3(0.0), contribution = vec3(0.0);
  if (sampled) {
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
  if (clipped && u_sample == u_steps - 1) depthBefore += opticalDepthOver(u_cameraPos, dir, sb, t1, u_steps);
  imageStore(u_inscatter, q, vec4(sum, 1.0));
  imageStore(u_opticalDepth, q, vec4(depthBefore));
  imageStore(u_transmittance, q, vec4(exp(-depthBefore)));
  imageStore(u_rayLength, q, vec4(len));

  if (q == u_probePixel) {
    vec3 v = worldToVoxel(x);
    records[u_sample].voxel = vec4(v, t);
    records[u_sample].world = vec4(x, u);
    float count = sampled ? float(texelFetch(u_counts, clamp(ivec3(floor(v)), ivec3(0), ivec3(u_resolution - 1)), 0).r) : 0.0;
    records[u_sample].medium = vec4(lit, sigmaS, u_extinctionRatio * sigmaS, count);
    records[u_sample].phase = vec4(mu, phase, dot(E, vec3(0.2126, 0.7152, 0.0722)), T);
    records[u_sample].contribution = vec4(contribution, dot(sum, vec3(0.2126, 0.7152, 0.0722)));
    recordCount = uint(u_sample + 1);
  }
}
