// The facing codes of shaders/common/facing.glsl on the CPU: per voxel, for each of the six travel
// directions of a cone (d = 2 * axis + (0: +, 1: -)), the largest front weight max(0, -n.e) of
// its surfaces, in 5 steps of 0.2 as a thermometer code of 5 bits (30 bits of an R32UI texel).
// A cone travelling along +x sees the fronts of surfaces facing -x: so the side of a voxel that
// faces +a is the one cones travelling along -a (d = 2a + 1) see.
#pragma once
#include <cstdint>

#include "graph/output.h"

namespace voxlab {

// Volumes of facing codes (vct-grid's inject output voxel-facing).
inline constexpr Semantic kVoxelFacingSemantic{"voxel-facing"};
inline constexpr int kFacingSteps = 5;

// The front weight, in [0, 1], a cone travelling along direction d sees of a voxel with 'code'.
inline float facingFront(uint32_t code, int d) {
  uint32_t field = (code >> (kFacingSteps * d)) & ((1u << kFacingSteps) - 1u);
  int steps = 0;
  for (; field; field &= field - 1u) ++steps;
  return float(steps) / float(kFacingSteps);
}

// The weight of the voxel's side that faces axis a's sign s (+1, -1): what cones arriving from
// that side see.
inline float facingSide(uint32_t code, int a, int s) { return facingFront(code, 2 * a + (s > 0 ? 1 : 0)); }

}  // namespace voxlab
