// The voxelization passes every technique shares (seed 002 chapter 3; docs/voxelization.md):
// the per-triangle classification and the triangle-parallel compute pass, next to the
// fragment-parallel raster pass of voxelize_stage.h. vct-grid's voxelize stage and the
// voxelization technique's classify/voxelize stages both call these.
#pragma once
#include <cstdint>
#include <string>

#include "graph/stage.h"
#include "techniques/common/voxel_space.h"

namespace voxlab {

// The voxelize.method choices, in ParamDesc order.
enum class VoxelizeMethod { FragmentParallel = 0, Plain = 1, TriangleParallel = 2, Hybrid = 3 };

// "voxelize.method" with the given default (the shared voxelize stages default to hybrid, the
// faster routing on llvmpipe; the voxelization technique to fragment-parallel).
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

// The board buffers one voxelization works in. Each board resource has one writer, so a stage
// that voxelizes a part of the scene next to another stage doing the rest names its own.
struct VoxelizeScratch {
  std::string triangleInfo = "triangle-info";        // material | class bit | other-part bit per triangle
  std::string triangleList = "triangle-list";        // the triangles the compute pass visits
  std::string triangleClasses = "triangle-classes";  // the classification's counters
  std::string axisCounts = "voxelize.axis-counts";   // triangles per projection axis (raster pass)
  // The four named "<prefix>.triangle-info", "<prefix>.triangle-list", ...
  static VoxelizeScratch prefixed(const std::string& prefix);
  void declareWrites(StageBuilder& b) const;  // declares the four as written by the stage
};

// Which triangles of the scene a voxelization covers: all, those no animation moves, or those
// it moves (Scene::triangleMoves).
enum class TrianglePart { All, Static, Dynamic };
// Whether 'part' holds 'triangle' of 'scene'.
bool partHolds(const Scene& scene, TrianglePart part, size_t triangle);

// Classifies every triangle of 'part' for 'method' (plain and fragment-parallel: all raster;
// triangle-parallel: all compute; hybrid: by projected area against voxelize.hybrid-cutoff);
// triangles outside it are left to neither pass. Writes the board's "triangle-info" (material |
// class bit | other-part bit per triangle), "triangle-list" and "triangle-classes" (the
// counters); declare them as written by the calling stage.
void classifyTriangles(StageContext& ctx, const VoxelSpace& space, VoxelizeMethod method, float cutoff,
                       TrianglePart part = TrianglePart::All, const VoxelizeScratch& scratch = {});
// Reads the counters back (one readback).
TriangleClasses readTriangleClasses(StageContext& ctx, const VoxelizeScratch& scratch = {});

// The triangle-parallel pass over the triangles classified 'compute', appending to the fragment
// list bound by fillFragmentList (call it inside its passes with the list's capacity). One
// dispatch per draw range, so each sees one material and samples its textures.
void voxelizeTrianglesCompute(StageContext& ctx, const VoxelSpace& space, const TriangleClasses& classes,
                              uint32_t capacity, const VoxelizeScratch& scratch = {});

// The fragment-parallel raster pass for 'method' (fragment-parallel, plain, or hybrid: the large
// triangles) over the triangles of 'part', appending to the list bound by fillFragmentList.
void voxelizeTrianglesRaster(StageContext& ctx, const VoxelSpace& space, VoxelizeMethod method, uint32_t capacity,
                             TrianglePart part = TrianglePart::All, const VoxelizeScratch& scratch = {});

// Both passes as 'method' needs them, over the triangles of 'part' (as classified); returns the
// count of the fragment list 'countResource' after the raster pass (0 when it did not run).
uint32_t voxelizeTriangles(StageContext& ctx, const VoxelSpace& space, VoxelizeMethod method,
                           const TriangleClasses& classes, uint32_t capacity, TrianglePart part = TrianglePart::All,
                           const VoxelizeScratch& scratch = {}, const std::string& countResource = "fragments.count");
bool methodRasterizes(VoxelizeMethod method, const TriangleClasses& classes);
bool methodComputes(VoxelizeMethod method, const TriangleClasses& classes);

}  // namespace voxlab
