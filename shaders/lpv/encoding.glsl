// Voxel encodings of the LPV grids (seed 000 Listings 4.27-4.29), the twin of the encodings in
// src/techniques/lpv/sh.h (same operations in the same order, `precise` against fused
// multiply-adds), so the CPU reference bins fragments into bit-identical records.
#ifndef VOXLAB_LPV_ENCODING_GLSL
#define VOXLAB_LPV_ENCODING_GLSL
#include "lpv/lpv_shared.h"

const float LPV_INV255 = 0.003921568627;
const float LPV_DOT_FIELD_SCALE = 0.244094488;  // 31 / 127

vec3 tetraDirection(int k) {
  const float a = 0.57735027, b = 0.81649658;
  if (k == 0) return vec3(0.0, -a, b);
  if (k == 1) return vec3(0.0, -a, -b);
  if (k == 2) return vec3(-b, a, 0.0);
  return vec3(b, a, 0.0);
}

// Bits 0-7 B, 8-15 G, 16-23 R, 24-30 contrast * 127, 31 occupied.
uint encodeColorOcclusion(uvec3 rgb8) {
  precise float r = float(rgb8.x) * LPV_INV255;
  precise float g = float(rgb8.y) * LPV_INV255;
  precise float b = float(rgb8.z) * LPV_INV255;
  precise float dx = r - g, dy = r - b, dz = g - b;
  precise float len = sqrt((dx * dx + dy * dy) + dz * dz);
  precise float denom = (1.41421356 + r) + (g + b);
  precise float scaled = 127.0 * len;
  uint contrast = uint(scaled / denom);
  return 0x80000000u | (contrast << 24) | (rgb8.x << 16) | (rgb8.y << 8) | rgb8.z;
}
vec3 decodeColor(uint m) { return vec3(float((m >> 16) & 255u), float((m >> 8) & 255u), float(m & 255u)) * LPV_INV255; }
bool decodeOccupied(uint m) { return (m >> 31) != 0u; }

// Components k of a packSnorm4x8 word (-127..127).
ivec3 snormComponents(uint w) {
  ivec3 k = ivec3(bitfieldExtract(int(w), 0, 8), bitfieldExtract(int(w), 8, 8), bitfieldExtract(int(w), 16, 8));
  return max(k, ivec3(-127));
}
int tetraChannel(ivec3 k, out uint dotField) {
  int best = 0;
  float bestDot = -1e30;
  vec3 n = vec3(k);
  for (int c = 0; c < 4; ++c) {
    vec3 f = tetraDirection(c);
    precise float d = (n.x * f.x + n.y * f.y) + n.z * f.z;
    if (d > bestDot) { bestDot = d; best = c; }
  }
  precise float field = min(max(bestDot, 0.0), 127.0) * LPV_DOT_FIELD_SCALE;
  dotField = uint(field);
  return best;
}
uint normalMagnitude(int v) { return uint((abs(v) * 510 + 127) / 254); }
uint encodeNormalMask(ivec3 k, uint dotField) {
  return (dotField << 27) | (normalMagnitude(k.x) << 18) | (k.x < 0 ? 1u << 26 : 0u) | (normalMagnitude(k.y) << 9) |
         (k.y < 0 ? 1u << 17 : 0u) | normalMagnitude(k.z) | (k.z < 0 ? 1u << 8 : 0u);
}
vec3 decodeNormalMask(uint m) {
  vec3 v = vec3(float((m >> 18) & 255u), float((m >> 9) & 255u), float(m & 255u)) * LPV_INV255;
  return vec3(((m >> 26) & 1u) != 0u ? -v.x : v.x, ((m >> 17) & 1u) != 0u ? -v.y : v.y, ((m >> 8) & 1u) != 0u ? -v.z : v.z);
}

// The surface area one voxel fragment stands for, in 'units' per fragment voxel^2: the fragment's
// voxel holds 'count' fragments (every triangle touching a voxel adds one, so finely tessellated
// surfaces give several per voxel; they share the voxel), and a conservative voxelization of a
// plane of unit normal n covers |n|_1 / voxel^2 voxels per unit area (a voxel is cut by the plane
// when its centre lies in a slab |n.x| + |n.y| + |n.z| voxels thick), so one voxel holds
// voxel^2 / |n|_1 of it. The twin of fragmentAreaUnits in src/techniques/lpv/sh.h.
uint fragmentAreaUnits(ivec3 k, uint count, float units) {
  precise float l1 = float(abs(k.x) + abs(k.y) + abs(k.z));
  precise float l2 = sqrt(float(k.x * k.x + k.y * k.y + k.z * k.z));
  precise float perVoxel = l1 > 0.0 ? (units * l2) / l1 : units;
  precise float w = perVoxel / float(max(count, 1u));
  return uint(w + 0.5);
}

// One cascade: cell i covers u_gridOrigin + [i, i+1) * u_cellSize.
uniform vec3 u_gridOrigin;
uniform float u_cellSize;
uniform int u_gridRes;
int cellIndex(ivec3 c) { return (c.z * u_gridRes + c.y) * u_gridRes + c.x; }
bool cellInside(ivec3 c) { return all(greaterThanEqual(c, ivec3(0))) && all(lessThan(c, ivec3(u_gridRes))); }
#endif
