// The clip-atlas view's mapping (views/clip_atlas.cpp), apart so that tests can check it
// against the C++ toroidal address and the GPU's unrolled levels (tests/unit/test_clipmap_views.cpp).
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "capture/capture.h"
#include "techniques/clipmap/stages.h"

namespace voxlab::clipmap {

// One z slice of one face of one level, N x N texels: the physical texture as stored (texel
// (x, y, z) of the level's block), or unrolled into logical order (texel (x, y) of slice z shows
// cell o_k + (x, y, z), read at its toroidal address: the region as it lies in the world).
struct AtlasSlice {
  int level = 0, face = 0, z = 0;
  bool unrolled = false;
};

// The physical texel (x, y, z in [0, N)) shown at slice texel (x, y).
glm::ivec3 atlasSliceTexel(const LevelRecord& level, const AtlasSlice& s, int x, int y);
// The world cell held by that texel: o + ((texel - o) mod N) (physical), o + (x, y, z) (unrolled).
Cell atlasSliceCell(const LevelRecord& level, const AtlasSlice& s, int x, int y);
// The slice's RGBA values (N x N x 1, x fastest, y up) from the captured atlas (guards skipped).
LevelData atlasSliceValues(const LevelData& atlas, const LevelRecord& level, const AtlasSlice& s);
// The level records of a captured clip-levels output.
std::vector<LevelRecord> levelRecords(const CapturedOutput& out);

}  // namespace voxlab::clipmap
