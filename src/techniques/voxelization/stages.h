// Stages of the voxelization technique (voxelization.cpp explains the whole).
#pragma once
#include "graph/stage.h"
#include "techniques/common/triangle_voxelizer.h"

namespace voxlab::vox {

// voxelize.method as this technique declares it (default fragment-parallel); the choices and
// the passes are shared with vct-grid (techniques/common/triangle_voxelizer.h).
ParamDesc methodParam();
// The 10:10:10 voxel packing addresses at most this many voxels per axis.
inline constexpr int kMaxPackedResolution = 1024;
// Throws Error when 'resolution' cannot be packed into 10 bits per axis.
void checkPackableResolution(int resolution);

// 1. Per triangle: dominant axis, projected area, class (small -> compute, large -> raster).
class ClassifyStage : public Stage {
 public:
  const char* id() const override { return "classify"; }
  const char* title() const override { return "Classify triangles"; }
  const char* summary() const override {
    return "Find each triangle's dominant axis and its area projected along it, and decide which pass "
           "voxelizes it: the triangle-parallel compute pass or the fragment-parallel raster pass.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

// 1b. One chosen triangle along its dominant axis: plain vs conservative pixel coverage.
class TriangleViewStage : public Stage {
 public:
  const char* id() const override { return "triangle-view"; }
  const char* title() const override { return "Look at one triangle"; }
  const char* summary() const override {
    return "One triangle projected along its dominant axis at the voxel resolution: the pixels plain "
           "rasterization covers, the ones conservative rasterization adds, the grown triangle and its box.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

// 2. Triangles -> voxel fragment list, by the chosen method.
class VoxelizeStage : public Stage {
 public:
  const char* id() const override { return "voxelize"; }
  const char* title() const override { return "Voxelize"; }
  const char* summary() const override {
    return "Append one voxel fragment per (triangle, overlapped voxel): by rasterizing along the dominant "
           "axis, by looping over each triangle's voxel box in a compute shader, or both.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

// 3. Fragment list -> occupancy grid (fragments per voxel).
class OccupancyStage : public Stage {
 public:
  const char* id() const override { return "occupancy"; }
  const char* title() const override { return "Build the occupancy grid"; }
  const char* summary() const override {
    return "Count the fragments of every voxel with image atomics; fragments minus occupied voxels are "
           "the duplicates the fragment list carries.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

// 4. The CPU reference set and where the method differs from it.
class CompareStage : public Stage {
 public:
  const char* id() const override { return "compare"; }
  const char* title() const override { return "Compare with the CPU reference"; }
  const char* summary() const override {
    return "Voxelize the same triangles on the CPU with the exact triangle/box test and mark every voxel "
           "the method missed (1) or added (2).";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

}  // namespace voxlab::vox
