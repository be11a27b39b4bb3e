// VoxelizeStage: turns the scene's triangles into a voxel fragment list (seed 000 section 2.1).
//
// One rasterization pass over an empty framebuffer of resolution^2 pixels: the geometry shader
// projects each triangle along its dominant axis and, in conservative mode, grows it by half a
// pixel diagonal (triangle expansion with bounding-box discard, since llvmpipe has no
// conservative-raster extension); the fragment shader appends one VoxelFragment (position packed
// 10:10:10, albedo, normal, emission) per overlapped voxel with an atomic counter.
//
// Writes: "fragments" (the list), "fragments.count" (atomic counter), "triangle-axes" (triangles
// coloured by projection axis, from the camera).
#pragma once
#include <string>

#include "graph/stage.h"

namespace voxlab {

class VoxelizeStage : public Stage {
 public:
  const char* id() const override { return "voxelize"; }
  const char* title() const override { return "Voxelize the scene"; }
  const char* summary() const override {
    return "Project each triangle along its dominant axis, rasterize it conservatively at the voxel "
           "resolution and append one voxel fragment per covered voxel.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

// Renders the scene from the camera into the 2D texture 'resource', each triangle coloured by the
// axis voxelization projects it along (x red, y green, z blue).
void renderTriangleAxes(StageContext& ctx, const std::string& resource);

// Parameter shared by every stage that needs the voxel grid size.
ParamDesc voxelResolutionParam();

}  // namespace voxlab
