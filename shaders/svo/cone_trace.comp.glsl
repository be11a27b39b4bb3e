#version 450
// svo-cone-trace, one invocation per traced pixel: the cones of vct-grid's cone-trace (diffuse
// cones with their AO, one specular cone, one soft-shadow cone), sampling the octree instead of a
// dense mip chain. Each sample descends from the root to the level of its diameter and blends two
// levels (quadrilinear, svoFineWeight in svo_shared.h); inside a node the brick's 3x3x3 texels are
// filtered by the hardware (texel coordinate 3 * brick + 0.5 + 2u, u the position in the node).
// Ambient occlusion can use its own constellation (Basgier's 3, 5 or 8 cones) and weights each
// sample's opacity by the falloff f(r) = 1 / (1 + lambda r), r in voxels (lambda 0: vct-grid's
// plain range cut). For the probed pixel every sample and every level of its descent is recorded.
// With anisotropic mips (u_anisotropic) a node above the voxels is read from its three directional
// bricks facing the cone, weighted dir^2 (common/anisotropic_mip.glsl, as vct-grid's
// sampleVolume); the voxels stay isotropic, so between the voxel level and the one above a sample
// blends the leaf with the directional value, as vct-grid fades its voxels into directional level 1.
// A voxel without a brick (empty, or no node: bricks are only on non-empty nodes) is read as the
// dense grid reads it, from the eight voxels around the sample (u_voxelHalo, voxelLevelSample).
#include "common/shared.h"
#include "common/voxel_space.glsl"
#include "common/packing.glsl"
#include "common/lights.glsl"
#include "common/cone_setup.glsl"
#include "common/sky.glsl"
#include "common/anisotropic_mip.glsl"
#include "svo/svo_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = SVO_BINDING_NODES) readonly buffer Nodes { SvoNode nodes[]; };
layout(std430, binding = SVO_BINDING_BRICK_INDEX) readonly buffer BrickIndex { uint brickIndex[]; };
layout(std430, binding = SVO_BINDING_VALUES) readonly buffer Values { vec4 values[]; };
layout(std430, binding = VOXLAB_BINDING_CONE_SAMPLES) writeonly buffer ConeSamples { ConeSample coneSamples[]; };
layout(std430, binding = VOXLAB_BINDING_CONE_SAMPLE_COUNT) buffer ConeSampleCount { uint coneSampleCount; };
layout(std430, binding = SVO_BINDING_DESCENT) writeonly buffer Descent { SvoDescentStep descent[]; };
layout(std430, binding = SVO_BINDING_DESCENT_COUNT) buffer DescentCount { uint descentCount; };
layout(binding = 0) uniform sampler3D u_brickPool;
layout(binding = 4) uniform sampler3D u_directionalPool;  // six parts stacked along z: +x -x +y -y +z -z
layout(rgba16f, binding = 0) uniform writeonly image2D u_indirectDiffuse;
layout(rgba16f, binding = 1) uniform writeonly image2D u_indirectSpecular;
layout(r16f, binding = 2) uniform writeonly image2D u_ambientOcclusion;
layout(r16f, binding = 3) uniform writeonly image2D u_softShadow;

uniform int u_depth;
uniform ivec3 u_bricksPerAxis;
uniform int u_dilated;            // 1: empty neighbours have nodes, so an absent node is exactly 0
uniform int u_layoutTile;         // 1: Layout T, the brick of a level-l node holds level l + 1
uniform int u_anisotropic;        // 1: nodes above the voxels are read from their directional bricks
uniform int u_voxelHalo;          // 1: a voxel without a brick is read as the dense grid's blend (voxelLevelSample)
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

// The trilinear sample of the brick of 'node' (at 'level', holding voxel 'voxel') at voxel-space
// point v (clamped into the node), as seen by a cone travelling along 'dir'. The node's cell
// follows from the voxel: no pool read for it.
vec4 brickSample(uint node, int level, uvec3 voxel, vec3 v, vec3 dir) {
  uint b = brickIndex[node];
  if (b == 0u) return vec4(0.0);
  float cell = exp2(float(u_depth - level));
  vec3 u = clamp(v / cell - vec3(voxel >> uint(u_depth - level)), 0.0, 1.0);
  if (u_anisotropic == 1 && level < u_depth) {
    // Directional bricks: the +axis or -axis part of each axis is a z offset (the same lookups for
    // every pixel, whatever the sign: no divergent branch on llvmpipe).
    vec3 size = vec3(textureSize(u_directionalPool, 0));
    vec3 texel = 3.0 * vec3(svoBrickCoords(b, uvec2(u_directionalPerAxis.xy))) + 0.5 + 2.0 * u;
    float part = 3.0 * float(u_directionalPerAxis.z);
    vec3 w = anisotropicWeights(dir);
    vec4 sx = textureLod(u_directionalPool, (texel + vec3(0.0, 0.0, part * (dir.x < 0.0 ? 1.0 : 0.0))) / size, 0.0);
    vec4 sy = textureLod(u_directionalPool, (texel + vec3(0.0, 0.0, part * (dir.y < 0.0 ? 3.0 : 2.0))) / size, 0.0);
    vec4 sz = textureLod(u_directionalPool, (texel + vec3(0.0, 0.0, part * (dir.z < 0.0 ? 5.0 : 4.0))) / size, 0.0);
    return w.x * sx + w.y * sy + w.z * sz;
  }
  vec3 origin = 3.0 * vec3(svoBrickCoords(b, uvec2(u_bricksPerAxis.xy)));
  return textureLod(u_brickPool, (origin + 0.5 + 2.0 * u) / vec3(textureSize(u_brickPool, 0)), 0.0);
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
    if (all(equal(cell, voxel))) continue;  // the sample's own voxel has no brick: it is empty
    uint n = svoVoxelFrom(from, level, voxel, cell);
    vec3 w3 = mix(1.0 - f, f, vec3(bit));
    if (n != SVO_ABSENT) sum += (w3.x * w3.y * w3.z) * values[n];
  }
  return sum;
}

// The octree at voxel-space point v and fractional level levelStar (0 = root .. D = voxels), seen
// along 'dir': one descent from the root to the fine level, keeping the node one level above as
// the coarse one. Layout T: level l is read from the bricks of level l - 1 (the descent ends one
// level higher and the root's brick is the coarsest level, 1).
vec4 svoSample(vec3 v, float levelStar, vec3 dir, bool record, uint sampleIndex) {
  const int shift = u_layoutTile;
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
      vec4 value = node == SVO_ABSENT ? vec4(0.0) : brickSample(node, l, voxel, v, dir);
      if (k < SVO_MAX_DESCENT_STEPS)
        descent[k] = SvoDescentStep(sampleIndex, uint(l), node, packVoxel10(voxel >> uint(u_depth - l)),
                                    float[4](value.r, value.g, value.b, value.a));
    }
    if (node == SVO_ABSENT) break;  // the record ends at the first absent node
    deepest = node;
    deepestLevel = l;
  }
  vec4 coarse = coarseNode == SVO_ABSENT ? vec4(0.0) : brickSample(coarseNode, fine - 1, voxel, v, dir);
  // At the voxel level a voxel without a brick is read as the dense grid reads it (svo.voxel-halo).
  const bool denseVoxels = u_voxelHalo == 1 && fine == u_depth;
  if (fineNode == SVO_ABSENT && denseVoxels) return mix(coarse, voxelLevelSample(v, deepest, deepestLevel, voxel), w);
  if (fineNode == SVO_ABSENT) {
    // Without dilation an absent fine node next to a filled one is not exactly empty: use the
    // coarse level alone there (the note's fallback for source error P2).
    if (u_dilated == 0) return coarse;
    return (1.0 - w) * coarse;
  }
  vec4 fineValue = denseVoxels && brickIndex[fineNode] == 0u ? voxelLevelSample(v, fineNode, fine, voxel)
                                                               : brickSample(fineNode, fine, voxel, v, dir);
  return mix(coarse, fineValue, w);
}

struct ConeResult {
  vec3 radiance;
  float opacity;
  float occlusion;  // opacity with the AO falloff, accumulated up to markDistance
};

ConeResult traceCone(vec3 origin, vec3 dir, float aperture, float startDistance, float maxDistance,
                     float markDistance, int coneIndex, bool record) {
  float tanHalf = tan(0.5 * aperture);
  float t = startDistance;
  ConeResult r = ConeResult(vec3(0.0), 0.0, 0.0);
  bool left = false;  // the sample lay wholly outside the volume
  for (int step = 0; step < u_maxSteps && r.opacity < 0.99 && t < maxDistance; ++step) {
    float diameter = max(2.0 * tanHalf * t, u_voxelSize);
    float lod = max(log2(diameter / u_voxelSize) + u_lodBias, 0.0);
    float levelStar = clamp(float(u_depth) - lod, 0.0, float(u_depth));
    vec3 p = origin + dir * t;
    vec3 v = worldToVoxel(p);
    float margin = 0.5 * diameter / u_voxelSize;
    if (any(lessThan(v, vec3(-margin))) || any(greaterThan(v, vec3(float(u_resolution) + margin)))) { left = true; break; }
    uint k = 0u;
    if (record) k = atomicAdd(coneSampleCount, 1u);
    vec4 s = svoSample(v, levelStar, dir, record, k);
    float stepLength = diameter * u_stepScale;
    float texelSize = u_voxelSize * exp2(lod);
    float a = 1.0 - pow(max(1.0 - s.a, 0.0), stepLength / texelSize);
    vec3 c = s.a > 0.0 ? s.rgb * (a / s.a) : vec3(0.0);
    r.radiance += (1.0 - r.opacity) * c;
    if (t <= markDistance) {
      float falloff = 1.0 / (1.0 + u_aoFalloff * t / u_voxelSize);
      r.occlusion += (1.0 - r.occlusion) * a * falloff;
    }
    r.opacity += (1.0 - r.opacity) * a;
    if (record && k < uint(VOXLAB_MAX_CONES * VOXLAB_MAX_SAMPLES_PER_CONE))
      coneSamples[k] = ConeSample(vec4(p, diameter), vec4(r.radiance, r.opacity), vec4(float(coneIndex), t, lod, a));
    t += stepLength;
  }
  r.radiance += coneSky(left, t >= maxDistance, origin + dir * t, r.opacity);  // common/sky.glsl
  return r;
}

void main() {
  // The probed pixel's records come from a second program (SVO_RECORD_PROBE), dispatched as one
  // work group in which only the first invocation runs, tracing that pixel again (the same values)
  // with record set. In the program for every pixel record is a compile-time false, so the
  // recording code is not there: llvmpipe runs a branch that depends on the invocation masked in
  // every invocation, and the cone trace took 3x as long with record = (px == the probed pixel).
#ifdef SVO_RECORD_PROBE
  const bool record = true;
  if (gl_LocalInvocationIndex != 0u) return;
  ivec2 px = u_probePixel;
#else
  const bool record = false;
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
#endif
  if (any(greaterThanEqual(px, imageSize(u_indirectDiffuse)))) return;
  ConeSurface surface = coneSurface(px);
  if (!surface.valid) {
    imageStore(u_indirectDiffuse, px, vec4(0.0));
    imageStore(u_indirectSpecular, px, vec4(0.0));
    imageStore(u_ambientOcclusion, px, vec4(0.0));
    imageStore(u_softShadow, px, vec4(0.0));
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
  for (int i = 0; i < u_coneCount; ++i) {
    ConeResult c = traceCone(origin, coneAxis(u_cones[i], t, b, n), u_diffuseAperture, start, u_maxDistance, u_aoRange, i, record);
    incoming += u_cones[i].w * c.radiance;
    occlusion += u_cones[i].w * c.occlusion;
  }
  if (u_aoConeCount > 0) {
    occlusion = 0.0;
    for (int i = 0; i < u_aoConeCount; ++i) {
      ConeResult c = traceCone(origin, coneAxis(u_aoCones[i], t, b, n), u_aoAperture, start, u_aoRange, u_aoRange,
                               u_coneCount + 2 + i, record);
      occlusion += u_aoCones[i].w * c.occlusion;
    }
  }
  imageStore(u_indirectDiffuse, px, vec4(surface.albedo * incoming, 1.0));
  imageStore(u_ambientOcclusion, px, vec4(1.0 - occlusion));

  vec3 view = normalize(surface.position - u_cameraPos);
  ConeResult spec = traceCone(origin, reflect(view, n), u_specularAperture, start, u_maxDistance, u_maxDistance,
                              u_coneCount, record);
  imageStore(u_indirectSpecular, px, vec4(spec.radiance, 1.0));
  vec3 toLight; float dist;
  lightDirection(surface.position, toLight, dist);
  float shadowVis = 0.0;
  if (dot(n, toLight) > 0.0) {
    float end = shadowConeEnd(dist, tan(0.5 * u_shadowAperture), u_lodBias, u_voxelSize);
    ConeResult sh = traceCone(origin, toLight, u_shadowAperture, start, min(end, u_maxDistance), 0.0,
                              u_coneCount + 1, record);
    shadowVis = 1.0 - sh.opacity;
  }
  imageStore(u_softShadow, px, vec4(shadowVis));
}
