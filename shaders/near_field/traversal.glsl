// Hierarchical traversal of the binary voxel hierarchy (seed 000 section 4.4.6, Listing 4.47;
// after Forest et al. 2009), in the unit space of the voxel volume ([0,1]^3, z = slice axis).
//
// Differences from the thesis / GP3 code, each one a known error there (docs/fidelity.md):
//  - exact stepping: the next texel comes from the exit face of the current one (no 0.25-texel
//    offset that skips thin corner crossings);
//  - ray masks from a table whose slice range always has first <= last (no XOR[128] fetch);
//  - the first set bit by findMSB / findLSB (no log2 of a float of an int);
//  - an origin outside the volume ends the walk as NF_END_OUTSIDE before any fetch;
//  - running out of steps is NF_END_BUDGET, reported, not a silent miss;
//  - the hit point is the ray's own point in the hit voxel, not the column entry point.
#include "near_field/near_field_shared.h"

layout(binding = 4) uniform usampler2D u_hierarchy;  // RGBA32UI columns, levels 0..u_maxLevel
layout(binding = 5) uniform usampler2D u_rayMasks;   // RGBA32UI, texel (first, last) = slices first..last
uniform int u_gridRes;     // level-0 columns per side
uniform int u_maxLevel;    // log2(u_gridRes)
uniform int u_startLevel;  // the walk starts at min(u_startLevel, u_maxLevel)

struct Walk {
  uint end;       // NF_END_*
  ivec3 voxel;    // hit column and slice (level 0)
  float tHit;     // segment parameter of the hit point (0..1)
  int steps;      // texels visited
};

// First set slice of a mask along the ray: smallest index toward +z, largest toward -z.
int firstSliceAlong(uvec4 m, bool towardMinusZ) {
  if (!towardMinusZ) {
    for (int c = 0; c < 4; ++c)
      if (m[c] != 0u) return c * 32 + (31 - findMSB(m[c]));
  } else {
    for (int c = 3; c >= 0; --c)
      if (m[c] != 0u) return c * 32 + (31 - findLSB(m[c]));
  }
  return -1;
}

#ifdef NF_RECORD_STEPS
layout(std430, binding = NF_BINDING_TRAVERSAL_STEPS) buffer Steps { TraversalStep steps[]; };
layout(std430, binding = NF_BINDING_RAY_COUNTERS) buffer Counters { uint counters[]; };
void recordStep(bool on, int i, int level, ivec2 pc, int k0, int k1, uint action, int hitSlice,
                uvec4 ray, uvec4 hitMask, float t0, float t1, float tEnd) {
  if (!on) return;
  uint slot = atomicAdd(counters[0], 1u);
  if (slot >= uint(NF_MAX_TRAVERSAL_STEPS)) return;
  steps[slot].where = uvec4(uint(i), uint(level), uvec2(pc));
  steps[slot].slices = uvec4(uint(k0), uint(k1), action, hitSlice < 0 ? 255u : uint(hitSlice));
  steps[slot].rayMask = ray;
  steps[slot].hitMask = hitMask;
  steps[slot].t = vec4(t0, t1, tEnd, 0.0);
}
#else
#define recordStep(on, i, level, pc, k0, k1, action, hitSlice, ray, hitMask, t0, t1, tEnd)
#endif

// Walks the segment o -> e (unit space, t in [0, 1]) to the first set voxel, at most 'budget'
// texels. 'record' writes every step to the probe buffer (NF_RECORD_STEPS builds only).
Walk traverse(vec3 o, vec3 e, int budget, bool record) {
  Walk w;
  w.end = NF_END_LEFT;
  w.voxel = ivec3(-1);
  w.tHit = 1.0;
  w.steps = 0;
  if (any(lessThan(o, vec3(0.0))) || any(greaterThanEqual(o, vec3(1.0)))) {
    w.end = NF_END_OUTSIDE;
    return w;
  }
  vec3 d = e - o;
  // Segment end clipped to the volume; for d == 0 along an axis that axis never limits it.
  float tEnd = 1.0;
  for (int a = 0; a < 3; ++a) {
    if (d[a] > 0.0) tEnd = min(tEnd, (1.0 - o[a]) / d[a]);
    else if (d[a] < 0.0) tEnd = min(tEnd, -o[a] / d[a]);
  }
  ivec2 col = clamp(ivec2(floor(o.xy * float(u_gridRes))), ivec2(0), ivec2(u_gridRes - 1));
  int level = min(u_startLevel, u_maxLevel);
  float t = 0.0;
  bool towardMinusZ = d.z < 0.0;
  for (int i = 0; i < budget; ++i) {
    w.steps = i + 1;
    int resL = u_gridRes >> level;
    ivec2 pc = col >> level;
    // Parameter where the ray leaves the texel's column through its x and y faces.
    vec2 tFace = vec2(1e30);
    for (int a = 0; a < 2; ++a) {
      if (d[a] > 0.0) tFace[a] = (float(pc[a] + 1) / float(resL) - o[a]) / d[a];
      else if (d[a] < 0.0) tFace[a] = (float(pc[a]) / float(resL) - o[a]) / d[a];
    }
    float tExit = min(min(tFace.x, tFace.y), tEnd);
    float z0 = o.z + t * d.z, z1 = o.z + tExit * d.z;
    int k0 = clamp(int(floor(min(z0, z1) * float(NF_SLICES))), 0, NF_SLICES - 1);
    int k1 = clamp(int(floor(max(z0, z1) * float(NF_SLICES))), 0, NF_SLICES - 1);
    uvec4 ray = texelFetch(u_rayMasks, ivec2(k0, k1), 0);
    uvec4 hitMask = ray & texelFetch(u_hierarchy, pc, level);
    if (any(notEqual(hitMask, uvec4(0u)))) {
      if (level == 0) {
        int k = firstSliceAlong(hitMask, towardMinusZ);
        // The ray's entry into slice k, within the column's part of the segment.
        float zEntry = float(towardMinusZ ? k + 1 : k) / float(NF_SLICES);
        float tz = d.z != 0.0 ? (zEntry - o.z) / d.z : t;
        w.tHit = clamp(tz, t, tExit);
        w.voxel = ivec3(pc, k);
        w.end = NF_END_HIT;
        recordStep(record, i, level, pc, k0, k1, NF_END_HIT, k, ray, hitMask, t, tExit, tEnd);
        return w;
      }
      recordStep(record, i, level, pc, k0, k1, NF_STEP_DESCEND, -1, ray, hitMask, t, tExit, tEnd);
      level -= 1;
      continue;
    }
    recordStep(record, i, level, pc, k0, k1, NF_STEP_ADVANCE, -1, ray, hitMask, t, tExit, tEnd);
    if (tExit >= tEnd) return w;  // NF_END_LEFT
    t = tExit;
    // Step the level-0 column across the exit face(s) of the level-'level' texel.
    for (int a = 0; a < 2; ++a) {
      int lo = pc[a] << level, hi = ((pc[a] + 1) << level) - 1;
      if (tFace[a] <= tExit) col[a] = d[a] > 0.0 ? hi + 1 : lo - 1;
      else col[a] = clamp(int(floor((o[a] + t * d[a]) * float(u_gridRes))), lo, hi);
    }
    if (any(lessThan(col, ivec2(0))) || any(greaterThanEqual(col, ivec2(u_gridRes)))) return w;
    level = min(level + 1, u_maxLevel);
  }
  w.end = NF_END_BUDGET;
  return w;
}
