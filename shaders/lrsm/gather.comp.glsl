#version 450
// Cone gathering (src/techniques/lrsm/lrsm.h): per traced pixel, 6 diffuse cones, 1 specular
// cone and 1 shadow cone march sphere samples; alpha_i comes from the isotropic occlusion mips,
// L_i from the layered RSM by Algorithm 1, composited front to back with Eq. 1.
//
// The probed pixel's records (cone samples, Algorithm 1's layers, cone results) come from the
// recorder (common/probe_recorder.glsl), which writes no image: behind a per-pixel flag they cost
// every pixel their stores at every sample and layer (about 15 % of the gather).
#include "common/shared.h"
#include "common/lights.glsl"
#include "common/voxel_space.glsl"
#include "common/sky.glsl"
#include "common/step_opacity.glsl"
#include "common/probe_recorder.glsl"
#include "lrsm/lrsm_shared.h"
#include "lrsm/lrsm_common.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler3D u_occlusion;
layout(binding = 1) uniform sampler2D u_lrsmRadiance;
layout(binding = 2) uniform sampler2D u_lrsmNormal;
layout(binding = 3) uniform sampler2D u_lrsmMoments;
layout(binding = 4) uniform sampler2D u_position;
layout(binding = 5) uniform sampler2D u_normal;
layout(binding = 6) uniform sampler2D u_albedo;
layout(rgba32f, binding = 0) uniform writeonly image2D u_diffuse;
layout(rgba16f, binding = 1) uniform writeonly image2D u_specular;
layout(r16f, binding = 2) uniform writeonly image2D u_shadow;
uniform int u_traceShadow;  // 0: the soft-shadow image is not wanted (outputs on demand)
layout(std430, binding = VOXLAB_BINDING_CONE_SAMPLES) writeonly buffer ConeSamples { ConeSample coneSamples[]; };
layout(std430, binding = VOXLAB_BINDING_CONE_SAMPLE_COUNT) buffer ConeSampleCount { uint coneSampleCount; };
layout(std430, binding = LRSM_BINDING_GATHER) writeonly buffer Gather { LrsmGatherRecord gather[]; };
layout(std430, binding = LRSM_BINDING_GATHER_COUNT) buffer GatherCount { uint gatherCount; };
layout(std430, binding = LRSM_BINDING_CONE_RESULTS) writeonly buffer Cones { LrsmConeResult coneResults[]; };

uniform int u_layerWidth, u_lrsmLevels, u_voxelLevels, u_maxSteps, u_traceScale;
uniform int u_traceSpecular;  // 1: trace the specular cone
// The gather's choices, fixed per program (ConeGatherStage builds it with these defines): llvmpipe
// runs both sides of a branch on a uniform, so as uniforms every sample also paid for the choices
// not taken (the gather took 1.2 times as long at the defaults).
const int kEstimator = LRSM_ESTIMATOR;            // LRSM_ESTIMATOR_*: what a sample adds to Eq. 1 (src/techniques/lrsm/lrsm.h)
const int kWindowLayers = LRSM_WINDOW_LAYERS;     // 1: every layer whose texels' interval meets the depth window, f = 1; 0: Eq. 15
const int kSmoothFalloff = LRSM_SMOOTH_FALLOFF;   // 1: Eq. 15's falloff smoothstepped (lrsm.falloff)
const int kLitOcclusion = LRSM_LIT_OCCLUSION;     // 1: a sample's opacity is at least the lit surface's coverage (coverage estimator)
const int kHorizon = LRSM_HORIZON;                // 1: the receiver's plane bounds what its diffuse cones see (cone.horizon)
const int kVisibility = LRSM_VISIBILITY;          // 1: Eq. 12 (Gaussian depth visibility); 0: V = 1 (every texel of the column)
const int kTwoLobes = LRSM_TWO_LOBES;             // 1: V from two Gaussians matched to four depth moments (lrsm.two-lobes)
uniform float u_footprintBias;  // added to log2(d_circle): the LRSM level, blended between its two neighbours
uniform float u_minVariance, u_stepScale, u_startVoxels, u_lodBias;
uniform float u_shadowLodBias;  // the shadow cone's (cone.shadow-lod-bias)
uniform float u_diffuseTanHalf, u_specularTanHalf, u_shadowTanHalf;
uniform vec3 u_cameraPos;
uniform vec4 u_diffuseCones[6];  // tangent space direction, weight (sum pi)
uniform ivec2 u_probePixel;
uniform int u_interleave;  // 1: each pixel of a 4 x 4 tile shifts its diffuse cones' steps (cone.interleave)
const float PI = 3.14159265358979;

bool g_record = false;
int g_cone = 0, g_step = 0;
float g_voxelMip = 0.0, g_alpha = 0.0, g_transmittance = 1.0;

// Bilinear fetch of one layer's tile at an LRSM level, clamped half a texel inside the tile so
// that the filter never reaches a neighbouring layer (the texture filters GL_LINEAR within the
// level, GL_LINEAR_MIPMAP_NEAREST picks exactly 'level').
vec4 fetchLayerLevel(sampler2D s, int layer, int level, vec2 uv) {
  float w = float(max(u_layerWidth >> level, 1));
  float layers = float(u_depthIntervals * u_normalIntervals);
  vec2 inTile = clamp(uv, vec2(0.5 / w), vec2(1.0 - 0.5 / w));
  return textureLod(s, vec2((float(layer) + inTile.x) / layers, inTile.y), float(level));
}
// The layer at a fractional level: its two neighbouring levels blended (trilinear, written out:
// each level clamped inside its own tile), so that the footprint grows smoothly with the sphere
// and no level switch draws a ring on a receiver.
vec4 fetchLayer(sampler2D s, int layer, float level, vec2 uv) {
  int l0 = int(floor(level));
  int l1 = min(l0 + 1, u_lrsmLevels - 1);
  float t = level - float(l0);
  return mix(fetchLayerLevel(s, layer, l0, uv), fetchLayerLevel(s, layer, l1, uv), t);
}

// Where p lies in the light's image (the RSM is twice a layer's width): one view, or the cube
// face of a point light that looks at it (a face's tile of the atlas; a sphere near a face's edge
// reads that face only).
vec2 lightUV(vec3 p) {
  vec3 uvz;
  lightMapCoord(p, lightMapFace(p), ivec2(2 * u_layerWidth), uvz);
  return uvz.xy;
}

// The coverage estimator reads A V <n.v> / <n.l> as a fraction of the footprint and lends it to
// the cone's cross-section, which holds while the sphere is small against its distance zc from a
// spot or point light (Eq. 3 takes r, the surface's distance from the light, as constant over the
// sample). A sphere that reaches near the lamp breaks it: its footprint's lit surface may lie at
// zs << zc, a small patch of surface (area ~ zs^2 per steradian of the light's image) with the
// lamp's 1/zs^2 radiance, which the fraction would spread over the whole cross-section (the far
// samples of a long corridor lit from its end). Bound: the surface the footprint can hold at
// depth zs, Omega zs^2 (Omega = 2 pi (1 - cos a), sin a = rc / zc, the sphere's silhouette from
// the light; all directions once the sphere holds the light), seen from the receiver at distance
// ds, covers at most Omega zs^2 / ds^2 of solid angle, against pi rc^2 / t^2 of the sample's
// (t: the sample's distance from the receiver). 1 for a small sphere with zs near zc. A
// directional light's footprint has the sphere's own cross-section at every depth: 1.
float solidAngleBound(float zc, float rc, float zs, float t, float ds) {
  if (lightType() <= VOXLAB_LIGHT_DIRECTIONAL + 0.5) return 1.0;
  float s = min(rc / max(zc, 1e-6), 1.0);
  // Omega / pi = 2 (1 - cos a), written without the cancellation of 1 - cos a at small a.
  float omegaOverPi = 2.0 * s * s / (1.0 + sqrt(1.0 - s * s));
  return min(omegaOverPi * (zs * t) * (zs * t) / max((rc * ds) * (rc * ds), 1e-12), 1.0);
}

// Does depth interval d's texel range (its classification interval; the first and last open
// toward zNear and zFar) meet [z0, z1]?
bool intervalMeets(int d, float z0, float z1) {
  float w = (u_zFar - u_zNear) / float(u_depthIntervals);
  float lo = d == 0 ? -1e30 : u_zNear + w * float(d);
  float hi = d + 1 == u_depthIntervals ? 1e30 : u_zNear + w * float(d + 1);
  return z1 >= lo && z0 <= hi;
}

// The weight f of depth interval d's layers for a sample at light depth zc whose depth window is
// zc +- halfWindow: 1 or 0 (every layer whose texels' interval meets the window) or Eq. 15.
float layerWeight(int d, float zc, float halfWindow) {
  return kWindowLayers == 1 ? (intervalMeets(d, zc - halfWindow, zc + halfWindow) ? 1.0 : 0.0)
                            : layerFalloff(d, zc, kSmoothFalloff == 1);
}

// Depth interval d's warped coordinates of the sample: z_c in the layer's range (z') and half the
// depth window (r').
void warpedWindow(int d, float zc, float halfWindow, out float zw, out float rw) {
  float lo, hi;
  layerRange(d, lo, hi);
  zw = (zc - lo) / (hi - lo);
  rw = halfWindow / (hi - lo);
}

// One layer's record of the probed pixel's sample (LrsmGatherRecord, lrsm_shared.h; its sample's
// cone, step, voxel mip, alpha and transmittance from the march's globals).
void recordLayer(vec3 xc, float rc, vec2 uv, float level, int l, float f, float N, vec4 moments, vec4 ar,
                 vec4 contribution, vec3 footprint) {
  uint k = atomicAdd(gatherCount, 1u);
  if (k < uint(LRSM_MAX_GATHER_RECORDS))
    gather[k] = LrsmGatherRecord(vec4(xc, rc), vec4(float(g_cone), float(g_step), g_voxelMip, g_alpha),
                                 vec4(g_transmittance, uv, level), vec4(float(l), f > 0.0 ? 1.0 : 0.0, f, N), moments,
                                 ar, contribution, vec4(footprint, 1.0));
}

// The probed pixel's records of depth interval d's layers where the sample reads none of them
// (f = 0): what the loop over the layers read would record for them.
void recordSkippedLayers(int d, vec3 xc, float rc, vec2 uv, float level, float zc, float halfWindow, float dCircle) {
  float zw, rw;
  warpedWindow(d, zc, halfWindow, zw, rw);
  for (int m = 0; m < u_normalIntervals; ++m)
    recordLayer(xc, rc, uv, level, d * u_normalIntervals + m, 0.0, 0.0, vec4(0.0, 0.0, 0.0, zw), vec4(0.0),
                vec4(vec3(0.0), rw), vec3(dCircle, zc, 1.0));
}

// Algorithm 1 for the sphere (xc, rc) seen from the receiver p: what the sample adds to Eq. 1
// before the transmittance (rgb) and the opacity it would carry (a) by the estimator chosen:
//   coverage   sum_l A*R V <n.v> / <n.l>: the lit surface's radiance times the fraction of the
//              cone's cross-section it covers (Eq. 3's Jacobian r^2 / <n.l> turns light-image
//              area into surface area, <n.v> projects it toward the receiver); the depth window
//              is half a step wide each side, so consecutive samples count a surface once.
//   paper      sum_l f A*R V N as printed; the caller multiplies it by alpha_i.
vec3 sampleLrsm(vec3 xc, float rc, float stepLength, vec3 p, vec3 pn, out vec2 litCoverage) {
  litCoverage = vec2(0.0);
  vec2 uv = lightUV(xc);
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return vec3(0.0);
  // Two directions perpendicular to the light ray through xc; the projected radius is their mean.
  bool radial = lightType() > VOXLAB_LIGHT_DIRECTIONAL + 0.5;  // spot or point
  vec3 ray = radial ? normalize(xc - u_light.positionType.xyz) : u_light.directionRange.xyz;
  vec3 e1 = normalize(cross(ray, abs(ray.y) < 0.9 ? vec3(0, 1, 0) : vec3(1, 0, 0)));
  vec3 e2 = cross(ray, e1);
  float uvRadius = 0.5 * (length(lightUV(xc + rc * e1) - uv) + length(lightUV(xc + rc * e2) - uv));
  float dCircle = 2.0 * uvRadius * float(u_layerWidth);
  // A point light's faces are tiles of the layer: a level whose texels span a tile would blend
  // another face's surfaces into this one, so the level stops where a tile is 4 texels wide.
  const float topLevel = lightType() == VOXLAB_LIGHT_POINT
                             ? max(floor(log2(float(u_layerWidth / 3))) - 2.0, 0.0) : float(u_lrsmLevels - 1);
  float level = clamp(log2(max(dCircle, 1.0)) + u_footprintBias, 0.0, min(topLevel, float(u_lrsmLevels - 1)));
  float zc = lightDepth(xc);
  vec3 vc = normalize(p - xc);
  vec3 toLight = -ray;
  bool coverage = kEstimator == LRSM_ESTIMATOR_COVERAGE;
  // Half-width of the depth window: the sphere's radius (Algorithm 1) or half the step (coverage).
  float halfWindow = coverage ? 0.5 * stepLength : rc;
  // The layers a sample reads (f > 0) are a few of the depth intervals (at the defaults one of two,
  // two where the window straddles their border): the loop below visits only the intervals from
  // the first to the last that the sample reads. llvmpipe runs every iteration's reads for every
  // lane, so a loop over all intervals paid the reads of the layers no lane of the row needed.
  int dFirst = u_depthIntervals, dLast = -1;
  for (int d = 0; d < u_depthIntervals; ++d) {
    if (layerWeight(d, zc, halfWindow) > 0.0) {
      dFirst = min(dFirst, d);
      dLast = d;
    }
  }
  // The probed pixel records every layer in order, those before and after the ones read too.
  if (g_record)
    for (int d = 0; d < dFirst; ++d) recordSkippedLayers(d, xc, rc, uv, level, zc, halfWindow, dCircle);
  vec3 L = vec3(0.0);
  for (int d = dFirst; d <= dLast; ++d) {
    float f = layerWeight(d, zc, halfWindow);
    float lo, hi;
    layerRange(d, lo, hi);
    float zw, rw;
    warpedWindow(d, zc, halfWindow, zw, rw);
    for (int m = 0; m < u_normalIntervals; ++m) {
      int l = d * u_normalIntervals + m;
      float N = 0.0, mu = 0.0, sigma2 = 0.0, V = 0.0, jacobian = 1.0;
      vec4 ar = vec4(0.0);
      vec3 add = vec3(0.0);
      if (f > 0.0) {
        vec4 nm = fetchLayer(u_lrsmNormal, l, level, uv);
        float alpha = nm.w;
        if (alpha > 1e-4) {
          vec4 mo = fetchLayer(u_lrsmMoments, l, level, uv);
          vec4 moments = mo / alpha;  // E[z'], E[z'^2], E[z'^3], E[z'^4]
          mu = moments.x;
          sigma2 = max(moments.y - mu * mu, u_minVariance);
          vec3 nMean = nm.xyz / alpha;
          // The layer's depths as lobes (depthLobes): one Gaussian, or two where the layer holds
          // two surfaces at different depths; each lobe is a surface of its own (its mean point,
          // horizon, V and Jacobian), sharing the layer's normal and radiance.
          vec3 means, weights, variances;
          int lobes = coverage && kVisibility == 1 && kTwoLobes == 1
                          ? depthLobes(moments, u_minVariance, means, weights, variances)
                          : singleLobe(mu, sigma2, means, weights, variances);
          // The layer's radiance, read once before the lobes (llvmpipe would read it in every
          // lobe's iteration, masked or not); recorded only where a lobe adds light.
          vec4 radiance = fetchLayer(u_lrsmRadiance, l, level, uv);
          float sumN = 0.0, sumAdded = 0.0;
          V = 0.0;
          for (int k = 0; k < lobes; ++k) {
            if (weights[k] <= 0.0) continue;
            float zs = lo + means[k] * (hi - lo);
            // coverage: the receiver seen from the lobe's mean surface point on the light ray
            // through x_c (depth mu), not from x_c: a sphere that holds the receiver's own plane
            // then sees it edge-on (N near 0), neither lit nor blocking.
            vec3 xs = xc + ray * (zs - zc);
            float Nk = dot(nMean, coverage ? normalize(p - xs) : vc);
            // A surface behind the receiver's plane, or in it, is below its horizon: it neither
            // lights nor shades the hemisphere (the receiver's own plane and the other faces of a
            // box, seen by the light at grazing angles, would).
            if (coverage && kHorizon == 1 && dot(xs - p, pn) < LRSM_HORIZON_VOXELS * u_voxelSize) Nk = 0.0;
            // Algorithm 1 culls back faces; the coverage estimator keeps them as occluders.
            if (coverage ? Nk == 0.0 : Nk <= 0.0) continue;
            float Vk = weights[k] * (kVisibility == 0 ? 1.0 : gaussianVisibility(zw, rw, means[k], variances[k]));
            // <n.l> of the layer's mean normal, floored: R carries <n.l>, so A*R / <n.l> stays
            // bounded as the surface turns edge-on to the light.
            float Jk = coverage ? solidAngleBound(zc, rc, zs, length(xc - p), length(xs - p)) /
                                      max(dot(nMean, toLight), LRSM_MIN_NDOTL)
                                : 1.0;
            if (coverage) {
              // The fraction of the cone's cross-section the lit surface covers: x facing the
              // receiver, y facing away (which sends nothing but blocks: a lit wall between rooms).
              float c = f * alpha * Vk * abs(Nk) * Jk;
              litCoverage += Nk > 0.0 ? vec2(c, 0.0) : vec2(0.0, c);
            }
            if (Nk > 0.0 && Vk > 0.0) {
              ar = radiance;
              add += f * ar.rgb * Vk * Nk * Jk;
              sumAdded += Vk * Nk * Jk;
              sumN += Vk * Nk;
            }
            V += Vk;
          }
          // Recorded: V summed over the lobes, N the V-weighted mean of the lobes that add light
          // (a lobe facing away blocks but adds nothing), J such that f A*R V N J is what they added.
          N = V > 0.0 ? sumN / V : 0.0;
          jacobian = V * N != 0.0 ? sumAdded / (V * N) : 1.0;
        }
      }
      L += add;
      if (g_record)
        recordLayer(xc, rc, uv, level, l, f, N, vec4(mu, sigma2, V, zw), ar, vec4(add, rw), vec3(dCircle, zc, jacobian));
    }
  }
  if (g_record)
    for (int d = max(dLast + 1, dFirst); d < u_depthIntervals; ++d) recordSkippedLayers(d, xc, rc, uv, level, zc, halfWindow, dCircle);
  return L;
}

// Marches one cone from p (normal n) along dir, its first sample 'phase' of a step beyond
// cone.start; returns I (rgb, Eq. 1) and the opacity (a).
// radiance = false: the shadow cone (occlusion only, until the light or the volume's edge).
vec4 traceCone(vec3 p, vec3 n, vec3 dir, float tanHalf, float lodBias, bool radiance, float maxDistance, int coneIndex,
               bool record, float phase) {
  vec3 origin = p + n * u_voxelSize;
  float t = u_startVoxels * u_voxelSize;
  t += phase * max(2.0 * tanHalf * t, u_voxelSize) * u_stepScale;  // phase: a fraction of the first step
  vec3 I = vec3(0.0);
  float T = 1.0;
  int steps = 0;
  bool left = false;  // the sample lay wholly outside the volume
  for (int step = 0; step < u_maxSteps && T > 0.01 && t < maxDistance; ++step) {
    float diameter = max(2.0 * tanHalf * t, u_voxelSize);
    vec3 x = origin + dir * t;
    vec3 uvw = worldToVolumeUV(x);
    float margin = 0.5 * diameter / (u_voxelSize * float(u_resolution));
    if (any(lessThan(uvw, vec3(-margin))) || any(greaterThan(uvw, vec3(1.0 + margin)))) { left = true; break; }
    float mip = clamp(log2(diameter / u_voxelSize) + lodBias, 0.0, float(u_voxelLevels - 1));
    if (radiance && kHorizon == 1) {
      // The receiver's own surface does not occlude its hemisphere: the filter stays above the
      // plane. A texel of edge s holding a surface voxel has its centre at most s/2 + 1 voxel from
      // the surface and the trilinear filter reaches one texel, so s <= (h - voxel) / 1.5.
      float h = dot(x - p, n);
      mip = min(mip, max(log2(max(h - u_voxelSize, 0.0) / (1.5 * u_voxelSize)), 0.0));
    }
    float a = textureLod(u_occlusion, uvw, mip).r;
    float stepLength = diameter * u_stepScale;
    a = stepOpacity(a, stepLength / (u_voxelSize * exp2(mip)));
    g_record = record; g_cone = coneIndex; g_step = step; g_voxelMip = mip; g_alpha = a; g_transmittance = T;
    // coverage: the sample's own estimate of the lit surface it holds, weighted by the
    // transmittance in front of it; paper: Eq. 1 with L_i from Algorithm 1.
    if (radiance) {
      vec2 lit;
      if (kEstimator == LRSM_ESTIMATOR_COVERAGE) {
        I += T * sampleLrsm(x, 0.5 * diameter, stepLength, p, n, lit);
        // Eq. 1's alpha_i: the voxels' opacity, or the lit surfaces' coverage where that is more
        // (a lit surface blocks what lies behind it; the isotropic mips of a thin wall let most through).
        if (kLitOcclusion == 1) a = max(a, min(lit.x + lit.y, 1.0));
      } else if (a > 0.0) I += T * a * sampleLrsm(x, 0.5 * diameter, stepLength, p, n, lit);
    }
    T *= 1.0 - a;
    steps = step + 1;
    if (record) {
      uint k = atomicAdd(coneSampleCount, 1u);
      if (k < uint(VOXLAB_MAX_CONES * VOXLAB_MAX_SAMPLES_PER_CONE))
        coneSamples[k] = ConeSample(vec4(x, diameter), vec4(I, 1.0 - T), vec4(float(coneIndex), t, mip, a));
    }
    t += stepLength;
  }
  g_record = false;
  // A radiance cone that escaped sees the sky through its transmittance (common/sky.glsl).
  if (radiance) I += coneSky(left, t >= maxDistance, origin + dir * t, 1.0 - T);
  if (record) coneResults[coneIndex] = LrsmConeResult(vec4(dir, 0.0), vec4(I, 1.0 - T), vec4(float(coneIndex), float(steps), 0.0, 0.0));
  return vec4(I, 1.0 - T);
}

void main() {
  const bool record = kRecordProbe;
  ivec2 px;
  if (!recorderPixel(u_probePixel, px)) return;
  ivec2 size = imageSize(u_diffuse);
  if (any(greaterThanEqual(px, size))) return;
  ivec2 g = min(px * u_traceScale, textureSize(u_position, 0) - 1);
  vec4 pos = texelFetch(u_position, g, 0);
  if (pos.w == 0.0) {
#ifndef VOXLAB_RECORD_PROBE
    imageStore(u_diffuse, px, vec4(0.0));
    imageStore(u_specular, px, vec4(0.0));
    if (u_traceShadow == 1) imageStore(u_shadow, px, vec4(1.0));
#endif
    return;
  }
  vec3 p = pos.xyz;
  vec3 n = normalize(texelFetch(u_normal, g, 0).xyz);
  vec3 albedo = texelFetch(u_albedo, g, 0).rgb;
  vec3 tx = normalize(abs(n.x) < 0.9 ? cross(n, vec3(1, 0, 0)) : cross(n, vec3(0, 1, 0)));
  vec3 ty = cross(n, tx);
  // Interleaved steps: each pixel of a 4 x 4 tile starts its diffuse cones' sphere samples at
  // its own fraction of the first step (a Bayer order: neighbours take far-apart fractions,
  // centred on cone.start). With one start for every pixel, a flat surface's receivers all place
  // their samples at the same heights above it, and where a sample's depth window meets a wall
  // or a floor the count jumps from one receiver to the next: swirls round the lamp on the
  // Cornell ceiling, a dark patch on the tall box. The filter stage averages the tile.
  float phase = 0.0;
  if (u_interleave == 1) {
    const int bayer[16] = int[16](0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5);
    phase = (float(bayer[(px.y & 3) * 4 + (px.x & 3)]) + 0.5) / 16.0 - 0.5;
  }
  float far = u_voxelSize * float(u_resolution) * 1.7320508;
  vec3 E = vec3(0.0);
  for (int k = 0; k < 6; ++k) {
    vec3 d = normalize(u_diffuseCones[k].x * tx + u_diffuseCones[k].y * ty + u_diffuseCones[k].z * n);
    vec4 c = traceCone(p, n, d, u_diffuseTanHalf, u_lodBias, true, far, k, record, phase);
    E += u_diffuseCones[k].w * c.rgb;
    if (record) { coneResults[k].direction.w = u_diffuseCones[k].w; coneResults[k].info.zw = vec2(2.0 * atan(u_diffuseTanHalf), 0.0); }
  }
  vec3 view = normalize(p - u_cameraPos);
  vec3 mirror = reflect(view, n);
  vec4 spec = u_traceSpecular == 1 ? traceCone(p, n, mirror, u_specularTanHalf, u_lodBias, true, far, 6, record, 0.0) : vec4(0.0);
  // A cone that is not traced is still recorded under its own index, with no steps.
  if (record && u_traceSpecular != 1) coneResults[6] = LrsmConeResult(vec4(mirror, 0.0), vec4(0.0), vec4(6.0, 0.0, 0.0, 0.0));
  if (record) coneResults[6].info.zw = vec2(2.0 * atan(u_specularTanHalf), 1.0);
  vec3 toLight; float dist;
  lightDirection(p, toLight, dist);
  const float shadowEnd = min(shadowConeEnd(dist, u_shadowTanHalf, u_shadowLodBias, u_voxelSize), far);
  // Without the soft-shadow image (outputs on demand) only the probed pixel traces it, for its record.
  const bool shadowCone = dot(n, toLight) > 0.0 && (u_traceShadow == 1 || record);
  vec4 shadow = shadowCone ? traceCone(p, n, toLight, u_shadowTanHalf, u_shadowLodBias, false, shadowEnd, 7, record, 0.0)
                                      : vec4(0.0, 0.0, 0.0, 1.0);
  if (record && dot(n, toLight) <= 0.0) coneResults[7] = LrsmConeResult(vec4(toLight, 0.0), vec4(0.0, 0.0, 0.0, 1.0), vec4(7.0, 0.0, 0.0, 0.0));
  if (record) coneResults[7].info.zw = vec2(2.0 * atan(u_shadowTanHalf), 2.0);
  vec3 diffuse = albedo / PI * E;
#ifndef VOXLAB_RECORD_PROBE
  imageStore(u_diffuse, px, vec4(diffuse, 1.0));
  imageStore(u_specular, px, vec4(spec.rgb, 1.0));
  if (u_traceShadow == 1) imageStore(u_shadow, px, vec4(1.0 - shadow.a));
#endif
  if (record) coneResults[LRSM_MAX_CONES] = LrsmConeResult(vec4(n, PI), vec4(diffuse, 0.0), vec4(float(LRSM_MAX_CONES), 0.0, 0.0, 3.0));
}
