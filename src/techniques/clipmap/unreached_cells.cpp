// Breadth-first walks over one level's cells (unreached_cells.h).
#include "techniques/clipmap/unreached_cells.h"

#include <algorithm>
#include <array>
#include <cstdlib>

namespace voxlab::clipmap {

UnreachedCells findUnreachedCells(const UnreachedInput& input) {
  const int n = input.n;
  const size_t count = size_t(n) * size_t(n) * size_t(n);
  UnreachedCells out;
  out.reached.assign(count, 0);
  out.source.assign(count, -1);
  out.sourceStep.assign(count, -1);
  out.open.assign(count, 0);
  auto index = [n](glm::ivec3 c) { return logicalCellIndex(c, n); };
  auto cellOf = [n](size_t i) { return logicalCell(i, n); };
  auto inside = [n](glm::ivec3 c) { return c.x >= 0 && c.y >= 0 && c.z >= 0 && c.x < n && c.y < n && c.z < n; };
  const std::array<glm::ivec3, 6> steps = {glm::ivec3(1, 0, 0), glm::ivec3(-1, 0, 0), glm::ivec3(0, 1, 0),
                                           glm::ivec3(0, -1, 0), glm::ivec3(0, 0, 1), glm::ivec3(0, 0, -1)};

  std::vector<size_t> queue;
  bool anyReached = false;
  if (!input.inherited.empty())
    for (size_t i = 0; i < count; ++i)
      if (input.inherited[i]) {
        out.reached[i] = 1;
        anyReached = true;
        queue.push_back(i);
      }
  if (input.seed && inside(*input.seed)) {
    // The camera may sit in a surface's cell (close to a wall): start from the nearest empty cell
    // within two cells, nearest by Chebyshev distance, then in index order.
    std::optional<size_t> start;
    for (int r = 0; r <= 2 && !start; ++r)
      for (int z = -r; z <= r && !start; ++z)
        for (int y = -r; y <= r && !start; ++y)
          for (int x = -r; x <= r && !start; ++x) {
            if (std::max(std::abs(x), std::max(std::abs(y), std::abs(z))) != r) continue;
            const glm::ivec3 c = *input.seed + glm::ivec3(x, y, z);
            if (inside(c) && !input.occupied[index(c)]) start = index(c);
          }
    if (start && !out.reached[*start]) {
      out.reached[*start] = 1;
      queue.push_back(*start);
    }
    anyReached = anyReached || start.has_value();
  }
  if (!anyReached) return out;  // nothing of the camera's space in this level: left as voxelized

  for (size_t q = 0; q < queue.size(); ++q) {
    const size_t i = queue[q];
    const glm::ivec3 c = cellOf(i);
    const unsigned open = input.occupied[i] ? (input.openFaces.empty() ? 0u : unsigned(input.openFaces[i])) : 0x3Fu;
    for (size_t k = 0; k < steps.size(); ++k) {
      if (!(open & (1u << k))) continue;
      const glm::ivec3 d = c + steps[k];
      if (!inside(d)) continue;
      const size_t j = index(d);
      if (input.occupied[j] || out.reached[j]) continue;
      out.reached[j] = 1;
      queue.push_back(j);
    }
  }

  for (size_t i = 0; i < count; ++i)
    if (out.reached[i]) out.open[i] = input.occupied[i] ? (input.openFaces.empty() ? 0 : input.openFaces[i]) : 0x3F;

  // The unreached cells, walked from every surface cell that borders the camera's space (a
  // reached empty neighbour) at once, through unreached cells, empty or not (a slab's far face, the
  // space beyond it): each unreached empty cell takes the surface cell its walk started from and
  // the step from that cell to its reached neighbour, so it shows the light of the wall as the
  // camera's space sees it, not that of the wall's outside.
  std::vector<int32_t> from(count, -1);
  std::vector<int8_t> step(count, -1);
  std::vector<uint8_t> depth(count, 0);
  std::vector<size_t> front;
  for (size_t i = 0; i < count; ++i) {
    if (!input.occupied[i]) continue;
    if (out.reached[i]) {  // an inherited cell: the camera's space runs inside it
      from[i] = int32_t(i);
      front.push_back(i);
      continue;
    }
    const glm::ivec3 c = cellOf(i);
    for (size_t k = 0; k < steps.size(); ++k) {
      const glm::ivec3 d = c + steps[k];
      if (!inside(d) || input.occupied[index(d)] || !out.reached[index(d)]) continue;
      from[i] = int32_t(i);
      step[i] = int8_t(k);
      front.push_back(i);
      break;
    }
  }
  for (size_t q = 0; q < front.size(); ++q) {
    const glm::ivec3 c = cellOf(front[q]);
    for (const glm::ivec3& s : steps) {
      const glm::ivec3 d = c + s;
      if (!inside(d)) continue;
      const size_t j = index(d);
      if (out.reached[j] || from[j] >= 0) continue;
      from[j] = from[front[q]];
      step[j] = step[front[q]];
      depth[j] = uint8_t(std::min(int(depth[front[q]]) + 1, 255));
      if (!input.occupied[j] && depth[j] > kUnfilledLayers) {
        out.source[j] = from[j];
        out.sourceStep[j] = step[j];
        ++out.filled;
      }
      front.push_back(j);
    }
  }
  return out;
}

}  // namespace voxlab::clipmap
