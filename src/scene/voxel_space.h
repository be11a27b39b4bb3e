// VoxelSpace: the voxel volume every voxel technique and the CPU reference voxelizer use, a cube
// around the scene's bounds, resolution^3 voxels. The scene's largest extent spans resolution - 1
// voxels and is centred, so the outermost surfaces lie half a voxel inside the volume (never
// exactly on a voxel boundary or outside).
#pragma once
#include <glm/glm.hpp>

#include "gpu/gl.h"
#include "scene/scene.h"

namespace voxlab {

struct WorldBox;  // graph/blackboard.h: where a volume sits in the world

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
  // The volume as the blackboard places volumes (Blackboard::setVoxelSpace); defined with the
  // blackboard's users, in techniques/common/voxel_space.cpp.
  WorldBox box() const;
};

}  // namespace voxlab
