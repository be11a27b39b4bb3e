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
#include <functional>
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

// Fills the voxel fragment list "fragments" (counter "fragments.count", per-axis triangle counts
// "voxelize.axis-counts"): resets the counters, binds the three, and runs 'passes' with the list's
// capacity in records. When the counter says more fragments were produced than fit, the list grows
// to that size and the passes run once more. Returns the fragments produced; 'capacity' receives
// the list's final capacity.
uint32_t fillFragmentList(StageContext& ctx, int resolution, const std::function<void(uint32_t capacity)>& passes,
                          size_t& capacity);

// The fragment-parallel pass: draws the scene with 'program' (common/world.vert +
// common/voxelize.geom/.frag) over a resolution^2 framebuffer without attachments, then makes
// its appends visible. Call inside fillFragmentList's passes.
void rasterizeVoxelFragments(StageContext& ctx, GLuint program, int resolution);

// The value of a 32-bit counter at byte 'offset' of 'buffer' (reads it back).
uint32_t readCounter(const Buffer& buffer, size_t offset = 0);

// Renders the scene from the camera into the 2D texture 'resource', each triangle coloured by the
// axis voxelization projects it along (x red, y green, z blue).
void renderTriangleAxes(StageContext& ctx, const std::string& resource);
TextureDesc triangleAxesDesc(const ViewState& view);

// Declares the "fragments" pool (its starting size; it grows to what the scene produces) for the
// resource budget: every stage that fills it through fillFragmentList calls this in declare().
void declareFragmentPool(StageBuilder& b);

// Parameter shared by every stage that needs the voxel grid size.
ParamDesc voxelResolutionParam();

}  // namespace voxlab
