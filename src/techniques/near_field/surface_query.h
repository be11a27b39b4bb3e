// The true surface a probed near-field ray meets, for the probe record: an exact ray/triangle query
// over every triangle of the scene (no acceleration structure: it runs once per probed ray, a few
// milliseconds on Sponza's 262 k triangles), and how far that point lies from the voxel the
// hierarchical walk stopped in, in voxels.
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace voxlab::nearfield {

struct BinaryGridGeometry;

struct SurfaceHit {
  bool hit = false;
  float t = 0.0f;         // distance along the unit direction (m)
  uint32_t triangle = 0;  // index of the triangle (Scene::indices / 3)
};

// The nearest triangle hit by o + t d for t in (0, tMax] (d unit). Moller-Trumbore in double
// precision; alphaMode MASK triangles let the ray through where baseColor.a x the bilinear texture
// alpha (REPEAT) is below the cutoff, the rule of the G-buffer and of the reference path tracer.
SurfaceHit firstSurfaceAlong(const Scene& scene, glm::vec3 o, glm::vec3 d, float tMax);

// Distance from world point p to the box of binary-grid voxel (x, y, slice), measured per axis in
// that axis' voxel size (columns: edge / res, slices: edge / 128). chebyshev: the largest axis
// distance (0: p inside the voxel or on its faces, <= 1: p inside one of its 26 neighbours);
// euclidean: the length of the per-axis distances.
struct VoxelGap {
  float chebyshev = 0.0f;
  float euclidean = 0.0f;
};
VoxelGap gapToVoxel(const BinaryGridGeometry& geo, glm::ivec3 voxel, glm::vec3 p);

}  // namespace voxlab::nearfield
