// Voxelization's alpha test for alphaMode MASK triangles: the rule of src/scene/alpha_coverage.h
// (read it there), written with the same float operations so the GPU voxelizers and the CPU
// reference voxelizer keep the same voxels. 'alpha' is GpuMaterial::alpha of the triangle's
// material; a, b, c are the triangle in voxel coordinates, ua, ub, uc its texture coordinates.
#include "common/shared.h"
layout(std430, binding = VOXLAB_BINDING_COVERAGE_BITS) readonly buffer CoverageBits { uint coverageBits[]; };
layout(std430, binding = VOXLAB_BINDING_COVERAGE_LEVELS) readonly buffer CoverageLevels { uvec4 coverageLevels[]; };

// A program built for one kind of material (common/material.glsl) knows it without reading.
bool coverageMasked(vec4 alpha) {
#if !defined(VOXLAB_MATERIAL_KIND)
  return alpha.y > 0.5;
#elif defined(VOXLAB_MATERIAL_ALPHA_MASK)
  return true;
#else
  return false;
#endif
}

uint coverageLevelFor(vec4 alpha, vec3 a, vec3 b, vec3 c, vec2 ua, vec2 ub, vec2 uc) {
  uint first = uint(alpha.z), count = uint(alpha.w);
  uvec4 L0 = coverageLevels[first];
  vec2 du = ub - ua, dv = uc - ua;
  float uvArea = abs(du.x * dv.y - du.y * dv.x) * float(L0.y) * float(L0.z);
  float area = length(cross(b - a, c - a));
  float ratio = area > 0.0 ? uvArea / area : 0.0;
  uint level = 0u;
  float scale = 1.0;
  while (level + 1u < count && scale < ratio) {
    ++level;
    scale *= 4.0;
  }
  return level;
}

bool coverageBit(uvec4 L, uint x, uint y) {
  uint i = L.x + y * L.y + x;
  return ((coverageBits[i >> 5] >> (i & 31u)) & 1u) != 0u;
}

uint coverageWrap(float i, uint n) {
  float m = i - floor(i / float(n)) * float(n);
  return min(uint(m), n - 1u);
}

// Texture coordinates of the voxel centre projected onto the triangle (barycentrics clamped).
vec2 voxelSampleUv(vec3 a, vec3 b, vec3 c, vec2 ua, vec2 ub, vec2 uc, ivec3 voxel) {
  vec3 e1 = b - a, e2 = c - a, q = vec3(voxel) + 0.5 - a;
  float d00 = dot(e1, e1), d01 = dot(e1, e2), d11 = dot(e2, e2);
  float d20 = dot(q, e1), d21 = dot(q, e2);
  float denom = d00 * d11 - d01 * d01;
  float wb = 0.0, wc = 0.0;
  if (denom > 0.0) {
    wb = (d11 * d20 - d01 * d21) / denom;
    wc = (d00 * d21 - d01 * d20) / denom;
  }
  float wa = 1.0 - wb - wc;
  wa = max(wa, 0.0);
  wb = max(wb, 0.0);
  wc = max(wc, 0.0);
  float sum = wa + wb + wc;
  return sum > 0.0 ? (ua * wa + ub * wb + uc * wc) / sum : ua;
}

bool coverageAt(vec4 alpha, uint level, vec3 a, vec3 b, vec3 c, vec2 ua, vec2 ub, vec2 uc, ivec3 voxel) {
  vec2 uv = voxelSampleUv(a, b, c, ua, ub, uc, voxel);
  uvec4 L = coverageLevels[uint(alpha.z) + level];
  float x = uv.x * float(L.y) - 0.5, y = uv.y * float(L.z) - 0.5;
  float fx = floor(x), fy = floor(y);
  uint x0 = coverageWrap(fx, L.y), x1 = coverageWrap(fx + 1.0, L.y);
  uint y0 = coverageWrap(fy, L.z), y1 = coverageWrap(fy + 1.0, L.z);
  return coverageBit(L, x0, y0) || coverageBit(L, x1, y0) || coverageBit(L, x0, y1) || coverageBit(L, x1, y1);
}
