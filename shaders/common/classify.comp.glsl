#version 450
// Triangle classification, one invocation per triangle: the dominant axis of the plane normal
// (from positions, in voxel units), the area of the triangle projected along it in voxels^2, and
// the class: small triangles go to the triangle-parallel compute pass (listed in triangleList and
// flagged with bit 31 of triangleInfo), large ones to the fragment-parallel raster pass
// (Rauwendaal & Bailey 2013; seed 002 chapter 3). A triangle outside the part of the scene being
// voxelized (bit 30 of triangleInfo, set by the stage: static triangles when it voxelizes the
// moving ones, or the reverse) is neither counted nor classified, so neither pass voxelizes it.
#include "common/shared.h"
#include "common/voxel_space.glsl"
#include "common/scene_triangles.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = VOXLAB_BINDING_TRIANGLE_INFO) buffer TriangleInfo { uint triangleInfo[]; };
layout(std430, binding = VOXLAB_BINDING_TRIANGLE_LIST) writeonly buffer TriangleList { uint triangleList[]; };
// [0..2] triangles per dominant axis, [3] degenerate, [4] small (compute), [5] large (raster),
// [6] an upper bound of the voxel columns of any listed triangle, [7] listed triangles with more
// than u_chunkColumns columns. The compute pass loops over a triangle's columns in chunks of
// u_chunkColumns (triangle_parallel.comp.glsl): every listed triangle is in triangleList[0..[4]),
// the ones that need more than one chunk also in triangleList[u_triangleCount + (0..[7])).
layout(std430, binding = VOXLAB_BINDING_CLASS_COUNTS) buffer ClassCounts { uint classCounts[8]; };

uniform uint u_triangleCount;
uniform int u_mode;      // 0: every triangle large (raster), 1: every triangle small (compute), 2: by area
uniform float u_cutoff;  // hybrid: projected area (voxels^2) below which a triangle is small
uniform uint u_chunkColumns;  // voxel columns one compute invocation visits at most

void main() {
  uint t = gl_GlobalInvocationID.x;
  if (t >= u_triangleCount) return;
  if ((triangleInfo[t] & 0x40000000u) != 0u) return;  // another part of the scene
  vec3 v0 = worldToVoxel(scenePosition(sceneVertexIndex(t, 0)));
  vec3 v1 = worldToVoxel(scenePosition(sceneVertexIndex(t, 1)));
  vec3 v2 = worldToVoxel(scenePosition(sceneVertexIndex(t, 2)));
  vec3 n = cross(v1 - v0, v2 - v0);
  uint info = triangleInfo[t] & 0x00FFFFFFu;  // keep the material index, clear the class bit
  // Degenerate triangles have no area and no voxels: neither pass voxelizes them.
  if (max(abs(n.x), max(abs(n.y), abs(n.z))) <= 0.0) {
    atomicAdd(classCounts[3], 1u);
    triangleInfo[t] = info;
    return;
  }
  int axis = dominantAxis(n);
  atomicAdd(classCounts[axis], 1u);
  // The projection along the dominant axis has area |n[axis]| / 2 (n is twice the area vector).
  float projectedArea = 0.5 * abs(n[axis]);
  bool small = u_mode == 1 || (u_mode == 2 && projectedArea < u_cutoff);
  if (small) {
    uint slot = atomicAdd(classCounts[4], 1u);
    triangleList[slot] = t;
    info |= 0x80000000u;
    // Columns of the triangle's voxel box seen along any axis, the box grown by one voxel so that
    // rounding in the compute pass's own box can only make it smaller than this bound.
    vec3 lo = min(v0, min(v1, v2)), hi = max(v0, max(v1, v2));
    uvec3 extent = uvec3(clamp(ivec3(floor(hi)) + 1, ivec3(0), ivec3(u_resolution - 1)) -
                         clamp(ivec3(ceil(lo)) - 2, ivec3(0), ivec3(u_resolution - 1)) + 1);
    uint columns = max(extent.x * extent.y, max(extent.y * extent.z, extent.z * extent.x));
    atomicMax(classCounts[6], columns);
    if (columns > u_chunkColumns) triangleList[u_triangleCount + atomicAdd(classCounts[7], 1u)] = t;
  } else {
    atomicAdd(classCounts[5], 1u);
  }
  triangleInfo[t] = info;
}
