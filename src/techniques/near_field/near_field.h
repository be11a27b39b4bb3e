// Geometry of near-field's binary voxel grid, shared by its stages and tests.
#pragma once
#include <glm/glm.hpp>

#include "scene/scene.h"

namespace voxlab::nearfield {

// The binary grid spans the voxel volume (VoxelSpace::fromScene): res x res columns of 128
// slices, so a voxel is columnSize x columnSize x sliceDepth (anisotropic unless res = 128).
struct BinaryGridGeometry {
  glm::vec3 origin{0.0f};  // world position of the volume's minimum corner
  float edge = 1.0f;       // volume edge (m); unit space = (world - origin) / edge
  int resolution = 1;      // columns per side
  float columnSize = 1.0f;
  float sliceDepth = 1.0f;
  float voxelDiagonal = 1.0f;  // sqrt(2 columnSize^2 + sliceDepth^2), the unit of the ray offsets
  static BinaryGridGeometry of(const Scene& scene, int res);
};

int maxLevelOf(int res);  // log2(res): the hierarchy's top level (1 x 1)

}  // namespace voxlab::nearfield
