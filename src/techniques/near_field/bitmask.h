// CPU side of the near-field bitmask maths (seed 000 section 4.4.1, GP3 Bitmask.cpp): the OR and
// XOR tables, ray masks, the 2D OR mip hierarchy and a brute-force 3D DDA over the binary grid.
// The GPU stages compute the same things; tests/unit/test_near_field.cpp compares them exactly.
// Bit order: src/techniques/common/binary_voxels_stage.h.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "techniques/common/binary_voxels_stage.h"

namespace voxlab::nearfield {

// OR[k]: only slice k set.
BitColumn orMask(int k);
// XOR[k]: slices k..127 set; XOR[128] = 0 (the 129th entry the public code lacks: it fetches
// texel 128 of a 128-texel table for ray masks that end at slice 127).
BitColumn xorMask(int k);
std::vector<BitColumn> orTable();   // 128 entries
std::vector<BitColumn> xorTable();  // 129 entries, the last all zero
// Slices first..last set (first <= last): XOR[first] ^ XOR[last + 1].
BitColumn rayMask(int first, int last);
// First set slice of a mask along the ray: the smallest when the ray goes toward +z, else the
// largest; -1 when empty (what findMSB / findLSB give on the GPU).
int firstSliceAlong(const BitColumn& mask, bool towardMinusZ);

// Levels 0..log2(res) of the 2D OR hierarchy: level l + 1 texel (x, y) is the OR of level-l
// texels (2x + {0,1}, 2y + {0,1}); all 128 slices are kept at every level.
std::vector<std::vector<BitColumn>> orMipChain(const std::vector<BitColumn>& level0, int res);

// The first set voxel along the unit-space segment o -> e (t in [0,1]) by Amanatides-Woo over
// the res x res x 128 cells. 'tie' reports whether the walk stepped where two axes' crossings lie
// within 1e-5 in t (corner or edge ties, where the visiting order is a matter of rounding).
struct DdaResult {
  bool hit = false;
  glm::ivec3 voxel{-1};  // x, y, slice
  bool tie = false;
  int cells = 0;  // cells visited
};
// visited (optional): every cell the walk visits, in order, with the t it enters it at (the last
// is the hit when there is one).
struct DdaCell {
  glm::ivec3 cell;
  float tEnter;
};
DdaResult bruteForceDda(const std::vector<BitColumn>& level0, int res, glm::vec3 o, glm::vec3 e,
                        std::vector<DdaCell>* visited = nullptr);

}  // namespace voxlab::nearfield
