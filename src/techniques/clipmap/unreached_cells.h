// Cells of a clip level that no path of empty cells from the camera reaches: the space behind the
// walls of a closed room and inside closed objects. A cone whose footprint reaches past a wall
// that it runs along sees that space, and empty it lets the cone go on as if the wall were not
// there (a corridor's cones run its whole length seeing nothing of its walls). Filled, opaque,
// with the light of the nearest surface, it stops them as the wall would stop their rays.
// Pure CPU code on one level's occupancy (the update stage reads the level back and writes the
// filled texels); the unit tests check it cell by cell.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

namespace voxlab::clipmap {

// A level of N^3 cells in logical order: index (z * N + y) * N + x, and back.
inline size_t logicalCellIndex(glm::ivec3 c, int n) {
  return (size_t(c.z) * size_t(n) + size_t(c.y)) * size_t(n) + size_t(c.x);
}
inline glm::ivec3 logicalCell(size_t i, int n) {
  return glm::ivec3(int(i % size_t(n)), int((i / size_t(n)) % size_t(n)), int(i / (size_t(n) * size_t(n))));
}

struct UnreachedInput {
  int n = 0;
  std::vector<uint8_t> occupied;  // 1: a surface's cell (what the voxelizer or the filter wrote)
  // 1: reached through the finer level (a covered cell with a reached child); empty for level 0.
  std::vector<uint8_t> inherited;
  // Per inherited cell that is occupied, bit s (the steps +x -x +y -y +z -z) set where reached
  // cells of the finer level touch its face that way: reachability leaves an occupied cell only
  // through such a face (the open space of the finer level goes on past its border there, as the
  // sky above a courtyard does), never through the rest of it (a corridor inside the cell).
  std::vector<uint8_t> openFaces;
  std::optional<glm::ivec3> seed;  // the camera's cell (level 0), logical
};

struct UnreachedCells {
  std::vector<uint8_t> reached;  // 1: an empty cell a path of empty cells reaches, or an inherited one
  // Per cell, the faces (bits as openFaces) through which the camera's space leaves it: all six
  // for a reached empty cell, an inherited occupied cell's open faces, none elsewhere. The next
  // coarser level's openFaces are made of them.
  std::vector<uint8_t> open;
  // Per cell, the logical index of the surface cell whose light a filled cell takes: the nearest
  // surface cell that borders a reached empty cell or is itself inherited (the camera's space runs
  // inside it), by a breadth-first walk over the unreached cells (6-connected, ties to the first
  // found in index order); -1 where the cell is not filled.
  std::vector<int32_t> source;
  // Per filled cell, the step (+x -x +y -y +z -z) from its surface cell to that reached neighbour:
  // the way out of the wall into the camera's space; -1 elsewhere.
  std::vector<int8_t> sourceStep;
  int64_t filled = 0;
};

// The cells next to a wall's cell on its far side stay empty: a sample of a cone leaving the wall
// reads one cell either side of its position (trilinear filtering), at the wall's level and at
// the coarser ones the filter makes of it, and a filled cell there would show the cone its own
// wall's light below its horizon (measured: the skylight room's floor, whose indirect light is
// all but nil, lit 4 to 20 times the reference by its own sun patch).
constexpr int kUnfilledLayers = 1;

// Reached: the seed (an empty cell; an occupied seed is moved to the nearest empty cell within
// two cells, and with none the level is left alone: nothing is filled) and every inherited cell,
// then every empty cell 6-connected to them through empty cells (leaving an occupied inherited
// cell only through its open faces). Filled: every empty cell not reached that a walk from the
// surface cells bordering the reached space reaches through unreached cells, more than
// kUnfilledLayers steps from them. With no seed and nothing inherited nothing is reached, and
// nothing is filled either (a level the camera's space does not touch is left as voxelized).
UnreachedCells findUnreachedCells(const UnreachedInput& input);

}  // namespace voxlab::clipmap
