#version 450
// svo-cone-trace, one invocation per traced pixel: the cones of vct-grid's cone-trace (diffuse
// cones with their AO, one specular cone, one soft-shadow cone), sampling the octree instead of a
// dense mip chain. Each sample descends from the root to the level of its diameter and blends two
// levels (quadrilinear, svoFineWeight in svo_shared.h); inside a node the brick's 3x3x3 texels are
// filtered by the hardware (texel coordinate 3 * brick + 0.5 + 2u, u the position in the node).
// Ambient occlusion can use its own constellation (Basgier's 3, 5 or 8 cones) and weights each
// sample's opacity by the falloff f(r) = 1 / (1 + lambda r), r in voxels (lambda 0: vct-grid's
// plain range cut). For the probed pixel every sample and every level of its descent is recorded.
// With anisotropic mips (SVO_ANISOTROPIC) a node above the voxels is read from its three directional
// bricks facing the cone, weighted dir^2, the two levels of a sample blended per direction before
// the three are combined, as vct-grid's sampleVolume does (common/cone_trace.glsl): with
// mipmap.fronts (SVO_FRONTS, the default) the bricks hold the fronts only and combine by optical
// depth (seenFronts, common/facing.glsl), and two more bricks hold the voxels' solid
// opacity, which ambient occlusion and the shadow cone accumulate (ConeResult.blocked); without
// it, Crassin's classic weighted sum, whose opacity is also the solid one. The voxels stay
// isotropic, so between the voxel level and the one above a sample blends the leaf with the
// directional value, as vct-grid fades its voxels into directional level 1.
// A voxel without a brick (empty, or no node: bricks are only on non-empty nodes) is read as the
// dense grid reads it, from the eight voxels around the sample (SVO_VOXEL_HALO, voxelLevelSample).
#include "common/shared.h"
#include "common/voxel_space.glsl"
#include "common/packing.glsl"
#include "common/lights.glsl"
#include "common/cone_setup.glsl"
#include "common/sky.glsl"
#include "common/anisotropic_mip.glsl"
#include "common/facing.glsl"
#include "common/step_opacity.glsl"
#include "common/probe_recorder.glsl"
#include "svo/svo_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = SVO_BINDING_NODES) readonly buffer Nodes { SvoNode nodes[]; };
layout(std430, binding = SVO_BINDING_BRICK_INDEX) readonly buffer BrickIndex { uint brickIndex[]; };
layout(std430, binding = SVO_BINDING_VALUES) readonly buffer Values { vec4 values[]; };
// SVO_SCALED_BRICKS (HDR bricks of Layout N): per brick number the scales of its isotropic and six
// directional bricks' radiance (svo/bricks.comp.glsl)
layout(std430, binding = SVO_BINDING_BRICK_SCALES) readonly buffer BrickScales { float brickScales[]; };
layout(std430, binding = VOXLAB_BINDING_CONE_SAMPLES) writeonly buffer ConeSamples { ConeSample coneSamples[]; };
layout(std430, binding = VOXLAB_BINDING_CONE_SAMPLE_COUNT) buffer ConeSampleCount { uint coneSampleCount; };
layout(std430, binding = SVO_BINDING_DESCENT) writeonly buffer Descent { SvoDescentStep descent[]; };
layout(std430, binding = SVO_BINDING_DESCENT_COUNT) buffer DescentCount { uint descentCount; };
layout(binding = 0) uniform sampler3D u_brickPool;
layout(binding = 4) uniform sampler3D u_directionalPool;  // six parts stacked along z: +x -x +y -y +z -z
// (SVO_FRONTS) the solid opacity along x, y, z (rgb, the same either way), the same bricks
layout(binding = 5) uniform sampler3D u_opacityPool;
layout(rgba16f, binding = 0) uniform writeonly image2D u_indirectDiffuse;
layout(rgba16f, binding = 1) uniform writeonly image2D u_indirectSpecular;
layout(r16f, binding = 2) uniform writeonly image2D u_ambientOcclusion;
layout(r16f, binding = 3) uniform writeonly image2D u_softShadow;

uniform int u_depth;
uniform ivec3 u_bricksPerAxis;
// The switches of a run, fixed per program by the stage's defines (svo/stages.cpp,
// coneTraceDefines), not uniforms: llvmpipe runs both sides of every branch, so as uniforms every
// sample also paid for the reads of the modes not chosen.
#if !defined(SVO_DILATED) || !defined(SVO_LAYOUT_TILE) || !defined(SVO_ANISOTROPIC) || !defined(SVO_FRONTS) || \
    !defined(SVO_VOXEL_HALO) || !defined(SVO_AO_CONES) || !defined(SVO_SHADOW_CONE)
#error "svo/cone_trace.comp.glsl needs the defines of coneTraceDefines (svo/stages.cpp)"
#endif
// SVO_DILATED 1: empty neighbours have nodes, so an absent node is exactly 0
// SVO_LAYOUT_TILE 1: Layout T, the brick of a level-l node holds level l + 1
// SVO_ANISOTROPIC 1: nodes above the voxels are read from their directional bricks
// SVO_FRONTS 1: the directional bricks hold fronts only, solid opacity apart (mipmap.fronts)
// SVO_VOXEL_HALO 1: a voxel without a brick is read as the dense grid's blend (voxelLevelSample)
// SVO_AO_CONES 1: ambient occlusion from its own constellation (ao.cones), not the diffuse cones
// SVO_SHADOW_CONE 1: every pixel traces the soft-shadow cone (the image is wanted); 0: only the
//   probed pixel's record does
// SVO_SPECULAR_CONE 1: every pixel traces the specular cone (the image is wanted); 0: only the
//   probed pixel's record does
uniform ivec3 u_directionalPerAxis;  // bricks per axis of one direction's part of the directional pool
uniform int u_aoConeCount;                 // 0: AO from the diffuse cones
uniform vec4 u_aoCones[VOXLAB_MAX_CONES];
uniform float u_aoAperture;
uniform float u_aoFalloff;                 // lambda, per voxel
uniform int u_aoJitter;                    // 1: the cone frame turns about the normal by a per-pixel angle
uniform float u_stepScale;
uniform float u_lodBias;
uniform int u_maxSteps;
#include "svo/octree.glsl"

// The position inside the node of 'level' holding voxel 'voxel' of voxel-space point v (clamped
// into the node): the node's cell follows from the voxel, no pool read for it.
vec3 nodePosition(int level, uvec3 voxel, vec3 v) {
  float cell = exp2(float(u_depth - level));
  return clamp(v / cell - vec3(voxel >> uint(u_depth - level)), 0.0, 1.0);
}

// The trilinear sample of the isotropic brick of 'node' (at 'level', holding voxel 'voxel') at
// voxel-space point v.
vec4 brickSample(uint node, int level, uvec3 voxel, vec3 v) {
  uint b = brickIndex[node];
  if (b == 0u) return vec4(0.0);
  vec3 origin = 3.0 * vec3(svoBrickCoords(b, uvec2(u_bricksPerAxis.xy)));
  vec4 s = textureLod(u_brickPool, (origin + 0.5 + 2.0 * nodePosition(level, voxel, v)) / vec3(textureSize(u_brickPool, 0)), 0.0);
#ifdef SVO_SCALED_BRICKS
  s.rgb *= brickScales[8u * b];
#endif
  return s;
}

// What a node above the voxels shows a cone travelling along 'dir': its directional bricks facing
// the cone, one per axis, and (SVO_FRONTS) the solid opacity per axis.
struct Seen {
  vec4 x, y, z;
  vec3 solid;
};
const Seen kSeenNothing = Seen(vec4(0.0), vec4(0.0), vec4(0.0), vec3(0.0));
Seen mixSeen(Seen a, Seen b, float w) {
  return Seen(mix(a.x, b.x, w), mix(a.y, b.y, w), mix(a.z, b.z, w), mix(a.solid, b.solid, w));
}

// What the current sample must read with the fronts rule: the fronts (radiance; set per cone by
// traceCone), and the solid opacity (ambient occlusion up to its range, the shadow cone; set per
// loop of the march, g_wantSolid). Both are constants where the compiler sees them, so what a cone
// or a loop does not read is not in its code (llvmpipe runs both sides of a branch even where every
// lane agrees). Without the fronts rule a sample's opacity is its solid opacity: everything is read.
bool g_wantFronts = true;
bool g_wantSolid = true;
// Whether the current cone reads a voxel without a brick as the dense grid's blend (SVO_VOXEL_HALO):
// every cone but the soft-shadow one (set per cone by traceCone, the same for every lane).
bool g_halo = true;

// The phases of a cone's samples (svoPhase): lod 0, where the fine level (the voxels) has weight 1;
// the fade, where the fine level is the voxels and the coarse one above them; and above the voxels.
const int kSvoPhaseVoxels = 0;
const int kSvoPhaseFade = 1;
const int kSvoPhaseAbove = 2;

// The directional bricks of 'node' (above the voxels) at v. The +axis or -axis part of each axis is
// a z offset (the same lookups for every pixel, whatever the sign: no divergent branch on
// llvmpipe); the solid opacity is one brick, the same travelling either way along an axis.
Seen directionalSample(uint node, int level, uvec3 voxel, vec3 v, vec3 dir) {
  uint b = brickIndex[node];
  if (b == 0u) return kSeenNothing;
  vec3 size = vec3(textureSize(u_directionalPool, 0));
  vec3 texel = 3.0 * vec3(svoBrickCoords(b, uvec2(u_directionalPerAxis.xy))) + 0.5 + 2.0 * nodePosition(level, voxel, v);
  float part = 3.0 * float(u_directionalPerAxis.z);
  Seen s = kSeenNothing;
  if (g_wantFronts || SVO_FRONTS == 0) {
    s.x = textureLod(u_directionalPool, (texel + vec3(0.0, 0.0, part * (dir.x < 0.0 ? 1.0 : 0.0))) / size, 0.0);
    s.y = textureLod(u_directionalPool, (texel + vec3(0.0, 0.0, part * (dir.y < 0.0 ? 3.0 : 2.0))) / size, 0.0);
    s.z = textureLod(u_directionalPool, (texel + vec3(0.0, 0.0, part * (dir.z < 0.0 ? 5.0 : 4.0))) / size, 0.0);
#ifdef SVO_SCALED_BRICKS
    s.x.rgb *= brickScales[8u * b + (dir.x < 0.0 ? 2u : 1u)];
    s.y.rgb *= brickScales[8u * b + (dir.y < 0.0 ? 4u : 3u)];
    s.z.rgb *= brickScales[8u * b + (dir.z < 0.0 ? 6u : 5u)];
#endif
  }
  if (SVO_FRONTS == 1 && g_wantSolid) {
    s.solid = textureLod(u_opacityPool, texel / vec3(textureSize(u_opacityPool, 0)), 0.0).rgb;
  }
  return s;
}

// The three directional values as one premultiplied sample, and in 'solid' the opacity of the
// voxels as solid cubes (vct-grid's sampleVolume at lod >= 1).
vec4 combineSeen(Seen s, vec3 dir, out float solid) {
  vec3 w = anisotropicWeights(dir);
  if (SVO_FRONTS == 0) {
    vec4 classic = w.x * s.x + w.y * s.y + w.z * s.z;
    solid = classic.a;
    return classic;
  }
  solid = dot(w, s.solid);
  return seenFronts(w, s.x, s.y, s.z);
}

// The node of voxel m, found from node 'from' (at 'level', holding voxel 'voxel'): up the parent
// links to the closest common ancestor, then down along the bits of m; SVO_ABSENT where a node
// on the way down has no children. The voxels around a sample share an ancestor a level or two
// up, so this reads fewer nodes than a descent from the root.
uint svoVoxelFrom(uint from, int level, uvec3 voxel, uvec3 m) {
  uint node = from;
  int l = level;
  while (l > 0 && any(notEqual(voxel >> uint(u_depth - l), m >> uint(u_depth - l)))) {
    node = nodes[node].parent;
    --l;
  }
  for (++l; l <= u_depth; ++l) {
    uint first = nodes[node].word & SVO_CHILD_MASK;
    if (first == 0u) return SVO_ABSENT;
    uvec3 bit = (m >> uint(u_depth - l)) & 1u;
    node = first + bit.x + 2u * bit.y + 4u * bit.z;
  }
  return node;
}

// The voxel level at voxel-space point v as the dense grid's trilinear filter gives it: the eight
// voxels around v (clamped to the volume, as CLAMP_TO_EDGE), absent or empty ones counting 0,
// found from 'from', the deepest node of v's descent (at 'level'). Used where a sample's fine
// level is the voxels and its voxel has no brick (empty, or no node at all): next to a filled
// voxel the dense grid blends that voxel in there, which bricks only on non-empty nodes cannot
// hold (without this, a cone starting next to a surface saw nothing in the first voxel).
vec4 voxelLevelSample(vec3 v, uint from, int level, uvec3 voxel) {
  vec3 p = v - 0.5;
  ivec3 base = ivec3(floor(p));
  vec3 f = p - vec3(base);
  vec4 sum = vec4(0.0);
  for (int k = 0; k < 8; ++k) {
    ivec3 bit = ivec3(k & 1, (k >> 1) & 1, k >> 2);
    uvec3 cell = uvec3(clamp(base + bit, ivec3(0), ivec3(u_resolution - 1)));
    // Inside the cell of 'from' the voxels are empty: 'from' is the sample's own voxel without a
    // brick, or a node above the voxels without children (svoVoxelFrom would find none there).
    if (all(equal(cell >> uint(u_depth - level), voxel >> uint(u_depth - level)))) continue;
    uint n = svoVoxelFrom(from, level, voxel, cell);
    vec3 w3 = mix(1.0 - f, f, vec3(bit));
    if (n != SVO_ABSENT) sum += (w3.x * w3.y * w3.z) * values[n];
  }
  return sum;
}

// The octree at voxel-space point v and fractional level levelStar (0 = root .. D = voxels), seen
// along 'dir': one descent from the root to the fine level, keeping the node one level above as
// the coarse one; 'solid' is the opacity of the voxels as solid cubes there (the sample's own
// opacity except with the fronts rule). Layout T: level l is read from the bricks of level l - 1
// (the descent ends one level higher and the root's brick is the coarsest level, 1).
// 'phase' (a constant at every call, kSvoPhase*) says which levels the sample's lod reads, so that
// the code of the others is left out; each phase gives the same values as the general expression.
vec4 svoSample(vec3 v, float levelStar, vec3 dir, bool record, uint sampleIndex, int phase, out float solid) {
  const int shift = SVO_LAYOUT_TILE;
  // The fine level is the voxels in the first two phases (before Layout T's shift), above them in the last.
  const bool fineIsVoxels = SVO_LAYOUT_TILE == 0 && phase != kSvoPhaseAbove;
  levelStar = max(levelStar, float(shift));
  int fine = int(svoFineLevel(levelStar, float(u_depth)));
  float w = svoFineWeight(levelStar, float(u_depth));
  uvec3 voxel = uvec3(clamp(ivec3(floor(v)), ivec3(0), ivec3(u_resolution - 1)));
  uint node = 0u, coarseNode = SVO_ABSENT, fineNode = SVO_ABSENT;
  uint deepest = 0u;  // the deepest node of the descent, at level deepestLevel
  int deepestLevel = 0;
  fine -= shift;
  for (int l = 0; l <= fine; ++l) {
    if (l > 0) {
      uint first = nodes[node].word & SVO_CHILD_MASK;
      if (first == 0u) {
        node = SVO_ABSENT;
      } else {
        uvec3 bit = (voxel >> uint(u_depth - l)) & 1u;
        node = first + bit.x + 2u * bit.y + 4u * bit.z;
      }
    }
    if (l == fine - 1) coarseNode = node;
    if (l == fine) fineNode = node;
    if (record) {
      uint k = atomicAdd(descentCount, 1u);
      float ignored;
      vec4 value = node == SVO_ABSENT                       ? vec4(0.0)
                   : SVO_ANISOTROPIC == 1 && l < u_depth ? combineSeen(directionalSample(node, l, voxel, v, dir), dir, ignored)
                                                        : brickSample(node, l, voxel, v);
      if (k < SVO_MAX_DESCENT_STEPS)
        descent[k] = SvoDescentStep(sampleIndex, uint(l), node, packVoxel10(voxel >> uint(u_depth - l)),
                                    float[4](value.r, value.g, value.b, value.a));
    }
    if (node == SVO_ABSENT) break;  // the record ends at the first absent node
    deepest = node;
    deepestLevel = l;
  }
  // Without dilation an absent fine node next to a filled one is not exactly empty: the coarse
  // level alone is used there (the note's fallback for source error P2); with it, it is 0.
  // At the voxel level a voxel without a brick is read as the dense grid reads it (svo.voxel-halo).
  const bool denseVoxels = SVO_VOXEL_HALO == 1 && g_halo && fineIsVoxels;
  const bool fineFallback = fineNode == SVO_ABSENT && !denseVoxels;
  const float fineWeight = fineFallback && SVO_DILATED == 0 ? 0.0 : w;
  // A level of weight 0 is not read: the coarse one while a cone is no wider than the voxels
  // (lod 0: the fine level's weight is 1, as vct-grid reads its voxels alone there), unless an
  // absent fine node falls back to it. In that phase the compiler drops the coarse reads.
  const bool coarseUnused = phase == kSvoPhaseVoxels && (SVO_DILATED == 1 || denseVoxels);
  const bool readCoarse = !coarseUnused && coarseNode != SVO_ABSENT && fineWeight < 1.0;
  if (SVO_ANISOTROPIC == 1 && !fineIsVoxels) {
    // Both levels directional: blended per direction, then combined.
    Seen coarse = !readCoarse ? kSeenNothing : directionalSample(coarseNode, fine - 1, voxel, v, dir);
    Seen fineSeen = fineNode == SVO_ABSENT ? kSeenNothing : directionalSample(fineNode, fine, voxel, v, dir);
    return combineSeen(mixSeen(coarse, fineSeen, fineWeight), dir, solid);
  }
  vec4 coarse = vec4(0.0);
  float coarseSolid = 0.0;
  if (readCoarse) {
    if (SVO_ANISOTROPIC == 1) coarse = combineSeen(directionalSample(coarseNode, fine - 1, voxel, v, dir), dir, coarseSolid);
    else coarse = brickSample(coarseNode, fine - 1, voxel, v);
    if (SVO_ANISOTROPIC == 0) coarseSolid = coarse.a;
  }
  // The halo starts from the deepest node of the descent, which is the fine node where there is one:
  // one call serves both cases (llvmpipe runs a call in a branch for every lane).
  vec4 fineValue = vec4(0.0);
  const bool halo = denseVoxels && (fineNode == SVO_ABSENT || brickIndex[fineNode] == 0u);
  if (halo) fineValue = voxelLevelSample(v, deepest, deepestLevel, voxel);
  else if (fineNode != SVO_ABSENT) fineValue = brickSample(fineNode, fine, voxel, v);
  solid = mix(coarseSolid, fineValue.a, fineWeight);
  return mix(coarse, fineValue, fineWeight);
}

struct ConeResult {
  vec3 radiance;
  float opacity;    // accumulated opacity of the fronts the radiance comes from
  float blocked;    // accumulated opacity of the voxels as solid cubes (shadows)
  float occlusion;  // 'blocked' with the AO falloff, accumulated up to markDistance
};

// A cone's march: where it is and what it has gathered.
struct SvoMarch {
  float t;
  int step;
  bool done;  // opaque enough, out of steps or distance, or left the volume
  bool left;  // the sample lay wholly outside the volume
  ConeResult r;
};

float svoConeDiameter(float tanHalf, float t) { return max(2.0 * tanHalf * t, u_voxelSize); }
float svoConeLod(float diameter) { return max(log2(diameter / u_voxelSize) + u_lodBias, 0.0); }
float svoLevelStar(float lod) { return clamp(float(u_depth) - lod, 0.0, float(u_depth)); }

// The phase of a sample at distance t (svoSample): lod 0 (the voxels alone), the fine level the
// voxels, or both levels above them. It only grows along a cone.
int svoPhase(float tanHalf, float t) {
  float lod = svoConeLod(svoConeDiameter(tanHalf, t));
  if (lod <= 0.0) return kSvoPhaseVoxels;
  return int(svoFineLevel(svoLevelStar(lod), float(u_depth))) == u_depth ? kSvoPhaseFade : kSvoPhaseAbove;
}

// One sample of the march (phase: svoSample; wantSolid: g_wantSolid, t <= markDistance), or the
// end of the march (m.done).
void svoConeStep(inout SvoMarch m, vec3 origin, vec3 dir, float tanHalf, float maxDistance, float markDistance,
                 int coneIndex, bool record, bool wantRadiance, int phase, bool wantSolid) {
  if (m.step >= u_maxSteps || m.t >= maxDistance) { m.done = true; return; }
  if ((m.r.opacity >= 0.99 || !wantRadiance) && (m.r.blocked >= 0.99 || m.t > markDistance)) { m.done = true; return; }
  g_wantSolid = wantSolid;
  float diameter = svoConeDiameter(tanHalf, m.t);
  float lod = svoConeLod(diameter);
  float levelStar = svoLevelStar(lod);
  vec3 p = origin + dir * m.t;
  vec3 v = worldToVoxel(p);
  float margin = 0.5 * diameter / u_voxelSize;
  if (any(lessThan(v, vec3(-margin))) || any(greaterThan(v, vec3(float(u_resolution) + margin)))) {
    m.left = true;
    m.done = true;
    return;
  }
  uint k = 0u;
  if (record) k = atomicAdd(coneSampleCount, 1u);
  float solid;
  vec4 s = svoSample(v, levelStar, dir, record, k, phase, solid);
  float stepLength = diameter * u_stepScale;
  float texelSize = u_voxelSize * exp2(lod);
  float a = compositeSample(m.r.radiance, m.r.opacity, s, stepLength / texelSize);
  float aSolid = stepOpacity(solid, stepLength / texelSize);
  if (m.t <= markDistance) {
    float falloff = 1.0 / (1.0 + u_aoFalloff * m.t / u_voxelSize);
    m.r.occlusion += (1.0 - m.r.occlusion) * aSolid * falloff;
  }
  m.r.blocked += (1.0 - m.r.blocked) * aSolid;
  if (record && k < uint(VOXLAB_MAX_CONES * VOXLAB_MAX_SAMPLES_PER_CONE))
    coneSamples[k] = ConeSample(vec4(p, diameter), vec4(m.r.radiance, m.r.opacity), vec4(float(coneIndex), m.t, lod, a));
  m.t += stepLength;
  m.step += 1;
}

// Marches the cone front to back until the radiance is gathered (opacity 0.99; unless
// wantRadiance is false: the shadow and AO cones) and, up to markDistance, the occlusion too
// (vct-grid's traceCone, common/cone_trace.glsl), or it leaves the volume, or reaches maxDistance.
// The march runs in loops by phase (svoPhase) and, within a phase, before and after markDistance,
// as vct-grid's does: every pixel's cone takes the same steps (t depends on the aperture and the
// start only), so each loop's code holds only the lookups its samples need. With the fronts rule
// the solid opacity is read only up to markDistance (beyond it only 'blocked' would use it, which
// no cone that asks for the radiance reads). halo: g_halo.
ConeResult traceCone(vec3 origin, vec3 dir, float aperture, float startDistance, float maxDistance,
                     float markDistance, int coneIndex, bool record, bool wantRadiance, bool halo) {
  g_wantFronts = wantRadiance;
  g_halo = halo;
  float tanHalf = tan(0.5 * aperture);
  SvoMarch m = SvoMarch(startDistance, 0, false, false, ConeResult(vec3(0.0), 0.0, 0.0, 0.0));
  while (!m.done && svoPhase(tanHalf, m.t) == kSvoPhaseVoxels)
    svoConeStep(m, origin, dir, tanHalf, maxDistance, markDistance, coneIndex, record, wantRadiance, kSvoPhaseVoxels, m.t <= markDistance);
  while (!m.done && svoPhase(tanHalf, m.t) == kSvoPhaseFade)
    svoConeStep(m, origin, dir, tanHalf, maxDistance, markDistance, coneIndex, record, wantRadiance, kSvoPhaseFade, m.t <= markDistance);
  while (!m.done && m.t <= markDistance)
    svoConeStep(m, origin, dir, tanHalf, maxDistance, markDistance, coneIndex, record, wantRadiance, kSvoPhaseAbove, true);
  while (!m.done)
    svoConeStep(m, origin, dir, tanHalf, maxDistance, markDistance, coneIndex, record, wantRadiance, kSvoPhaseAbove, false);
  ConeResult r = m.r;
  r.radiance += coneSky(m.left, m.t >= maxDistance, origin + dir * m.t, r.opacity);  // common/sky.glsl
  return r;
}

void main() {
  // The probed pixel's records come from the recorder (common/probe_recorder.glsl): with
  // record = (px == the probed pixel) the cone trace took 3x as long.
  const bool record = kRecordProbe;
  ivec2 px;
  if (!recorderPixel(u_probePixel, px)) return;
  if (any(greaterThanEqual(px, imageSize(u_indirectDiffuse)))) return;
  ConeSurface surface = coneSurface(px);
  if (!surface.valid) {
    imageStore(u_indirectDiffuse, px, vec4(0.0));
#if SVO_SPECULAR_CONE == 1
    imageStore(u_indirectSpecular, px, vec4(0.0));
#endif
    imageStore(u_ambientOcclusion, px, vec4(0.0));
#if SVO_SHADOW_CONE == 1
    imageStore(u_softShadow, px, vec4(0.0));
#endif
    return;
  }
  vec3 n = surface.normal;
  vec3 origin = surface.origin;
  float start = u_voxelSize;
  vec3 t, b;
  coneFrame(n, t, b);
  if (u_aoJitter == 1) {
    // A fixed hash of the pixel (the same image every run): the constellation's banding becomes noise.
    uint h = uint(px.x) * 1973u + uint(px.y) * 9277u + 26699u;
    h = (h ^ (h >> 13u)) * 0x5bd1e995u;
    h ^= h >> 15u;
    float angle = float(h & 0xffffu) / 65536.0 * 6.28318530718;
    vec3 turned = cos(angle) * t + sin(angle) * b;
    b = cross(n, turned);
    t = turned;
  }
  vec3 incoming = vec3(0.0);
  float occlusion = 0.0;
  vec3 view = normalize(surface.position - u_cameraPos);
  vec3 mirror = reflect(view, n);
  vec3 specular = vec3(0.0);
#if SVO_AO_CONES == 1
  const int aoCones = u_aoConeCount;
#else
  const int aoCones = 0;
#endif
  // The diffuse cones, then (SVO_AO_CONES) the ambient-occlusion ones, then the specular one, in
  // one loop: the march's code (a copy per call, each loop of it with its own lookups) is compiled
  // once for all of them. Without the specular image (outputs on demand) only the probed pixel's
  // record traces the specular cone.
  const int specularCones = SVO_SPECULAR_CONE == 1 || record ? 1 : 0;
  for (int i = 0; i < u_coneCount + aoCones + specularCones; ++i) {
    const bool diffuse = i < u_coneCount;
    const bool ambient = !diffuse && i < u_coneCount + aoCones;
    const bool specularCone = !diffuse && !ambient;
    vec4 cone = diffuse ? u_cones[min(i, VOXLAB_MAX_CONES - 1)] : u_aoCones[clamp(i - u_coneCount, 0, VOXLAB_MAX_CONES - 1)];
    ConeResult c = traceCone(origin, specularCone ? mirror : coneAxis(cone, t, b, n),
                             diffuse ? u_diffuseAperture : ambient ? u_aoAperture : u_specularAperture, start,
                             ambient ? u_aoRange : u_maxDistance, specularCone ? 0.0 : u_aoRange,
                             diffuse ? i : ambient ? u_coneCount + 2 + (i - u_coneCount) : u_coneCount, record,
                             !ambient, true);
    if (diffuse) incoming += cone.w * c.radiance;
    // Ambient occlusion from the diffuse cones, or from its own constellation (ao.cones).
    if (SVO_AO_CONES == 0 ? diffuse : ambient) occlusion += cone.w * c.occlusion;
    if (specularCone) specular = c.radiance;
  }
  imageStore(u_indirectDiffuse, px, vec4(surface.albedo * incoming, 1.0));
  imageStore(u_ambientOcclusion, px, vec4(1.0 - occlusion));
#if SVO_SPECULAR_CONE == 1
  imageStore(u_indirectSpecular, px, vec4(specular, 1.0));
#endif
  // Without the soft-shadow image (outputs on demand) only the probed pixel traces it, for its record.
#if SVO_SHADOW_CONE == 0
  if (!record) return;
#endif
  vec3 toLight; float dist;
  lightDirection(surface.position, toLight, dist);
  float shadowVis = 0.0;
  if (dot(n, toLight) > 0.0) {
    float end = shadowConeEnd(dist, tan(0.5 * u_shadowAperture), u_lodBias, u_voxelSize);
    // The shadow cone, the narrowest (about 24 of its samples at the voxels), skips the halo reads
    // (svo.voxel-halo): on the Cornell box its image is unchanged to the eye and SoftShadowCone's
    // numbers barely move, while the halo's eight octree look-ups per sample cost time.
    ConeResult sh = traceCone(origin, toLight, u_shadowAperture, start, min(end, u_maxDistance), 1e30,
                              u_coneCount + 1, record, false, false);
    shadowVis = 1.0 - sh.blocked;
  }
#if SVO_SHADOW_CONE == 1
  imageStore(u_softShadow, px, vec4(shadowVis));
#endif
}
