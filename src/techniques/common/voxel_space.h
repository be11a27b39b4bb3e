// The voxel fragment list every voxelizing technique fills within the voxel volume (VoxelSpace,
// scene/voxel_space.h): its record count, the capacity to allocate before a pass, its layout.
#pragma once
#include <cstdint>
#include <string>

#include <glm/glm.hpp>

#include "graph/blackboard.h"
#include "graph/output.h"
#include "scene/scene.h"
#include "scene/voxel_space.h"

namespace voxlab {

class Blackboard;

// Valid records in the voxel fragment list "fragments": its counter "fragments.count", capped at
// the list's capacity (the counter keeps counting past it when the list overflows).
uint32_t voxelFragmentCount(Blackboard& board);

// Records to allocate for the fragment list 'list' before a voxelization pass: the larger of a
// guess of 12 per resolution^2 (at least 65536), estimateFragments() and the list's current size,
// so that the passes rarely have to run twice.
size_t initialFragmentCapacity(Blackboard& board, const Scene& scene, int resolution,
                               const std::string& list = "fragments");
// An estimate of the fragments a conservative voxelization of 'scene' produces (from each
// triangle's projected area and perimeter in voxels); it errs on the large side.
size_t estimateFragments(const Scene& scene, const VoxelSpace& space);
// Fragments the pool starts with at a resolution (before it grows to what a scene produces).
size_t fragmentPoolStart(int resolution);

// The record layout of the VoxelFragment list (shaders/common/shared.h), for outputs.
BufferLayout voxelFragmentLayout(const std::string& countResource);

}  // namespace voxlab
