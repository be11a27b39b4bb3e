#include "techniques/common/voxel_space.h"

#include <algorithm>
#include <cstring>

#include "common/shared.h"
#include "graph/blackboard.h"

namespace voxlab {

WorldBox VoxelSpace::box() const { return {origin, origin + glm::vec3(edge())}; }

uint32_t voxelFragmentCount(Blackboard& board) {
  uint32_t count = 0;
  auto bytes = board.buffer("fragments.count").download(4);
  std::memcpy(&count, bytes.data(), 4);
  uint32_t capacity = uint32_t(board.buffer("fragments").size() / sizeof(gpu::VoxelFragment));
  return std::min(count, capacity);
}

size_t estimateFragments(const Scene& scene, const VoxelSpace& space) {
  // Per triangle: its area projected along the dominant axis plus its projected perimeter (the
  // half-voxel border a conservative voxelization adds) plus one, in voxels, times 1.15 for the
  // voxels a steep plane adds to a column. Measured on Sponza at 128^3: 1.39 x the 706k
  // fragments produced (the list is 16 bytes a record).
  double sum = 0.0;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    glm::vec3 v[3];
    for (int k = 0; k < 3; ++k) v[k] = space.toVoxel(scene.positions[scene.indices[3 * t + k]]);
    glm::vec3 n = glm::abs(glm::cross(v[1] - v[0], v[2] - v[0]));
    int axis = (n.x >= n.y && n.x >= n.z) ? 0 : (n.y >= n.z ? 1 : 2);
    double perimeter = 0.0;
    for (int k = 0; k < 3; ++k) {
      glm::vec3 e = v[(k + 1) % 3] - v[k];
      e[axis] = 0.0f;
      perimeter += glm::length(e);
    }
    sum += 0.5 * double(n[axis]) + perimeter + 1.0;
  }
  return size_t(1.15 * sum);
}

size_t fragmentPoolStart(int resolution) { return std::max<size_t>(size_t(resolution) * resolution * 12, 1 << 16); }

size_t initialFragmentCapacity(Blackboard& board, const Scene& scene, int resolution, const std::string& list) {
  size_t capacity = fragmentPoolStart(resolution);
  capacity = std::max(capacity, estimateFragments(scene, VoxelSpace::fromScene(scene, resolution)));
  if (board.hasBuffer(list)) capacity = std::max(capacity, board.buffer(list).size() / sizeof(gpu::VoxelFragment));
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
