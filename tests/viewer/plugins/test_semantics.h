// Semantics that exist only in the test build of the viewer (voxlab_test_viewer): nothing outside
// tests/viewer/plugins knows them, which is what tests/viewer/plugins.txt shows.
#pragma once
#include "graph/output.h"

namespace voxlab::test_plugins {

// A volume whose texel at (x, y, z) holds its linear index x + n (y + n z), n = the edge.
inline constexpr Semantic kCellIndex{"test-cell-index"};
// One record per probed cell: the cell and the value read back from the volume there.
inline constexpr Semantic kProbedCell{"test-probed-cell"};

struct ProbedCellRecord {
  int32_t x, y, z;
  float value;
};

}  // namespace voxlab::test_plugins
