// Alpha-masked voxelization: which voxels an alphaMode MASK triangle covers.
//
// Camera and light rasterization (G-buffer, shadow map) and the reference path tracer test the
// base-colour alpha at the shaded point (baseColorFactor.a x texture alpha < alphaCutoff: no
// surface). A voxel is larger than a texel, so voxelization asks instead whether the triangle is
// opaque anywhere near the voxel, and it must answer identically in the GPU voxelizers (raster and
// compute) and the CPU reference voxelizer. The rule, written once here and once in
// shaders/common/alpha_coverage.glsl with the same float operations:
//
//  1. Coverage pyramid per MASK material (built on the CPU at upload): level 0 holds one bit per
//     texel of the base-colour texture, set when factor.a x alpha >= alphaCutoff (alpha as the
//     8-bit value / 255); level k+1 is the OR of 2x2 texels of level k (sizes halve, rounding up).
//  2. Level per triangle: the smallest level whose texel is at least as large as a voxel's edge on
//     the triangle, i.e. 4^L >= (triangle area in level-0 texels) / (triangle area in voxels^2).
//  3. Sample point per (triangle, voxel): the voxel centre projected orthogonally onto the
//     triangle's plane, barycentrics clamped to the triangle; its UV (REPEAT wrap) picks the 2x2
//     texels of that level around it (as a bilinear footprint would).
//  4. The triangle covers the voxel (after the exact triangle/box overlap test) when any of those
//     4 bits is set. So a voxel is dropped only when the mask is transparent within about one
//     voxel of the sample point: transparent regions leave no voxels, thin opaque detail (chain
//     links, leaf tips) keeps its voxels.
// A material without a base-colour texture uses its factor alone (all texels alike).
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace voxlab {

struct CoverageLevel {
  uint32_t bitOffset = 0;  // first bit of the level in AlphaCoverage::bits
  uint32_t width = 1;
  uint32_t height = 1;
};

struct AlphaCoverage {
  std::vector<uint32_t> bits;          // all levels of all masked materials, row-major, 32 per word
  std::vector<CoverageLevel> levels;   // all materials' levels, each material's contiguous
  // Per scene material: first entry in 'levels' and the number of levels (0 = not masked).
  std::vector<uint32_t> firstLevel, levelCount;

  static AlphaCoverage build(const Scene& scene);
  bool masked(uint32_t material) const { return material < levelCount.size() && levelCount[material] > 0; }
  bool bit(const CoverageLevel& L, uint32_t x, uint32_t y) const {
    uint32_t i = L.bitOffset + y * L.width + x;
    return (bits[i >> 5] >> (i & 31u)) & 1u;
  }
};

// Step 2: the pyramid level for a triangle (a, b, c in voxel coordinates, uvs ua, ub, uc).
inline uint32_t coverageLevelFor(const AlphaCoverage& cov, uint32_t material, glm::vec3 a, glm::vec3 b, glm::vec3 c,
                                 glm::vec2 ua, glm::vec2 ub, glm::vec2 uc) {
  const uint32_t first = cov.firstLevel[material], count = cov.levelCount[material];
  const CoverageLevel& L0 = cov.levels[first];
  glm::vec2 du = ub - ua, dv = uc - ua;
  float uvArea = std::abs(du.x * dv.y - du.y * dv.x) * float(L0.width) * float(L0.height);
  float area = glm::length(glm::cross(b - a, c - a));  // both twice the area: the ratio is what counts
  float ratio = area > 0.0f ? uvArea / area : 0.0f;
  uint32_t level = 0;
  float scale = 1.0f;
  while (level + 1 < count && scale < ratio) {
    ++level;
    scale *= 4.0f;
  }
  return level;
}

// Steps 3 and 4 for voxel 'voxel' (integer coordinates) at pyramid level 'level'.
inline bool coverageAt(const AlphaCoverage& cov, uint32_t material, uint32_t level, glm::vec3 a, glm::vec3 b,
                       glm::vec3 c, glm::vec2 ua, glm::vec2 ub, glm::vec2 uc, glm::ivec3 voxel) {
  glm::vec3 e1 = b - a, e2 = c - a, q = glm::vec3(voxel) + 0.5f - a;
  float d00 = glm::dot(e1, e1), d01 = glm::dot(e1, e2), d11 = glm::dot(e2, e2);
  float d20 = glm::dot(q, e1), d21 = glm::dot(q, e2);
  float denom = d00 * d11 - d01 * d01;
  float wb = 0.0f, wc = 0.0f;
  if (denom > 0.0f) {
    wb = (d11 * d20 - d01 * d21) / denom;
    wc = (d00 * d21 - d01 * d20) / denom;
  }
  float wa = 1.0f - wb - wc;
  wa = std::max(wa, 0.0f);
  wb = std::max(wb, 0.0f);
  wc = std::max(wc, 0.0f);
  float sum = wa + wb + wc;
  glm::vec2 uv = sum > 0.0f ? (ua * wa + ub * wb + uc * wc) / sum : ua;
  const CoverageLevel& L = cov.levels[cov.firstLevel[material] + level];
  float x = uv.x * float(L.width) - 0.5f, y = uv.y * float(L.height) - 0.5f;
  float fx = std::floor(x), fy = std::floor(y);
  // REPEAT wrap of the 2x2 texels; the float -> int conversions are exact for |uv| < 2^23 / size.
  auto wrap = [](float i, uint32_t n) {
    float m = i - std::floor(i / float(n)) * float(n);
    return std::min(uint32_t(m), n - 1);
  };
  uint32_t x0 = wrap(fx, L.width), x1 = wrap(fx + 1.0f, L.width);
  uint32_t y0 = wrap(fy, L.height), y1 = wrap(fy + 1.0f, L.height);
  return cov.bit(L, x0, y0) || cov.bit(L, x1, y0) || cov.bit(L, x0, y1) || cov.bit(L, x1, y1);
}

}  // namespace voxlab
