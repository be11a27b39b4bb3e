#include "scene/voxel_space.h"

#include <algorithm>

#include "gpu/shader_library.h"

namespace voxlab {

VoxelSpace VoxelSpace::fromScene(const Scene& scene, int resolution) {
  VoxelSpace v;
  v.resolution = resolution;
  glm::vec3 ext = scene.bounds.extent();
  float largest = std::max(std::max(ext.x, ext.y), std::max(ext.z, 1e-4f));
  v.voxelSize = largest / float(std::max(resolution - 1, 1));
  v.origin = scene.bounds.center() - 0.5f * v.voxelSize * float(resolution);
  return v;
}

void VoxelSpace::setUniforms(GLuint program) const {
  setUniform(program, "u_volumeOrigin", origin);
  setUniform(program, "u_voxelSize", voxelSize);
  setUniform(program, "u_voxelsPerMetre", voxelsPerMetre());
  setUniform(program, "u_resolution", resolution);
}

}  // namespace voxlab
