#include "techniques/clipmap/clipmap_math.h"

#include <algorithm>
#include <cmath>

namespace voxlab::clipmap {

int64_t floorDiv(int64_t a, int64_t b) {
  int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}
int64_t modPos(int64_t a, int64_t b) {
  int64_t r = a % b;
  return r < 0 ? r + b : r;
}
Cell floorDiv(const Cell& a, int64_t b) { return {floorDiv(a.x, b), floorDiv(a.y, b), floorDiv(a.z, b)}; }

Box intersect(const Box& a, const Box& b) {
  Box r{glm::max(a.lo, b.lo), glm::min(a.hi, b.hi)};
  if (r.empty()) return Box{};
  return r;
}

std::vector<Box> subtract(const Box& a, const Box& b) {
  std::vector<Box> out;
  if (a.empty()) return out;
  Box overlap = intersect(a, b);
  if (overlap.empty()) return {a};
  Box rest = a;
  for (int axis = 0; axis < 3; ++axis) {
    if (rest.lo[axis] < overlap.lo[axis]) {
      Box s = rest;
      s.hi[axis] = overlap.lo[axis];
      out.push_back(s);
    }
    if (overlap.hi[axis] < rest.hi[axis]) {
      Box s = rest;
      s.lo[axis] = overlap.hi[axis];
      out.push_back(s);
    }
    rest.lo[axis] = overlap.lo[axis];
    rest.hi[axis] = overlap.hi[axis];
  }
  return out;
}

glm::ivec3 toroidal(const Cell& c, int n) {
  const int64_t mask = n - 1;
  return {int(c.x & mask), int(c.y & mask), int(c.z & mask)};
}

Cell cellAtTexel(const glm::ivec3& texel, const Cell& origin, int n) {
  Cell r;
  for (int i = 0; i < 3; ++i) r[i] = origin[i] + modPos(int64_t(texel[i]) - origin[i], n);
  return r;
}

std::vector<Cell> snapOrigins(const Layout& layout, const glm::dvec3& anchor) {
  return snapOrigins(layout, anchor, glm::dvec3(0.0));
}

std::vector<Cell> snapOrigins(const Layout& layout, const glm::dvec3& anchor, const glm::dvec3& lead) {
  std::vector<Cell> origins(size_t(layout.levels));
  for (int k = 0; k < layout.levels; ++k) {
    const double next = layout.voxelSize(k + 1);
    const glm::dvec3 centre = anchor + lead * (double(layout.n) * layout.voxelSize(k));
    for (int i = 0; i < 3; ++i) origins[size_t(k)][i] = 2 * int64_t(std::floor(centre[i] / next)) - layout.n / 2;
  }
  return origins;
}

Box region(const Cell& origin, int n) { return {origin, origin + Cell(n)}; }

Box coveredBlock(const std::vector<Cell>& origins, int k, int n) {
  if (k == 0) return Box{};
  const Cell& finer = origins[size_t(k - 1)];
  Box projected{floorDiv(finer, 2), floorDiv(finer + Cell(n), 2)};
  return intersect(projected, region(origins[size_t(k)], n));
}

bool levelScheduled(Policy policy, int level, int levels, int64_t move) {
  if (policy == Policy::All || levels == 1) return true;
  const int64_t period = int64_t(1) << std::min(level + 1, levels - 1);
  const int64_t phase = (int64_t(1) << std::min(level, levels - 1)) - 1;
  return modPos(move - phase, period) == 0;
}

std::vector<LevelPlan> planMove(const Layout& layout, const std::vector<Cell>& before, const std::vector<Cell>& after) {
  const int n = layout.n;
  const bool full = before.empty();
  std::vector<LevelPlan> plans(size_t(layout.levels));
  for (int k = 0; k < layout.levels; ++k) {
    LevelPlan& p = plans[size_t(k)];
    p.origin = after[size_t(k)];
    p.full = full;
    const Box next = region(after[size_t(k)], n);
    p.covered = coveredBlock(after, k, n);
    p.refilteredCells = p.covered.volume();
    if (full) {
      p.exposed = {next};
      p.direct = subtract(next, p.covered);
    } else {
      p.delta = after[size_t(k)] - before[size_t(k)];
      const Box previous = region(before[size_t(k)], n);
      const Box wasCovered = coveredBlock(before, k, n);
      p.exposed = subtract(next, previous);
      for (const Box& x : p.exposed)
        for (const Box& d : subtract(x, p.covered)) p.direct.push_back(d);
      // Cells that held filtered values and are now uncovered: they need their own voxels.
      for (const Box& d : subtract(intersect(wasCovered, next), p.covered)) p.direct.push_back(d);
      for (const Box& d : subtract(intersect(wasCovered, next), p.covered)) p.coverageChanged += d.volume();
      for (const Box& d : subtract(intersect(p.covered, previous), wasCovered)) p.coverageChanged += d.volume();
    }
    for (const Box& x : p.exposed) p.exposedCells += x.volume();
    for (const Box& d : p.direct) p.directCells += d.volume();
  }
  return plans;
}

std::string describe(const Cell& c) {
  return "(" + std::to_string(c.x) + ", " + std::to_string(c.y) + ", " + std::to_string(c.z) + ")";
}

}  // namespace voxlab::clipmap
