// Cone tracing through a prefiltered (mipmapped) voxel volume of premultiplied radiance and
// opacity (Crassin et al. 2011). Along the cone the sample diameter grows as 2 t tan(aperture/2);
// the mip level lod = log2(diameter / voxel) + bias is sampled quadrilinearly (bias -1, the
// default, makes the filter's full support, two texels, equal to the diameter, so a cone does
// not see the surface it starts from); samples are composited front to back. Steps are half the
// sample diameter (u_stepScale = 0.5); each sample's opacity, which belongs to a path one texel
// long, is corrected to the distance actually stepped: a' = 1 - (1 - a)^(step / texel).
#include "common/shared.h"
#include "common/voxel_space.glsl"
#include "common/sky.glsl"
#include "common/anisotropic_mip.glsl"
#include "common/facing.glsl"
#include "common/step_opacity.glsl"

layout(binding = 0) uniform sampler3D u_radiance;   // isotropic: every level; anisotropic: level 0
// Anisotropic levels 1.. (their level 0 is level 1 of the hierarchy), one volume per travel
// direction, two per texture: at each level of u_dirX the volume seen by a cone travelling along
// +x fills z in [0, n), the one for -x z in [n, 2n) (n: the level's edge); likewise y and z
// (src/techniques/vct_grid/bounce_stage.cpp, bindRadianceGrid, copies them in).
layout(binding = 8) uniform sampler3D u_dirX;
layout(binding = 9) uniform sampler3D u_dirY;
layout(binding = 10) uniform sampler3D u_dirZ;
// Anisotropic levels 1..: the opacity of the voxels as solid cubes a cone travelling along x, y, z
// sees (r, g, b), the same travelling either way; the directional volumes' alpha is the coverage
// of the surfaces' fronts only (vct_grid/mipmap_anisotropic.comp.glsl).
layout(binding = 11) uniform sampler3D u_solidOpacity;
// Which volumes a sample reads, fixed per program by the stage's defines (vct_grid/stages.h,
// coneVolumeDefines): llvmpipe runs both sides of every branch, so with these as uniforms every
// sample also paid for the lookups of the modes not chosen. Without defines: the defaults.
#ifndef CONE_ANISOTROPIC
#define CONE_ANISOTROPIC 1           // mipmap.mode=anisotropic
#endif
#ifndef CONE_CLASSIC_DIRECTIONAL
#define CONE_CLASSIC_DIRECTIONAL 0   // 1: the directional volumes hold whole voxels (mipmap.fronts=false)
#endif
uniform float u_stepScale;     // step length as a fraction of the sample diameter
uniform float u_lodBias;       // added to log2(diameter / voxel size); -1 = filter support equals the diameter
uniform int u_maxSteps;

// What this invocation's cones cost: samples taken and volume lookups (a fetch of up to 16 texels:
// one textureLod, or for a directional volume one per level read, two but in the fade of phase 1),
// for the stage's statistics.
uint g_samples = 0u;
uint g_fetches = 0u;

// Level 'level' of one direction's volume at uvw (that volume's own [0,1]^3), as a lookup of the
// volume alone gives it: in z the coordinate is clamped to the centres of the edge texels (what
// clamp-to-edge does to the texels a linear filter reads), so the half of the other direction is
// read with weight exactly 0; x and y are clamped by the texture itself. (The edge comes from level
// 0's size: llvmpipe answers textureSize for one lane's level, so a per-pixel level there would
// give other pixels the wrong edge.)
vec4 directionalLevel(sampler3D pair, vec3 uvw, int level, bool negative) {
  float n = float(max(textureSize(pair, 0).x >> level, 1));
  float z = clamp(uvw.z * n, 0.5, n - 0.5) + (negative ? n : 0.0);
  return textureLod(pair, vec3(uvw.xy, z / (2.0 * n)), float(level));
}
// One direction's volume at level of detail lod, quadrilinear: its two levels blended, as textureLod
// blends them. Why not one textureLod of a volume per direction: which volume (+x or -x) depends on
// the cone's direction, which differs between the pixels of a SIMD row, and llvmpipe then fetches
// from both volumes for every pixel; here the sign is an offset and every pixel shares the lookups
// (docs/performance.md, vct-grid).
vec4 directionalLookup(sampler3D pair, vec3 uvw, float lod, bool negative) {
  int top = textureQueryLevels(pair) - 1;
  float l = clamp(lod, 0.0, float(top));
  int l0 = int(l);
  int l1 = min(l0 + 1, top);
  return mix(directionalLevel(pair, uvw, l0, negative), directionalLevel(pair, uvw, l1, negative), l - float(l0));
}

const float kSeesNothing = 0.25;

// The prefiltered volume seen by a cone travelling along 'dir' at level of detail 'lod', and in
// 'solid' the opacity of its voxels as solid cubes. With
// anisotropic mips, the three directional volumes facing the cone are blended with weights dir^2
// (they sum to 1); between level 0 and 1 the isotropic voxels fade into the directional level.
// 'phase' says which lookups the caller's lod needs (traceCone marches in three phases): 0 = lod is
// 0, the isotropic voxels alone; 1 = 0 < lod < 1, the fade; 2 = lod >= 1, directional volumes only.
// llvmpipe evaluates both sides of a condition that differs between the pixels of a SIMD row (the
// volume of +x or of -x: the cone's direction), so what a phase does not need must not be in its
// code at all; each phase gives the same result as the general expression for its lods.
vec4 sampleVolume(vec3 uvw, float lod, vec3 dir, int phase, bool wantSolid, out float solid) {
  if (CONE_ANISOTROPIC == 0) {
    g_fetches += 1u;
    vec4 s = textureLod(u_radiance, uvw, lod);
    solid = s.a;
    return s;
  }
  if (phase == 0) {
    g_fetches += 1u;
    vec4 s = textureLod(u_radiance, uvw, 0.0);
    solid = s.a;
    return s;
  }
  g_fetches += (phase == 1 ? 4u : 3u) + (wantSolid ? 1u : 0u);
  vec3 w = anisotropicWeights(dir);
  // In the fade (lod < 1) the directional lod is 0: one level, one texture read per volume.
  float l = phase == 1 ? 0.0 : max(lod - 1.0, 0.0);
  vec4 sx = phase == 1 ? directionalLevel(u_dirX, uvw, 0, dir.x < 0.0) : directionalLookup(u_dirX, uvw, l, dir.x < 0.0);
  vec4 sy = phase == 1 ? directionalLevel(u_dirY, uvw, 0, dir.y < 0.0) : directionalLookup(u_dirY, uvw, l, dir.y < 0.0);
  vec4 sz = phase == 1 ? directionalLevel(u_dirZ, uvw, 0, dir.z < 0.0) : directionalLookup(u_dirZ, uvw, l, dir.z < 0.0);
  if (CONE_CLASSIC_DIRECTIONAL != 0) {
    // Crassin's classic blend: the three premultiplied values weighted by dir^2; opacity is theirs.
    if (wantSolid) g_fetches -= 1u;  // no solid-opacity lookup
    vec4 classic = w.x * sx + w.y * sy + w.z * sz;
    solid = classic.a;
    if (phase == 2) return classic;
    vec4 iso0 = textureLod(u_radiance, uvw, 0.0);
    solid = mix(iso0.a, solid, lod);
    return mix(iso0, classic, lod);
  }
  // The volumes show only the fronts of the surfaces they see (common/facing.glsl, seenFronts).
  vec4 a = seenFronts(w, sx, sy, sz);
  // What blocks a ray whichever way its surfaces face (ambient occlusion, cone-traced shadows): the
  // voxels as solid cubes, their opacity along each axis blended as the opacities were before the
  // volumes kept the fronts apart (one lookup: the same whichever sign the cone travels).
  // Not wanted (the cone is past its occlusion range and only gathers radiance): not read at all.
  solid = 0.0;
  if (wantSolid) solid = dot(w, textureLod(u_solidOpacity, uvw, l).rgb);
  if (phase == 2) return a;
  vec4 iso = textureLod(u_radiance, uvw, 0.0);
  solid = mix(iso.a, solid, lod);
  return mix(iso, a, lod);
}

// Samples of the probed pixel's cones, for the viewer's cone inspector.
layout(std430, binding = VOXLAB_BINDING_CONE_SAMPLES) writeonly buffer ConeSamples { ConeSample coneSamples[]; };
layout(std430, binding = VOXLAB_BINDING_CONE_SAMPLE_COUNT) buffer ConeSampleCount { uint coneSampleCount; };

struct ConeResult {
  vec3 radiance;    // premultiplied accumulated radiance
  float opacity;    // accumulated opacity of the fronts the radiance comes from
  float blocked;    // accumulated opacity of the voxels as solid cubes (shadows), up to markDistance
  float blockedAt;  // 'blocked' when the cone passed 'markDistance' (ambient occlusion)
};

// One cone's march: where it is and what it has gathered.
struct ConeMarch {
  vec3 origin, dir;
  float tanHalf, t, maxDistance, markDistance;
  int step, coneIndex;
  bool marked, done, record, escaped;
  ConeResult r;
};

float coneLod(float tanHalf, float t) {
  return max(log2(max(2.0 * tanHalf * t, u_voxelSize) / u_voxelSize) + u_lodBias, 0.0);
}

// One sample of the march (phase: see sampleVolume); sets m.done where the cone ends.
void coneStep(inout ConeMarch m, int phase, bool wantSolid) {
  // Done when the radiance is gathered and, up to markDistance, the occlusion too.
  bool gathered = m.r.opacity >= 0.99 && (m.r.blocked >= 0.99 || m.marked);
  if (m.step >= u_maxSteps || gathered || m.t >= m.maxDistance) { m.done = true; return; }
  float diameter = max(2.0 * m.tanHalf * m.t, u_voxelSize);
  float lod = max(log2(diameter / u_voxelSize) + u_lodBias, 0.0);
  vec3 p = m.origin + m.dir * m.t;
  vec3 uvw = worldToVolumeUV(p);
  // Stop once the sample lies wholly outside the volume (edge texels are clamped, so a wall on
  // the volume's boundary stays a wall for samples that straddle it).
  float margin = 0.5 * diameter / (u_voxelSize * float(u_resolution));
  if (any(lessThan(uvw, vec3(-margin))) || any(greaterThan(uvw, vec3(1.0 + margin)))) { m.done = true; m.escaped = true; return; }
  if (!m.marked && m.t > m.markDistance) { m.r.blockedAt = m.r.blocked; m.marked = true; }
  float solid;
  vec4 s = sampleVolume(uvw, lod, m.dir, phase, wantSolid, solid);
  g_samples += 1u;
  float stepLength = diameter * u_stepScale;
  // A texel's opacity belongs to a path as long as the texel; correct it to the step length.
  float texelSize = u_voxelSize * exp2(lod);
  float a = compositeSample(m.r.radiance, m.r.opacity, s, stepLength / texelSize);
  if (wantSolid) m.r.blocked += (1.0 - m.r.blocked) * stepOpacity(solid, stepLength / texelSize);
  if (m.record) {
    uint k = atomicAdd(coneSampleCount, 1u);
    if (k < uint(VOXLAB_MAX_CONES * VOXLAB_MAX_SAMPLES_PER_CONE))
      coneSamples[k] = ConeSample(vec4(p, diameter), vec4(m.r.radiance, m.r.opacity), vec4(float(m.coneIndex), m.t, lod, a));
  }
  m.t += stepLength;
  m.step += 1;
}

// Marches the cone front to back until it is opaque (0.99), leaves the volume, or reaches
// maxDistance; blockedAt is the solid opacity when it passed markDistance. Beyond markDistance the
// solid opacity is not read (two of a directional sample's five lookups), so a cone that gathers
// radiance only (specular, a bounce: traceRadianceCone) ends once its radiance is gathered.
// The march runs in loops by phase of sampleVolume (the lod only grows along a cone) and, from lod
// 1 on, before and after markDistance: every pixel's cone takes the same steps (t depends on the
// aperture and the start only), so a loop's lookups are those all its pixels need.
// Each loop tests its condition at the end of its body, the body guarded by the same test: llvmpipe
// leaves a loop only at the end of an iteration in which no lane is left, so a loop written
// 'while (c) body' runs one more body, every lane masked off and every lookup paid, after its last
// sample; 'do { if (c) body } while (c)' does not, but pays a masked body where no lane enters. So
// there is no loop that is empty at the defaults: the fade (0 < lod < 1, a few samples, all within
// ao.range at the defaults) reads the solid opacity wherever the cone gathers occlusion at all
// (past markDistance it changes nothing the cone returns), and a radiance-only cone has no loop
// before markDistance ('occlusion' is a constant at every call, so the compiler drops that loop).
ConeResult marchCone(vec3 origin, vec3 dir, float aperture, float startDistance, float maxDistance,
                     float markDistance, bool occlusion, int coneIndex, bool record) {
  ConeMarch m;
  m.origin = origin;
  m.dir = dir;
  m.tanHalf = tan(0.5 * aperture);
  m.t = startDistance;
  m.maxDistance = maxDistance;
  m.markDistance = markDistance;
  m.step = 0;
  m.coneIndex = coneIndex;
  m.marked = false;
  m.done = false;
  m.escaped = false;
  m.record = record;
  m.r = ConeResult(vec3(0.0), 0.0, 0.0, 0.0);
#define CONE_MARCH_WHILE(condition, phase, wantSolid) \
  do { if (condition) coneStep(m, phase, wantSolid); } while (condition)
  CONE_MARCH_WHILE(!m.done && coneLod(m.tanHalf, m.t) <= 0.0, 0, true);
  CONE_MARCH_WHILE(!m.done && coneLod(m.tanHalf, m.t) < 1.0, 1, occlusion);
  if (occlusion) CONE_MARCH_WHILE(!m.done && m.t <= markDistance, 2, true);
  CONE_MARCH_WHILE(!m.done, 2, false);
#undef CONE_MARCH_WHILE
  if (!m.marked) m.r.blockedAt = m.r.blocked;
  // The sky through the transmittance left, if the cone escaped (common/sky.glsl).
  m.r.radiance += coneSky(m.escaped, m.t >= m.maxDistance, m.origin + m.dir * m.t, m.r.opacity);
  return m.r;
}

// A cone that gathers radiance and, up to markDistance, occlusion (blockedAt; blocked all along).
ConeResult traceCone(vec3 origin, vec3 dir, float aperture, float startDistance, float maxDistance,
                     float markDistance, int coneIndex, bool record) {
  return marchCone(origin, dir, aperture, startDistance, maxDistance, markDistance, true, coneIndex, record);
}

// A cone that gathers radiance only (its blocked and blockedAt are not to be read).
ConeResult traceRadianceCone(vec3 origin, vec3 dir, float aperture, float startDistance, float maxDistance,
                             int coneIndex, bool record) {
  return marchCone(origin, dir, aperture, startDistance, maxDistance, 0.0, false, coneIndex, record);
}
