// The ambient-occlusion harness shared by test_vct_grid.cpp and test_svo.cpp: the exact answer next
// to the wall of tests/data/scenes/wall-floor.gltf and the floor pixel nearest a point.
#pragma once
#include <cstddef>

#include <glm/glm.hpp>

#include "capture/capture.h"

namespace voxlab::testing_support {

// Cosine-weighted visible fraction at the floor point (px, 0, pz) (normal +y) in front of the wall
// rectangle x in [-1, 1], y in [0, 2] at z = 0.1, by midpoint quadrature over the hemisphere
// (400 x 800 cells in theta x phi).
double visibleFractionNextToWall(double px, double pz);

// The texel of a G-buffer position image (RGBA, w = 0 where no surface) whose point lies on the
// floor (|y| <= 1e-3) and is nearest 'target'; its distance in 'distance' (1e30 if none).
size_t floorTexelNearest(const LevelData& position, glm::vec3 target, float& distance);

}  // namespace voxlab::testing_support
