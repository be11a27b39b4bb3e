// CPU reference voxelizer: the exact conservative surface voxel set of a scene.
//
// A voxel belongs to the set when at least one triangle meets its half-open cell [i, i+1)^3
// (separating axis test over the 13 axes of Akenine-Moller 2001, ties on a cell's upper faces
// separate: docs/voxelization.md, "Ties on voxel faces"). A plane exactly on a voxel boundary
// therefore fills one layer, the one above it. Degenerate triangles (zero area) are skipped, as
// the GPU voxelizers skip them. Triangles of alphaMode MASK materials keep only the voxels
// their alpha coverage allows (scene/alpha_coverage.h, the GPU's rule). The GPU methods are
// tested against this.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace voxlab {

struct VoxelSpace;

bool triangleOverlapsBox(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                         const glm::dvec3& center, const glm::dvec3& halfSize);

// Sorted, unique voxel keys (x | y << 10 | z << 20, the 10:10:10 packing) overlapped by the
// scene's triangles in the given voxel space.
std::vector<uint32_t> referenceVoxelSet(const Scene& scene, const VoxelSpace& space);
// The number of (triangle, voxel) pairs: the fragments an exact voxelizer appends (one per
// triangle per voxel it meets).
size_t referencePairCount(const Scene& scene, const VoxelSpace& space);

inline uint32_t packVoxelKey(int x, int y, int z) { return uint32_t(x) | (uint32_t(y) << 10) | (uint32_t(z) << 20); }
inline glm::ivec3 unpackVoxelKey(uint32_t k) { return {int(k & 1023u), int((k >> 10) & 1023u), int((k >> 20) & 1023u)}; }

}  // namespace voxlab
