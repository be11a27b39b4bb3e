#version 450
// Cone tracing across clip levels. Along a cone the sample diameter grows as 2 t tan(aperture/2)
// and asks for level lambda = log2(diameter / s_0) + bias; a level may serve a sample only if the
// sample's trilinear footprint lies inside its region (u = (p - min_k) / s_k in [0.5, N - 0.5]
// on every axis), so the level read is l = max(lambda, k_min(p)), blended between floor(l) and
// floor(l) + 1 by its fraction; above L-1 it reads the coarsest level's mips. A sample outside the
// coarsest region ends the cone: the toroidal address would return some other cell's texel. The
// coarsest region is the volume the sky's escape rule (common/sky.glsl) sees: a cone that leaves
// it sees the sky through its remaining transmittance.
#include "common/shared.h"
#include "clipmap/clipmap.glsl"
#include "common/lights.glsl"
#include "common/sky.glsl"
#include "common/anisotropic_mip.glsl"
#include "common/facing.glsl"
#include "common/step_opacity.glsl"
#include "common/probe_recorder.glsl"
// The cone table, apertures, distances and G-buffer samplers; u_startOffset is in voxels of the
// level at the surface here (the tracer scales it).
#include "common/cone_setup.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler3D u_atlas;
layout(binding = 4) uniform sampler3D u_mips;
layout(rgba16f, binding = 0) uniform writeonly image2D u_indirectDiffuse;
layout(rgba16f, binding = 1) uniform writeonly image2D u_indirectSpecular;
uniform int u_traceSpecular;  // 0: the specular image is not wanted (composite.specular = 0 and no view of it)
layout(r16f, binding = 2) uniform writeonly image2D u_ambientOcclusion;
layout(r16f, binding = 3) uniform writeonly image2D u_levelUsed;
layout(std430, binding = VOXLAB_BINDING_CONE_SAMPLES) writeonly buffer ConeSamples { ConeSample coneSamples[]; };
layout(std430, binding = VOXLAB_BINDING_CONE_SAMPLE_COUNT) buffer ConeSampleCount { uint coneSampleCount; };

uniform vec3 u_levelMin[CLIPMAP_MAX_LEVELS];      // world min corner of each region, o_k s_k
uniform vec3 u_levelToroidal[CLIPMAP_MAX_LEVELS]; // T_k = o_k mod N
uniform float u_voxelSize0;                        // s_0
// 1 (isotropic) or 7 (isotropic + six directions): fixed per program (the stage's define
// CLIPMAP_FACES), so a sample runs one mode's lookups only (llvmpipe runs both sides of a branch on
// a uniform).
const int kFaces = CLIPMAP_FACES;
uniform int u_mipLevels;                           // mips of the coarsest level beyond it: at least 1
                                                   // (N >= 8, src/techniques/clipmap/layout.cpp, mipCount)
uniform float u_stepScale;
uniform float u_lodBias;
uniform int u_maxSteps;

float levelVoxel(int k) { return u_voxelSize0 * exp2(float(k)); }

bool footprintInside(vec3 p, int k) {
  vec3 u = (p - u_levelMin[k]) / levelVoxel(k);
  return all(greaterThanEqual(u, vec3(0.5))) && all(lessThanEqual(u, vec3(float(u_clipN) - 0.5)));
}

// The finest level whose region holds p's footprint; -1 outside the coarsest region.
int finestLevel(vec3 p) {
  for (int k = 0; k < u_clipLevels; ++k)
    if (footprintInside(p, k)) return k;
  return -1;
}

uniform float u_levelBand;  // cells: the transition band inside the finest level's border (0 = off)
// 1 where clipmap.transition-band is above 0 (the stage's define): without the band a raised level
// is exactly k_min, so the code of the ramp and of a raised second level is left out of the program
// (llvmpipe would run it for every sample).
#ifndef CLIPMAP_LEVEL_BAND
#define CLIPMAP_LEVEL_BAND 0
#endif

// The lowest level a sample at p may read: k_min(p), raised linearly towards k_min + 1 within
// u_levelBand cells of the border of k_min's footprint region (the next level holds p: levels nest
// with a margin of N/4 - 1 coarse cells), so the level changes continuously across the border.
float minimumLevel(vec3 p, int kmin) {
  if (CLIPMAP_LEVEL_BAND == 0 || kmin >= u_clipLevels - 1) return float(kmin);
  vec3 u = (p - u_levelMin[kmin]) / levelVoxel(kmin);
  vec3 inside = min(u - 0.5, float(u_clipN) - 0.5 - u);
  float margin = min(inside.x, min(inside.y, inside.z));
  return float(kmin) + clamp(1.0 - margin / u_levelBand, 0.0, 1.0);
}

vec4 fetchFace(int face, int k, vec3 phys) {
  float b = float(u_clipN + 2);
  vec3 texel = vec3(float(face) * b + 1.0, float(k) * b + 1.0, 1.0) + phys;
  return textureLod(u_atlas, texel / vec3(textureSize(u_atlas, 0)), 0.0);
}

// Face 'face' of clip level k at p, trilinear (the caller ensures k >= k_min(p)).
vec4 sampleLevel(int face, int k, vec3 p) {
  vec3 u = (p - u_levelMin[k]) / levelVoxel(k);
  return fetchFace(face, k, mod(u + u_levelToroidal[k], float(u_clipN)));
}

// Face 'face' of mip k - (L-1) of the coarsest level (k > L-1), whose faces lie side by side along
// x (its x is clamped to the face's edge texels' centres, as clamp-to-edge does to y and z, so no
// lookup reads the next face).
vec4 sampleMip(int face, int k, vec3 p) {
  int last = u_clipLevels - 1;
  int m = min(k - last, u_mipLevels);
  float n = float(u_clipN >> m);
  vec3 u = (p - u_levelMin[last]) / (levelVoxel(last) * float(u_clipN));
  float x = clamp(u.x * n, 0.5, n - 0.5) + float(face) * n;
  return textureLod(u_mips, vec3(x / (float(kFaces) * n), u.yz), float(m));
}

uniform float u_frontHold;  // cells: how far behind its surface a front keeps its opacity (0 = off)

// The march runs in three phases of the level the cone's width asks for ('own', which grows with
// the distance): near (own <= L-1: clip levels only, raised by the finer levels' reach and holding
// fronts), crossing (L-1 < own < L: the coarsest clip level and the first of its mips) and far
// (own >= L: the mips alone). llvmpipe runs both sides of every branch, even one on a uniform, so
// a sample that held the code of every level paid for reads it did not need (every hierarchy
// lookup read the atlas and the mips, every face the read behind its front); a phase's loop holds
// only its own reads. Each phase computes what the whole hierarchy would.
const int kNear = 0, kCrossing = 1, kFar = 2;

// The three directional faces 'faces' (1 + d, d = the travel direction) of clip level k <= L-1 at
// p, for the near phase: p's texel address is computed once for the three. 'hold': the level was
// raised above the cone's own because the finer levels do not reach p (the sample is smaller than
// the cell): a surface is one cell of the coarse level, and trilinear filtering spreads its
// opacity as a hat one cell either side of the cell's centre, which may lie half a cell in front
// of the surface. A cone that crosses the surface between two of its samples then sees only part
// of the surface's opacity and goes on behind it (into the void outside a room: light lost). So
// each face is also read u_frontHold cells back along the travel direction (only that axis of
// the address moves), and the more opaque of the two is kept: a front the cone has reached stays
// opaque for that far behind its cell centre. Before a front nothing changes (the read behind is
// further from the front than p). Only the near phase raises a level (beyond L-1 the cone's own
// level is coarser than any clip level).
void nearFaces(int k, vec3 p, bool hold, ivec3 faces, out vec4 s[3]) {
  float n = float(u_clipN);
  vec3 u = (p - u_levelMin[k]) / levelVoxel(k);
  vec3 phys = mod(u + u_levelToroidal[k], n);
  // No 'continue' in this loop: with one the compiler no longer unrolls it, s[] goes to memory and
  // the stage takes half as long again (docs/performance.md, clipmap).
  for (int a = 0; a < 3; ++a) {
    s[a] = fetchFace(faces[a], k, phys);
    if (hold && u_frontHold > 0.0) {
      // Face 1 + d travels along +axis for even d: behind it is -axis.
      float back = ((faces[a] - 1) & 1) == 0 ? -1.0 : 1.0;
      float ub = (p[a] + back * (u_frontHold * levelVoxel(k)) - u_levelMin[k][a]) / levelVoxel(k);
      // Read only where behind lies inside the level's footprint region.
      if (ub >= 0.5 && ub <= n - 0.5) {
        vec3 q = phys;
        q[a] = mod(ub + u_levelToroidal[k][a], n);
        vec4 behind = fetchFace(faces[a], k, q);
        if (behind.a > s[a].a) s[a] = behind;
      }
    }
  }
}

// One directional face at level 'level' beyond the near phase: its two levels blended. Crossing
// (L-1 < level < L) they are the coarsest clip level and its first mip; far, two mips (one at the
// top).
vec4 sampleFace(int face, float level, vec3 p, int phase) {
  int last = u_clipLevels - 1;
  int top = last + u_mipLevels;
  int k0 = min(int(floor(level)), top);
  float f = level - float(k0);
  if (phase == kCrossing) return mix(sampleLevel(face, last, p), sampleMip(face, last + 1, p), f);
  vec4 s = sampleMip(face, k0, p);
  if (f > 0.0 && k0 < top) s = mix(s, sampleMip(face, k0 + 1, p), f);
  return s;
}

// What a cone travelling along 'dir' sees at p at level 'level' (>= k_min(p)). The cone model is
// vct-grid's (common/cone_trace.glsl, sampleVolume): one face, the isotropic values, quadrilinear
// through the levels and the coarsest level's mips; with six faces, at every level the three faces
// facing the cone (the fronts each direction sees, resolve.comp.glsl) blended by their optical
// depths (common/facing.glsl, seenFronts). Level 0 reads its faces too: its isotropic values show
// a cone the light of the surface it starts from (a lit floor next to the camera, level 0, lit
// itself: 7 to 31 times the reference's indirect light in the two rooms' bottom strip).
vec4 sampleAt(vec3 p, float level, vec3 dir, bool hold, int phase) {
  int last = u_clipLevels - 1;
  if (kFaces == 1) {
    if (phase != kNear) {  // level > L-1: the coarsest level's mips
      vec3 u = (p - u_levelMin[last]) / levelVoxel(last);
      return textureLod(u_mips, u / float(u_clipN), level - float(last));
    }
    int k0 = min(int(floor(level)), last);
    float f = level - float(k0);
    vec4 s = sampleLevel(0, k0, p);
    if (f > 0.0 && k0 < last) s = mix(s, sampleLevel(0, k0 + 1, p), f);
    return s;
  }
  float directional = max(level, 0.0);
  ivec3 faces = ivec3(dir.x >= 0.0 ? 1 : 2, dir.y >= 0.0 ? 3 : 4, dir.z >= 0.0 ? 5 : 6);
  if (phase != kNear)
    return seenFronts(anisotropicWeights(dir), sampleFace(faces.x, directional, p, phase),
                      sampleFace(faces.y, directional, p, phase), sampleFace(faces.z, directional, p, phase));
  // Near: clip levels only, each read with its fronts held where the level was raised. Without the
  // transition band a raised level is k_min exactly, so the next level (weight 0 there) is read
  // only where it was not raised and needs no hold.
  int top = last + u_mipLevels;
  int k0 = min(int(floor(directional)), top);
  float f = directional - float(k0);
  vec4 s[3];
  nearFaces(min(k0, last), p, hold, faces, s);
  if (f > 0.0 && k0 < top) {
    vec4 next[3];
    nearFaces(min(k0 + 1, last), p, hold && CLIPMAP_LEVEL_BAND != 0, faces, next);
    for (int a = 0; a < 3; ++a) s[a] = mix(s[a], next[a], f);
  }
  return seenFronts(anisotropicWeights(dir), s[0], s[1], s[2]);
}

struct ConeResult { vec3 radiance; float opacity; float opacityAt; };

// The march's state between samples.
struct ConeMarch {
  ConeResult r;
  float t;
  int step;
  bool going;   // the cone goes on
  bool left;    // the sample's footprint left the coarsest region
  bool marked;  // r.opacityAt is set
};

// The level the cone's width asks for at distance t.
float ownLevel(float tanHalf, float t) {
  float diameter = max(2.0 * tanHalf * t, u_voxelSize0);
  return max(log2(diameter / u_voxelSize0) + u_lodBias, 0.0);
}

// Whether the phase holds a sample whose own level is 'own'.
bool inPhase(int phase, float own) {
  float last = float(u_clipLevels - 1);
  if (phase == kNear) return own <= last;
  if (phase == kCrossing) return own > last && own < last + 1.0;
  return own >= last + 1.0;
}

void marchSample(inout ConeMarch m, vec3 origin, vec3 dir, float tanHalf, float maxDistance,
                 float markDistance, int coneIndex, bool record, int phase) {
  float top = float(u_clipLevels - 1 + u_mipLevels);
  float diameter = max(2.0 * tanHalf * m.t, u_voxelSize0);
  vec3 p = origin + dir * m.t;
  // Beyond L-1 the coarsest region decides alone (the regions nest).
  int kmin = phase == kNear ? finestLevel(p) : (footprintInside(p, u_clipLevels - 1) ? u_clipLevels - 1 : -1);
  if (kmin < 0) {  // outside the coarsest region: the cone ends
    m.left = true;
    m.going = false;
    return;
  }
  float own = ownLevel(tanHalf, m.t);
  float level = phase == kNear ? min(max(own, minimumLevel(p, kmin)), top) : min(own, top);
  if (!m.marked && m.t > markDistance) { m.r.opacityAt = m.r.opacity; m.marked = true; }
  vec4 s = sampleAt(p, level, dir, phase == kNear && level > own, phase);
  float stepLength = diameter * u_stepScale;
  float texelSize = u_voxelSize0 * exp2(level);
  float a = compositeSample(m.r.radiance, m.r.opacity, s, stepLength / texelSize);
  if (record) {
    uint k = atomicAdd(coneSampleCount, 1u);
    // info.z: the level read (floor = finer level, fraction = weight of the next level).
    if (k < uint(VOXLAB_MAX_CONES * VOXLAB_MAX_SAMPLES_PER_CONE))
      coneSamples[k] = ConeSample(vec4(p, diameter), vec4(m.r.radiance, m.r.opacity), vec4(float(coneIndex), m.t, level, a));
  }
  m.t += stepLength;
  ++m.step;
  m.going = m.step < u_maxSteps && m.r.opacity < 0.99 && m.t < maxDistance;
}

ConeResult traceCone(vec3 origin, vec3 dir, float aperture, float start, float maxDistance, float markDistance,
                     int coneIndex, bool record) {
  float tanHalf = tan(0.5 * aperture);
  ConeMarch m = ConeMarch(ConeResult(vec3(0.0), 0.0, 0.0), start, 0, u_maxSteps > 0 && start < maxDistance, false, false);
  // Each loop tests its condition at the end of its body: llvmpipe leaves a loop only after an
  // iteration in which no lane is left, so a test at the top ran one more body, every lane masked
  // off and every lookup paid, after each cone's last sample (vct-grid's march, docs/performance.md).
  bool here = m.going && inPhase(kNear, ownLevel(tanHalf, m.t));
  do {
    if (here) marchSample(m, origin, dir, tanHalf, maxDistance, markDistance, coneIndex, record, kNear);
    here = m.going && inPhase(kNear, ownLevel(tanHalf, m.t));
  } while (here);
  here = m.going && inPhase(kCrossing, ownLevel(tanHalf, m.t));
  do {
    if (here) marchSample(m, origin, dir, tanHalf, maxDistance, markDistance, coneIndex, record, kCrossing);
    here = m.going && inPhase(kCrossing, ownLevel(tanHalf, m.t));
  } while (here);
  here = m.going;
  do {
    if (here) marchSample(m, origin, dir, tanHalf, maxDistance, markDistance, coneIndex, record, kFar);
    here = m.going;
  } while (here);
  if (!m.marked) m.r.opacityAt = m.r.opacity;
  m.r.radiance += coneSky(m.left, m.t >= maxDistance, origin + dir * m.t, m.r.opacity);
  return m.r;
}

void main() {
  // The probed pixel's samples come from the recorder (common/probe_recorder.glsl), which traces
  // that pixel again: a per-sample record flag cost every pixel its masked stores.
  const bool record = kRecordProbe;
  ivec2 px;
  if (!recorderPixel(u_probePixel, px)) return;
  if (any(greaterThanEqual(px, imageSize(u_indirectDiffuse)))) return;
  // At half resolution each traced pixel shades the top-left G-buffer pixel of its 2x2 block; the
  // composite upsamples along surfaces.
  ivec2 g = min(px * u_scale, textureSize(u_position, 0) - 1);
  vec4 pos = texelFetch(u_position, g, 0);
  if (pos.w == 0.0) {
    imageStore(u_indirectDiffuse, px, vec4(0.0));
    if (u_traceSpecular != 0) imageStore(u_indirectSpecular, px, vec4(0.0));
    imageStore(u_ambientOcclusion, px, vec4(0.0));
    imageStore(u_levelUsed, px, vec4(-1.0));
    return;
  }
  vec3 n = normalize(texelFetch(u_normal, g, 0).xyz);
  vec3 albedo = texelFetch(u_albedo, g, 0).rgb;
  int surfaceLevel = finestLevel(pos.xyz);
  imageStore(u_levelUsed, px, vec4(float(surfaceLevel)));
  float voxel = levelVoxel(max(surfaceLevel, 0));
  vec3 origin = pos.xyz + n * u_startOffset * voxel;
  vec3 t = normalize(abs(n.y) < 0.9 ? cross(n, vec3(0, 1, 0)) : cross(n, vec3(1, 0, 0)));
  vec3 b = cross(n, t);
  vec3 incoming = vec3(0.0);
  float occlusion = 0.0;
  for (int i = 0; i < u_coneCount; ++i) {
    vec3 d = normalize(t * u_cones[i].x + b * u_cones[i].y + n * u_cones[i].z);
    ConeResult c = traceCone(origin, d, u_diffuseAperture, voxel, u_maxDistance, u_aoRange, i, record);
    incoming += u_cones[i].w * c.radiance;
    occlusion += u_cones[i].w * c.opacityAt;
  }
  // Without the specular image (outputs on demand) only the probed pixel traces it, for its record.
  if (u_traceSpecular != 0 || record) {
    vec3 view = normalize(pos.xyz - u_cameraPos);
    vec3 reflected = reflect(view, n);
    ConeResult s = traceCone(origin, reflected, u_specularAperture, voxel, u_maxDistance, u_maxDistance, u_coneCount, record);
    if (u_traceSpecular != 0) imageStore(u_indirectSpecular, px, vec4(s.radiance, 1.0));
  }
  imageStore(u_indirectDiffuse, px, vec4(albedo * incoming, 1.0));
  imageStore(u_ambientOcclusion, px, vec4(1.0 - occlusion));
}
