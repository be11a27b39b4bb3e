// The voxelization passes every technique shares (seed 002 chapter 3; docs/voxelization.md):
// the per-triangle classification and the triangle-parallel compute pass, next to the
// fragment-parallel raster pass of voxelize_stage.h. vct-grid's voxelize stage and the
// voxelization technique's classify/voxelize stages both call these.
#pragma once
#include <cstdint>

#include "graph/stage.h"
#include "techniques/common/voxel_space.h"

namespace voxlab {

// The voxelize.method choices, in ParamDesc order.
enum class VoxelizeMethod { FragmentParallel = 0, Plain = 1, TriangleParallel = 2, Hybrid = 3 };

// "voxelize.method" with the given default (vct-grid defaults to the faster exact method on
// llvmpipe, triangle-parallel; the voxelization technique to fragment-parallel).
ParamDesc voxelizeMethodParam(VoxelizeMethod defaultMethod);
ParamDesc hybridCutoffParam();
VoxelizeMethod voxelizeMethodOf(const ParamSet& params);

// Voxel columns one triangle-parallel invocation visits at most (llvmpipe ends an invocation's
// loops after 65535 iterations in all; a chunk costs at most 5 per column).
inline constexpr uint32_t kChunkColumns = 8192;

// The classification's counters (shaders/common/classify.comp.glsl).
struct TriangleClasses {
  uint32_t axis[3] = {0, 0, 0};
  uint32_t degenerate = 0;
  uint32_t compute = 0;     // triangles the compute pass voxelizes (class bit set)
  uint32_t raster = 0;      // triangles left to the raster pass
  uint32_t maxColumns = 0;  // upper bound of any compute triangle's voxel columns
  uint32_t multiChunk = 0;  // compute triangles with more than kChunkColumns columns
  int chunks() const {
    uint32_t c = (maxColumns + kChunkColumns - 1) / kChunkColumns;
    return c > 1 ? int(c) : 1;
  }
};

// Classifies every triangle for 'method' (plain and fragment-parallel: all raster;
// triangle-parallel: all compute; hybrid: by projected area against voxelize.hybrid-cutoff).
// Writes the board's "triangle-info" (material | class bit per triangle), "triangle-list" and
// "triangle-classes" (the counters); declare them as written by the calling stage.
void classifyTriangles(StageContext& ctx, const VoxelSpace& space, VoxelizeMethod method, float cutoff);
// Reads the counters back (one readback).
TriangleClasses readTriangleClasses(StageContext& ctx);

// The triangle-parallel pass over the triangles classified 'compute', appending to the fragment
// list bound by fillFragmentList (call it inside its passes with the list's capacity). One
// dispatch per draw range, so each sees one material and samples its textures.
void voxelizeTrianglesCompute(StageContext& ctx, const VoxelSpace& space, const TriangleClasses& classes,
                              uint32_t capacity);

// The fragment-parallel raster pass for 'method' (fragment-parallel, plain, or hybrid: the large
// triangles), appending to the list bound by fillFragmentList.
void voxelizeTrianglesRaster(StageContext& ctx, const VoxelSpace& space, VoxelizeMethod method, uint32_t capacity);

// Both passes as 'method' needs them; returns the fragments the raster pass appended (0 when it
// did not run).
uint32_t voxelizeTriangles(StageContext& ctx, const VoxelSpace& space, VoxelizeMethod method,
                           const TriangleClasses& classes, uint32_t capacity);
bool methodRasterizes(VoxelizeMethod method, const TriangleClasses& classes);
bool methodComputes(VoxelizeMethod method, const TriangleClasses& classes);

}  // namespace voxlab
