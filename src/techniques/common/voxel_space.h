// The voxel volume every voxel technique uses: a cube around the scene's bounds, resolution^3
// voxels. The scene's largest extent spans resolution - 1 voxels and is centred, so the outermost
// surfaces lie half a voxel inside the volume (never exactly on a voxel boundary or outside).
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

#include "gpu/gl.h"
#include "graph/blackboard.h"
#include "graph/output.h"
#include "scene/scene.h"

namespace voxlab {

struct VoxelSpace {
  glm::vec3 origin{0.0f};  // world position of the volume's minimum corner
  float voxelSize = 1.0f;  // edge of one voxel, metres
  int resolution = 1;      // voxels per axis

  static VoxelSpace fromScene(const Scene& scene, int resolution);
  float edge() const { return voxelSize * float(resolution); }
  // Voxels per metre, the factor every voxelizer (GPU and CPU) multiplies by: a subtraction and a
  // multiplication are correctly rounded on every GPU (a GLSL division need not be), so a vertex
  // gets the same float voxel coordinates on both sides and a tie on a voxel face is the same tie.
  float voxelsPerMetre() const { return 1.0f / voxelSize; }
  glm::vec3 toVoxel(const glm::vec3& world) const { return (world - origin) * voxelsPerMetre(); }
  void setUniforms(GLuint program) const;  // u_volumeOrigin, u_voxelSize, u_voxelsPerMetre, u_resolution
  WorldBox box() const { return {origin, origin + glm::vec3(edge())}; }
};

class Blackboard;

// Valid records in the voxel fragment list "fragments": its counter "fragments.count", capped at
// the list's capacity (the counter keeps counting past it when the list overflows).
uint32_t voxelFragmentCount(Blackboard& board);

// Records to allocate for the fragment list before a voxelization pass: the larger of a guess of
// 12 per resolution^2 (at least 65536), estimateFragments() and the list's current size, so that
// the passes rarely have to run twice.
size_t initialFragmentCapacity(Blackboard& board, const Scene& scene, int resolution);
// An estimate of the fragments a conservative voxelization of 'scene' produces (from each
// triangle's projected area and perimeter in voxels); it errs on the large side.
size_t estimateFragments(const Scene& scene, const VoxelSpace& space);
// Fragments the pool starts with at a resolution (before it grows to what a scene produces).
size_t fragmentPoolStart(int resolution);

// The record layout of the VoxelFragment list (shaders/common/shared.h), for outputs.
BufferLayout voxelFragmentLayout(const std::string& countResource);

}  // namespace voxlab
