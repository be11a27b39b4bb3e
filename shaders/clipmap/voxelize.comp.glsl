#version 450
// Slab voxelization and light injection: one invocation per listed triangle of one material
// (whose textures are bound), for a list of entries (level, box of the planner's direct
// set, box to skip); the stage groups the entries so that no invocation's loops can pass
// llvmpipe's 65535 iterations (at most 7 N^2 per entry: N^2 columns, up to 6 candidates each). Cells are those of the lattice anchored to the world:
// cell c of level k covers [c, c+1) * s_k metres, and a vertex's cell coordinates are
// p * (1 / s_k), the same numbers whatever the camera, the level's origin or the box. Each
// (triangle, cell) pair is decided by the exact half-open triangle/cell test of
// common/triangle_cells.glsl (vct-grid's voxelizers use it too) in triangle-local double
// coordinates, so a cell gets the same triangles in a slab as in a full build. Each pair adds its
// direct light (Lambert, shadow-mapped, plus emission, evaluated at the point of the triangle
// nearest the cell centre) to the cell's fixed-point accumulators with integer atomics: the sums do
// not depend on the order. With six faces it also adds, per travel direction of a cone, the light
// of the fragments whose fronts that direction sees, and ORs the fragment's facing code
// (common/facing.glsl).
#include "common/shared.h"
#include "clipmap/clipmap.glsl"
#include "common/scene_triangles.glsl"
#include "common/alpha_coverage.glsl"

layout(local_size_x = 64) in;
#include "common/material.glsl"
#include "common/triangle_normal.glsl"
#include "common/lights.glsl"
#include "common/triangle_cells.glsl"
#include "common/facing.glsl"
layout(std430, binding = CLIPMAP_BINDING_ACCUM) buffer Accumulators { uint accum[]; };
layout(std430, binding = CLIPMAP_BINDING_COUNTERS) buffer Counters { uint counters[]; };
// The triangles this pass visits (those whose bounds reach an entry, tested on the CPU), one
// material per dispatch; u_firstTriangle and u_triangleCount index this list.
layout(std430, binding = VOXLAB_BINDING_TRIANGLE_LIST) readonly buffer TriangleList { uint triangleList[]; };
layout(binding = 2) uniform sampler2D u_shadowMap;
uniform uint u_firstTriangle;
uniform uint u_triangleCount;
#define CLIPMAP_MAX_ENTRIES 40
uniform int u_entryCount;
uniform int u_entryLevel[CLIPMAP_MAX_ENTRIES];
uniform ivec3 u_entryLo[CLIPMAP_MAX_ENTRIES];      // the box [lo, hi) of cells to voxelize
uniform ivec3 u_entryHi[CLIPMAP_MAX_ENTRIES];
uniform ivec3 u_entrySkipLo[CLIPMAP_MAX_ENTRIES];  // cells of [skipLo, skipHi) are left alone
uniform ivec3 u_entrySkipHi[CLIPMAP_MAX_ENTRIES];  // (a full build's covered block)
uniform float u_cellsPerMetre[CLIPMAP_MAX_LEVELS]; // 1 / s_k
uniform float u_cellSize[CLIPMAP_MAX_LEVELS];      // s_k, metres
uniform int u_mode;             // 0 = direct light, 1 = uniform radiance (furnace tests)
uniform vec3 u_uniformRadiance;
const float PI = 3.14159265358979;

vec3 toProjected(vec3 v, int axis) { return axis == 0 ? v.yzx : (axis == 1 ? v.zxy : v); }
ivec3 toProjectedI(ivec3 v, int axis) { return axis == 0 ? v.yzx : (axis == 1 ? v.zxy : v); }
ivec3 fromProjectedI(ivec3 s, int axis) { return axis == 0 ? s.zxy : (axis == 1 ? s.yzx : s); }

// The point of segment [a, b] nearest to p.
vec3 nearestOnSegment(vec3 p, vec3 a, vec3 b) {
  vec3 ab = b - a;
  float t = clamp(dot(p - a, ab) / max(dot(ab, ab), 1e-30), 0.0, 1.0);
  return a + t * ab;
}

// The point of triangle (a, b, c) nearest to p: p's projection onto the triangle's plane when it
// falls inside the triangle (on the inner side of all three edges), else the nearest point of the
// three edges.
vec3 nearestOnTriangle(vec3 p, vec3 a, vec3 b, vec3 c) {
  vec3 n = cross(b - a, c - a);
  float area2 = dot(n, n);
  if (area2 > 1e-30) {
    vec3 q = p - n * (dot(n, p - a) / area2);
    if (dot(cross(b - a, q - a), n) >= 0.0 && dot(cross(c - b, q - b), n) >= 0.0 && dot(cross(a - c, q - c), n) >= 0.0)
      return q;
  }
  vec3 onAB = nearestOnSegment(p, a, b), onBC = nearestOnSegment(p, b, c), onCA = nearestOnSegment(p, c, a);
  float dAB = dot(p - onAB, p - onAB), dBC = dot(p - onBC, p - onBC), dCA = dot(p - onCA, p - onCA);
  return dAB <= dBC && dAB <= dCA ? onAB : (dBC <= dCA ? onBC : onCA);
}

// Adds a fragment's fixed-point light to a cell's 32-bit sum. A sum of non-negative terms wraps
// past 2^32 floor(total / 2^32) times whatever the order, and exactly the additions that carry
// see the sum before them above 2^32 - 1 - value: they are counted after the levels' counters
// (reported by the stages), so a real overflow is never silent and a crowded cell whose light fits
// is not reported.
void addLight(uint index, uint value) {
  uint before = atomicAdd(accum[index], value);
  if (before > 0xFFFFFFFFu - value) atomicAdd(counters[5 * u_clipLevels], 1u);
}

void voxelizeEntry(uint t, int e) {
  const int level = u_entryLevel[e];
  uint i0 = sceneVertexIndex(t, 0), i1 = sceneVertexIndex(t, 1), i2 = sceneVertexIndex(t, 2);
  precise vec3 w0 = scenePosition(i0) * u_cellsPerMetre[level];
  precise vec3 w1 = scenePosition(i1) * u_cellsPerMetre[level];
  precise vec3 w2 = scenePosition(i2) * u_cellsPerMetre[level];
  vec3 lo = min(w0, min(w1, w2)), hi = max(w0, max(w1, w2));
  ivec3 bLo = max(ivec3(floor(lo)), u_entryLo[e]);
  ivec3 bHi = min(ivec3(floor(hi)), u_entryHi[e] - 1);
  if (any(greaterThan(bLo, bHi))) return;
  ivec3 skipLo = u_entrySkipLo[e], skipHi = u_entrySkipHi[e];

  // Triangle-local coordinates relative to an integer corner: exact in double.
  vec3 origin = floor(w0);
  ivec3 iorigin = ivec3(origin);
  dvec3 d0 = dvec3(w0) - dvec3(origin), d1 = dvec3(w1) - dvec3(origin), d2 = dvec3(w2) - dvec3(origin);
  dvec3 dn = cross(d1 - d0, d2 - d0);
  if (max(abs(dn.x), max(abs(dn.y), abs(dn.z))) <= 0.0) return;
  vec3 n = vec3(dn);
  int axis = dominantAxis(n);
  vec3 vertexNormals = sceneNormal(i0) + sceneNormal(i1) + sceneNormal(i2);
  vec3 normal = facingPlaneNormal(n, vertexNormals);
  // Which way the fronts face, from the normal as a voxel fragment carries it (8-bit snorm, as
  // vct-grid's voxelizers store it): the same surface gets vct-grid's facing code.
  vec3 facingNormal = normalize(unpackSnorm4x8(packSnorm4x8(vec4(normal, 0.0))).xyz);

  uint material = uint(u_materialIndex);
  vec4 alpha = materials[material].alpha;
  bool masked = coverageMasked(alpha);
  vec3 l0 = vec3(d0), l1 = vec3(d1), l2 = vec3(d2);
  vec2 t0 = sceneUv(i0), t1 = sceneUv(i1), t2 = sceneUv(i2);
  uint coverageLevel = masked ? coverageLevelFor(alpha, l0, l1, l2, t0, t1, t2) : 0u;
  float lod = voxelTextureLod(l0, l1, l2, t0, t1, t2);
  // The exact test's setup, once per triangle (the loops below stay inside its bounding box).
  TriangleCells cells = triangleCellsSetup(w0, w1, w2);

  // Columns along the dominant axis; in each, the cells the plane can reach (a superset: the
  // exact test decides).
  vec3 s0 = toProjected(l0, axis), sn = toProjected(n, axis);
  vec2 grad = -sn.xy / sn.z;
  float reach = 0.5 * (abs(grad.x) + abs(grad.y));
  ivec3 pLo = toProjectedI(bLo - iorigin, axis), pHi = toProjectedI(bHi - iorigin, axis);
  for (int b = pLo.y; b <= pHi.y; ++b)
    for (int a = pLo.x; a <= pHi.x; ++a) {
      vec2 center = vec2(a, b) + 0.5;
      float zc = s0.z + dot(grad, center - s0.xy);
      int kLo = max(int(floor(zc - reach)) - 1, pLo.z), kHi = min(int(floor(zc + reach)) + 1, pHi.z);
      for (int k = kLo; k <= kHi; ++k) {
        ivec3 local = fromProjectedI(ivec3(a, b, k), axis);  // cell, triangle-local
        ivec3 cell = iorigin + local;
        if (all(greaterThanEqual(cell, skipLo)) && all(lessThan(cell, skipHi))) continue;
        if (!triangleMeetsCell(cells, vec3(cell))) continue;
        vec3 centre = vec3(local) + 0.5;
        if (masked && !coverageAt(alpha, coverageLevel, l0, l1, l2, t0, t1, t2, local)) continue;
        vec3 radiance;
        if (u_mode == 1) {
          radiance = u_uniformRadiance;
        } else {
          // The point of the triangle nearest the cell centre, in world metres: where a cell holds
          // only a sliver of a surface, the centre's projection onto the plane lies off the
          // triangle (above the ceiling, beyond a corner), where the light and the shadow map
          // belong to another place; coarse cells hold more such slivers.
          vec3 p = (origin + nearestOnTriangle(centre, l0, l1, l2)) * u_cellSize[level];
          vec3 toLight; float dist;
          lightDirection(p, toLight, dist);
          float cosine = max(dot(normal, toLight), 0.0);
          vec3 albedo = materialAlbedoLod(voxelSampleUv(l0, l1, l2, t0, t1, t2, local), lod).rgb;
          vec3 emission = materialEmissionLod(voxelSampleUv(l0, l1, l2, t0, t1, t2, local), lod);
          radiance = albedo / PI * lightIrradiance(p) * cosine * shadowVisibility(u_shadowMap, p, normal) + emission;
        }
        // One fragment's light alone may pass 2^32 (b > 26 with HDR cells): it saturates, counted
        // as an overflow too.
        vec3 scaled = clamp(radiance, 0.0, u_maxRadiance) * u_fixedScale + 0.5;
        if (any(greaterThanEqual(scaled, vec3(4294967296.0)))) atomicAdd(counters[5 * u_clipLevels], 1u);
        uvec3 fixedPoint = uvec3(min(scaled, vec3(4294967040.0)));
        uint i = accumulatorIndex(level, toroidalAddress(cell));
        atomicAdd(accum[i], 1u);
        addLight(i + 1u, fixedPoint.r);
        addLight(i + 2u, fixedPoint.g);
        addLight(i + 3u, fixedPoint.b);
        if (u_cellWords > 4u) {
          // Six faces: the facing code, and the light of the fragment for every direction that
          // sees its front (resolve.comp.glsl shows each direction the fronts it sees).
          atomicOr(accum[i + kClipFacingWord], facingCode(facingNormal));
          for (int d = 0; d < 6; ++d) {
            if (frontSteps(facingNormal, d) == 0u) continue;
            uint j = i + clipDirectionWord(d);
            atomicAdd(accum[j], 1u);
            addLight(j + 1u, fixedPoint.r);
            addLight(j + 2u, fixedPoint.g);
            addLight(j + 3u, fixedPoint.b);
          }
        }
        atomicAdd(counters[5 * level + 1], 1u);
      }
    }
}

void main() {
  if (gl_GlobalInvocationID.x >= u_triangleCount) return;
  uint t = triangleList[u_firstTriangle + gl_GlobalInvocationID.x];
  for (int e = 0; e < u_entryCount; ++e) voxelizeEntry(t, e);
}
