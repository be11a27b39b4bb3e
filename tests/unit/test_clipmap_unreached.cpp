// The search for a clip level's unreached cells (src/techniques/clipmap/unreached_cells.h), cell by
// cell on small hand-built levels whose answer is known.
#include <gtest/gtest.h>

#include <algorithm>

#include "techniques/clipmap/unreached_cells.h"

namespace voxlab::clipmap {
namespace {

size_t at(int n, int x, int y, int z) { return (size_t(z) * size_t(n) + size_t(y)) * size_t(n) + size_t(x); }

// A wall across the whole level at x = 3 (n = 7), the camera at x = 1: the camera's side is
// reached; behind the wall the first layer (x = 4) stays empty and x = 5, 6 are filled, each with
// the wall cell in its row and the step -x (the way from the wall into the camera's space).
TEST(ClipmapUnreached, AWallAcrossTheLevelFillsWhatLiesBehindIt) {
  const int n = 7;
  UnreachedInput in;
  in.n = n;
  in.occupied.assign(size_t(n * n * n), 0);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y) in.occupied[at(n, 3, y, z)] = 1;
  in.seed = glm::ivec3(1, 2, 5);
  const UnreachedCells out = findUnreachedCells(in);
  EXPECT_EQ(out.filled, int64_t(2 * n * n));
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const size_t i = at(n, x, y, z);
        EXPECT_EQ(out.reached[i], x < 3 ? 1 : 0) << x << " " << y << " " << z;
        EXPECT_EQ(out.open[i], x < 3 ? 0x3F : 0) << x << " " << y << " " << z;
        if (x >= 5) {
          EXPECT_EQ(out.source[i], int32_t(at(n, 3, y, z))) << x << " " << y << " " << z;
          EXPECT_EQ(out.sourceStep[i], 1) << "step -x";
        } else {
          EXPECT_EQ(out.source[i], -1) << x << " " << y << " " << z;
        }
      }
}

// A closed box (shell [2, 5]^3 of n = 9) with the camera inside: the interior is reached and
// nothing else; outside, the layer next to each face of the shell stays empty and every other
// empty cell is filled (the walk also passes through the shell's edges and corners, which border
// no reached cell). Of the 729 cells, 64 are the shell and its interior and 24 the layer one step
// out of the 24 face cells that border the interior.
TEST(ClipmapUnreached, AClosedBoxFillsEverythingOutsideButTheLayerOnItsWalls) {
  const int n = 9;
  UnreachedInput in;
  in.n = n;
  in.occupied.assign(size_t(n * n * n), 0);
  auto shell = [](int x, int y, int z) {
    const bool inside = x >= 2 && x <= 5 && y >= 2 && y <= 5 && z >= 2 && z <= 5;
    return inside && (x == 2 || x == 5 || y == 2 || y == 5 || z == 2 || z == 5);
  };
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) in.occupied[at(n, x, y, z)] = shell(x, y, z) ? 1 : 0;
  in.seed = glm::ivec3(3, 4, 3);
  const UnreachedCells out = findUnreachedCells(in);
  int64_t reached = 0, filled = 0, layer = 0;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const size_t i = at(n, x, y, z);
        const bool interior = x >= 3 && x <= 4 && y >= 3 && y <= 4 && z >= 3 && z <= 4;
        EXPECT_EQ(out.reached[i] != 0, interior) << x << " " << y << " " << z;
        reached += out.reached[i];
        // One step out of a face cell that borders the interior: (1 or 6, 3..4, 3..4) and the
        // same on the other axes.
        const auto faceLayer = [](int a, int b, int c) { return (a == 1 || a == 6) && b >= 3 && b <= 4 && c >= 3 && c <= 4; };
        const bool gap = faceLayer(x, y, z) || faceLayer(y, z, x) || faceLayer(z, x, y);
        layer += gap;
        const bool expectFilled = !in.occupied[i] && !interior && !gap;
        EXPECT_EQ(out.source[i] >= 0, expectFilled) << x << " " << y << " " << z;
        filled += out.source[i] >= 0;
      }
  EXPECT_EQ(reached, 8);
  EXPECT_EQ(layer, 24);
  EXPECT_EQ(out.filled, filled);
  EXPECT_EQ(filled, int64_t(n * n * n) - 64 - 24);
}

// The camera in a wall's cell starts from the nearest empty cell within two cells; with none, or
// with no camera and nothing inherited, the level is left alone.
TEST(ClipmapUnreached, TheSearchStartsNextToACameraInAWallOrNotAtAll) {
  const int n = 5;
  UnreachedInput in;
  in.n = n;
  in.occupied.assign(size_t(n * n * n), 0);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y) in.occupied[at(n, 2, y, z)] = 1;  // a wall at x = 2
  in.seed = glm::ivec3(2, 2, 2);
  const UnreachedCells moved = findUnreachedCells(in);
  // Nearest empty cell in index order at Chebyshev distance 1: (1, 1, 1), on the wall's -x side.
  EXPECT_EQ(moved.reached[at(n, 0, 0, 0)], 1);
  EXPECT_EQ(moved.reached[at(n, 4, 0, 0)], 0);
  EXPECT_EQ(moved.filled, int64_t(n * n)) << "x = 3 is the layer next to the wall, x = 4 is filled";
  EXPECT_EQ(moved.source[at(n, 3, 0, 0)], -1);
  EXPECT_EQ(moved.source[at(n, 4, 0, 0)], int32_t(at(n, 2, 0, 0)));

  std::fill(in.occupied.begin(), in.occupied.end(), uint8_t(1));
  const UnreachedCells buried = findUnreachedCells(in);
  EXPECT_EQ(buried.filled, 0);
  in.seed.reset();
  std::fill(in.occupied.begin(), in.occupied.end(), uint8_t(0));
  const UnreachedCells none = findUnreachedCells(in);
  EXPECT_EQ(none.filled, 0);
  EXPECT_EQ(std::count(none.reached.begin(), none.reached.end(), uint8_t(1)), 0);
}

// A coarser level inherits: an occupied cell whose finer cells reach out only through its +x face
// passes the camera's space to its +x neighbour, not to its -x one (a corridor inside one coarse
// cell does not open the space around it; the sky at the edge of the finer level does).
TEST(ClipmapUnreached, AnInheritedCellOpensOnlyThroughItsOpenFaces) {
  const int n = 7;
  UnreachedInput in;
  in.n = n;
  in.occupied.assign(size_t(n * n * n), 0);
  in.inherited.assign(size_t(n * n * n), 0);
  in.openFaces.assign(size_t(n * n * n), 0);
  // One occupied cell (3, 3, 3) with the camera's space inside it, open towards +x only, in an
  // otherwise empty level.
  in.occupied[at(n, 3, 3, 3)] = 1;
  in.inherited[at(n, 3, 3, 3)] = 1;
  in.openFaces[at(n, 3, 3, 3)] = 1u << 0;  // +x
  const UnreachedCells out = findUnreachedCells(in);
  // Through +x the whole empty level is reached (it is connected), so nothing is filled.
  EXPECT_EQ(out.reached[at(n, 4, 3, 3)], 1);
  EXPECT_EQ(out.reached[at(n, 2, 3, 3)], 1) << "reached round the cell";
  EXPECT_EQ(out.filled, 0);

  // Closed in by a shell of walls round (3, 3, 3) except its +x side opening into a pocket
  // (4, 3, 3): with the face closed the pocket and everything outside the shell is unreached.
  UnreachedInput closed = in;
  for (int z = 1; z <= 5; ++z)
    for (int y = 1; y <= 5; ++y)
      for (int x = 1; x <= 5; ++x)
        if (x == 1 || x == 5 || y == 1 || y == 5 || z == 1 || z == 5) closed.occupied[at(n, x, y, z)] = 1;
  const UnreachedCells open = findUnreachedCells(closed);
  EXPECT_EQ(open.reached[at(n, 4, 3, 3)], 1);
  EXPECT_EQ(open.reached[at(n, 2, 3, 3)], 1) << "the pocket inside the shell is one space";
  EXPECT_EQ(open.reached[at(n, 0, 0, 0)], 0);
  closed.openFaces[at(n, 3, 3, 3)] = 0;
  const UnreachedCells shut = findUnreachedCells(closed);
  EXPECT_EQ(shut.reached[at(n, 4, 3, 3)], 0);
  EXPECT_EQ(shut.open[at(n, 3, 3, 3)], 0);
  EXPECT_EQ(shut.reached[at(n, 3, 3, 3)], 1) << "an inherited cell stays reached";
}

}  // namespace
}  // namespace voxlab::clipmap
