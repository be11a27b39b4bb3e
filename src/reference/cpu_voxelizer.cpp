#include "reference/cpu_voxelizer.h"

#include <algorithm>
#include <cmath>
#include <thread>
#include <vector>

#include "scene/alpha_coverage.h"
#include "scene/voxel_space.h"

namespace voxlab {

// Voxels are half-open cells [i, i+1) x [j, j+1) x [k, k+1) (docs/voxelization.md, "Ties on voxel
// faces"). Seen along an axis a, the half-open box's projection [-r, r] (relative to its centre)
// lacks its upper end when a has a positive component (that end is reached only at the cell's
// upper faces) and its lower end when a has a negative one. A triangle that only touches a missing
// end is separated. This is the limit of the closed test against [i, i+1-eps] as eps -> 0, so
// the 13 axes still decide exactly.
static bool separatedOn(const glm::dvec3& axis, const glm::dvec3& v0, const glm::dvec3& v1,
                        const glm::dvec3& v2, const glm::dvec3& h) {
  double p0 = glm::dot(v0, axis), p1 = glm::dot(v1, axis), p2 = glm::dot(v2, axis);
  double r = glm::dot(h, glm::abs(axis));
  double lo = std::min({p0, p1, p2}), hi = std::max({p0, p1, p2});
  bool upperOpen = axis.x > 0.0 || axis.y > 0.0 || axis.z > 0.0;
  bool lowerOpen = axis.x < 0.0 || axis.y < 0.0 || axis.z < 0.0;
  return (upperOpen ? lo >= r : lo > r) || (lowerOpen ? hi <= -r : hi < -r);
}

bool triangleOverlapsBox(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                         const glm::dvec3& center, const glm::dvec3& h) {
  glm::dvec3 v0 = a - center, v1 = b - center, v2 = c - center;
  // 1. Box face normals = the triangle's bounding box against the box.
  for (int i = 0; i < 3; ++i) {
    glm::dvec3 unit(0.0);
    unit[i] = 1.0;
    if (separatedOn(unit, v0, v1, v2, h)) return false;
  }
  glm::dvec3 e[3] = {v1 - v0, v2 - v1, v0 - v2};
  // 2. Triangle plane.
  if (separatedOn(glm::cross(e[0], e[1]), v0, v1, v2, h)) return false;
  // 3. Cross products of the box axes with the edges.
  for (int i = 0; i < 3; ++i) {
    glm::dvec3 unit(0.0);
    unit[i] = 1.0;
    for (const auto& edge : e) {
      glm::dvec3 axis = glm::cross(unit, edge);
      if (glm::dot(axis, axis) > 1e-30 && separatedOn(axis, v0, v1, v2, h)) return false;
    }
  }
  return true;
}

// triangleOverlapsBox for a box whose column along axis w lies wholly inside the triangle's
// projection along w (every face of the column's square at least kInsideMargin inside each edge):
// there the triangle fills the column, so it meets the box exactly where its plane does, and of
// the 13 axes only the plane's and w's can separate (the box axes u and v and the nine edge axes
// project to the edge tests, which the column passes by the margin). Both are computed with the
// expressions of triangleOverlapsBox, so a tie on a face resolves the same way.
static bool triangleOverlapsBoxInFilledColumn(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                                              const glm::dvec3& center, const glm::dvec3& h, int w) {
  glm::dvec3 v0 = a - center, v1 = b - center, v2 = c - center;
  glm::dvec3 unit(0.0);
  unit[w] = 1.0;
  if (separatedOn(unit, v0, v1, v2, h)) return false;
  return !separatedOn(glm::cross(v1 - v0, v2 - v1), v0, v1, v2, h);
}

// How far inside every edge of the triangle's projection a column's square must lie for
// triangleOverlapsBoxInFilledColumn: voxel coordinates reach 1024, where doubles resolve about
// 1e-13, so 1e-6 voxels leaves the squares near an edge to the full test whatever the rounding.
constexpr double kInsideMargin = 1e-6;

// Calls visit(key) for every (triangle, voxel) pair of triangles first, first + stride, ...
template <typename Visit>
static void forEachReferencePair(const Scene& scene, const VoxelSpace& space, const AlphaCoverage& coverage,
                                 size_t first, size_t stride, Visit visit) {
  const int res = space.resolution;
  const glm::dvec3 half(0.5);
  for (size_t t = first; t < scene.triangleCount(); t += stride) {
    glm::vec3 f[3];
    glm::vec2 uv[3];
    for (int k = 0; k < 3; ++k) {
      uint32_t i = scene.indices[3 * t + k];
      f[k] = space.toVoxel(scene.positions[i]);
      uv[k] = i < scene.uvs.size() ? scene.uvs[i] : glm::vec2(0.0f);
    }
    glm::dvec3 v[3] = {glm::dvec3(f[0]), glm::dvec3(f[1]), glm::dvec3(f[2])};
    if (glm::length(glm::cross(v[1] - v[0], v[2] - v[0])) <= 0.0) continue;
    // alphaMode MASK: the same coverage rule as the GPU voxelizers (scene/alpha_coverage.h), in float.
    const uint32_t material = scene.triangleMaterial(t);
    const bool masked = coverage.masked(material);
    const uint32_t level = masked ? coverageLevelFor(coverage, material, f[0], f[1], f[2], uv[0], uv[1], uv[2]) : 0;
    glm::dvec3 lo = glm::min(v[0], glm::min(v[1], v[2])), hi = glm::max(v[0], glm::max(v[1], v[2]));
    glm::ivec3 a = glm::clamp(glm::ivec3(glm::floor(lo)), glm::ivec3(0), glm::ivec3(res - 1));
    glm::ivec3 b = glm::clamp(glm::ivec3(glm::floor(hi)), glm::ivec3(0), glm::ivec3(res - 1));
    // Candidates: along the normal's dominant axis w, each column of the bounding box holds only
    // the cells whose centre c satisfies |n.c - n.v0| <= r (the triangle's plane meets the closed
    // cell), widened by one cell against rounding; the SAT test decides every candidate.
    const glm::dvec3 n = glm::cross(v[1] - v[0], v[2] - v[0]);
    const glm::dvec3 an = glm::abs(n);
    const int w = an.x >= an.y && an.x >= an.z ? 0 : (an.y >= an.z ? 1 : 2);
    const int axisU = (w + 1) % 3, axisV = (w + 2) % 3;
    const double r = 0.5 * (an.x + an.y + an.z), planeD = glm::dot(n, v[0]);
    // The projection along w: a column's square is inside an edge k when the edge function,
    // oriented so that the triangle is on its positive side, is positive at all four corners: at
    // the centre less half the sum of the edge's two components.
    const glm::dvec2 p[3] = {{v[0][axisU], v[0][axisV]}, {v[1][axisU], v[1][axisV]}, {v[2][axisU], v[2][axisV]}};
    const double orientation = n[w] > 0.0 ? 1.0 : -1.0;
    for (int cu = a[axisU]; cu <= b[axisU]; ++cu)
      for (int cv = a[axisV]; cv <= b[axisV]; ++cv) {
        const double rest = planeD - n[axisU] * (cu + 0.5) - n[axisV] * (cv + 0.5);
        const double c0 = (rest - r) / n[w], c1 = (rest + r) / n[w];
        const int w0 = std::max(a[w], int(std::floor(std::min(c0, c1) - 0.5)) - 1);
        const int w1 = std::min(b[w], int(std::ceil(std::max(c0, c1) - 0.5)) + 1);
        const glm::dvec2 centre(cu + 0.5, cv + 0.5);
        bool filled = true;
        for (int k = 0; k < 3; ++k) {
          const glm::dvec2 e = p[(k + 1) % 3] - p[k], q = centre - p[k];
          const double inside = orientation * (e.x * q.y - e.y * q.x) - 0.5 * (std::abs(e.x) + std::abs(e.y));
          filled = filled && inside > kInsideMargin;
        }
        for (int cw = w0; cw <= w1; ++cw) {
          glm::ivec3 cell;
          cell[w] = cw;
          cell[axisU] = cu;
          cell[axisV] = cv;
          const glm::dvec3 boxCentre = glm::dvec3(cell) + half;
          if (filled ? !triangleOverlapsBoxInFilledColumn(v[0], v[1], v[2], boxCentre, half, w)
                     : !triangleOverlapsBox(v[0], v[1], v[2], boxCentre, half))
            continue;
          if (masked && !coverageAt(coverage, material, level, f[0], f[1], f[2], uv[0], uv[1], uv[2], cell))
            continue;
          visit(packVoxelKey(cell.x, cell.y, cell.z));
        }
      }
  }
}

// Runs job(first, stride) for every worker: the triangles interleaved over two threads (the
// machine's cores; the triangles of a scene differ in size, so interleaving balances them). The
// result does not depend on the split: the pairs are summed or their keys sorted.
constexpr size_t kWorkers = 2;
template <typename Job>
static void onWorkers(Job job) {
  std::vector<std::thread> threads;
  for (size_t w = 1; w < kWorkers; ++w) threads.emplace_back(job, w, kWorkers);
  job(0, kWorkers);
  for (std::thread& t : threads) t.join();
}

std::vector<uint32_t> referenceVoxelSet(const Scene& scene, const VoxelSpace& space) {
  const AlphaCoverage coverage = AlphaCoverage::build(scene);
  std::vector<uint32_t> perWorker[kWorkers];
  onWorkers([&](size_t first, size_t stride) {
    forEachReferencePair(scene, space, coverage, first, stride, [&](uint32_t key) { perWorker[first].push_back(key); });
  });
  std::vector<uint32_t> keys;
  for (const std::vector<uint32_t>& part : perWorker) keys.insert(keys.end(), part.begin(), part.end());
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return keys;
}

size_t referencePairCount(const Scene& scene, const VoxelSpace& space) {
  const AlphaCoverage coverage = AlphaCoverage::build(scene);
  size_t pairs[kWorkers] = {};
  onWorkers([&](size_t first, size_t stride) {
    forEachReferencePair(scene, space, coverage, first, stride, [&](uint32_t) { ++pairs[first]; });
  });
  size_t sum = 0;
  for (size_t p : pairs) sum += p;
  return sum;
}

}  // namespace voxlab
