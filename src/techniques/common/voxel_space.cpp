#include "techniques/common/voxel_space.h"

#include <algorithm>
#include <cstring>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "graph/blackboard.h"

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

uint32_t voxelFragmentCount(Blackboard& board) {
  uint32_t count = 0;
  auto bytes = board.buffer("fragments.count").download(4);
  std::memcpy(&count, bytes.data(), 4);
  uint32_t capacity = uint32_t(board.buffer("fragments").size() / sizeof(gpu::VoxelFragment));
  return std::min(count, capacity);
}

size_t fragmentPoolStart(int resolution) { return std::max<size_t>(size_t(resolution) * resolution * 12, 1 << 16); }

size_t initialFragmentCapacity(Blackboard& board, int resolution) {
  size_t capacity = fragmentPoolStart(resolution);
  if (board.hasBuffer("fragments"))
    capacity = std::max(capacity, board.buffer("fragments").size() / sizeof(gpu::VoxelFragment));
  return capacity;
}

BufferLayout voxelFragmentLayout(const std::string& countResource) {
  BufferLayout L;
  L.stride = sizeof(gpu::VoxelFragment);
  L.fields = {{"voxel", FieldType::Packed10_10_10, offsetof(gpu::VoxelFragment, position), FieldRole::Position},
              {"albedo", FieldType::UnormRGBA8, offsetof(gpu::VoxelFragment, albedo), FieldRole::Color},
              {"normal", FieldType::SnormRGBA8, offsetof(gpu::VoxelFragment, normal), FieldRole::Normal},
              {"emission", FieldType::UnormRGBA8, offsetof(gpu::VoxelFragment, emission), FieldRole::Other}};
  L.countResource = countResource;
  return L;
}

}  // namespace voxlab
