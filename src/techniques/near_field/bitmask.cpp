#include "techniques/near_field/bitmask.h"

#include <algorithm>
#include <cmath>

namespace voxlab::nearfield {

BitColumn orMask(int k) {
  BitColumn c{0, 0, 0, 0};
  setSlice(c, k);
  return c;
}

BitColumn xorMask(int k) {
  BitColumn c{0, 0, 0, 0};
  if (k >= kBinarySlices) return c;
  const int ch = sliceChannel(k);
  c[ch] = 0xFFFFFFFFu >> (k & 31);
  for (int i = ch + 1; i < 4; ++i) c[i] = 0xFFFFFFFFu;
  return c;
}

std::vector<BitColumn> orTable() {
  std::vector<BitColumn> t;
  for (int k = 0; k < kBinarySlices; ++k) t.push_back(orMask(k));
  return t;
}

std::vector<BitColumn> xorTable() {
  std::vector<BitColumn> t;
  for (int k = 0; k <= kBinarySlices; ++k) t.push_back(xorMask(k));
  return t;
}

BitColumn rayMask(int first, int last) {
  BitColumn a = xorMask(first), b = xorMask(last + 1), r;
  for (int i = 0; i < 4; ++i) r[i] = a[i] ^ b[i];
  return r;
}

int firstSliceAlong(const BitColumn& mask, bool towardMinusZ) {
  if (!towardMinusZ) {
    for (int k = 0; k < kBinarySlices; ++k)
      if (hasSlice(mask, k)) return k;
  } else {
    for (int k = kBinarySlices - 1; k >= 0; --k)
      if (hasSlice(mask, k)) return k;
  }
  return -1;
}

std::vector<std::vector<BitColumn>> orMipChain(const std::vector<BitColumn>& level0, int res) {
  std::vector<std::vector<BitColumn>> levels{level0};
  for (int r = res / 2; r >= 1; r /= 2) {
    const auto& fine = levels.back();
    const int fr = r * 2;
    std::vector<BitColumn> coarse(size_t(r) * r, BitColumn{0, 0, 0, 0});
    for (int y = 0; y < r; ++y)
      for (int x = 0; x < r; ++x)
        for (int j = 0; j < 4; ++j)
          for (int c = 0; c < 4; ++c) coarse[size_t(y) * r + x][c] |= fine[size_t(2 * y + (j >> 1)) * fr + 2 * x + (j & 1)][c];
    levels.push_back(std::move(coarse));
  }
  return levels;
}

DdaResult bruteForceDda(const std::vector<BitColumn>& level0, int res, glm::vec3 o, glm::vec3 e,
                        std::vector<DdaCell>* visited) {
  DdaResult r;
  const glm::vec3 dims{float(res), float(res), float(kBinarySlices)};
  const glm::vec3 d = e - o;
  glm::ivec3 cell = glm::clamp(glm::ivec3(glm::floor(o * dims)), glm::ivec3(0), glm::ivec3(dims) - 1);
  glm::ivec3 step;
  glm::vec3 tMax, tDelta;
  for (int a = 0; a < 3; ++a) {
    if (d[a] > 0) {
      step[a] = 1;
      tMax[a] = (float(cell[a] + 1) / dims[a] - o[a]) / d[a];
      tDelta[a] = 1.0f / (dims[a] * d[a]);
    } else if (d[a] < 0) {
      step[a] = -1;
      tMax[a] = (float(cell[a]) / dims[a] - o[a]) / d[a];
      tDelta[a] = -1.0f / (dims[a] * d[a]);
    } else {
      step[a] = 0;
      tMax[a] = INFINITY;
      tDelta[a] = INFINITY;
    }
  }
  float t = 0.0f;
  while (t <= 1.0f) {
    if (glm::any(glm::lessThan(cell, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(cell, glm::ivec3(dims)))) break;
    ++r.cells;
    if (visited) visited->push_back({cell, t});
    if (hasSlice(level0[size_t(cell.y) * res + cell.x], cell.z)) {
      r.hit = true;
      r.voxel = cell;
      return r;
    }
    int a = tMax.x < tMax.y ? (tMax.x < tMax.z ? 0 : 2) : (tMax.y < tMax.z ? 1 : 2);
    for (int b = 0; b < 3; ++b)
      if (b != a && std::abs(tMax[b] - tMax[a]) < 1e-5f && tMax[a] <= 1.0f) r.tie = true;
    t = tMax[a];
    cell[a] += step[a];
    tMax[a] += tDelta[a];
  }
  return r;
}

}  // namespace voxlab::nearfield
