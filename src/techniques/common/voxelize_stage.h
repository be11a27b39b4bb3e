// The shared voxelization: the scene's triangles become a voxel fragment list (seed 000 section
// 2.1) in three stages, so that a frame where only animated nodes moved re-voxelizes only them.
//
//   voxelize-static  the triangles no animation moves (every triangle of a still scene) into the
//                    list "fragments.static"; it reads "@static-geometry" alone, so it runs once
//                    while objects move, the camera turns or lights change
//   voxelize         copies that list to the front of "fragments" and appends the fragments of the
//                    triangles animations move ("@dynamic-geometry"): the merged list every later
//                    stage reads. Crassin et al. 2011 (section 5) and Gomes (seed 000 section 3.x)
//                    keep the static voxels and revoxelize the dynamic objects each frame; with a
//                    fragment list, keeping a static copy and merging is one buffer copy.
//   triangle-axes    the triangles coloured by their projection axis, seen from the camera (the
//                    only one of the three that reads the view)
//
// Both voxelizing stages run the passes of techniques/common/triangle_voxelizer.h over their part
// of the scene: the triangle-parallel compute pass (the default) or the geometry-shader raster
// pass, which projects each triangle along its dominant axis and, in conservative mode, grows it
// by half a pixel diagonal (triangle expansion with bounding-box discard, since llvmpipe has no
// conservative-raster extension); each overlapped voxel appends one VoxelFragment (position
// packed 10:10:10, albedo, normal, emission) with an atomic counter. Every voxel is decided by one
// triangle alone, so the merged list holds the records voxelizing every triangle at once gives (in
// another order; every consumer sums or sorts them).
#pragma once
#include <functional>
#include <string>

#include "graph/stage.h"
#include "scene/gpu_scene.h"
#include "techniques/common/triangle_voxelizer.h"

namespace voxlab {

class Buffer;
class Technique;

class VoxelizeStaticStage : public Stage {
 public:
  const char* id() const override { return "voxelize-static"; }
  const char* title() const override { return "Voxelize the still triangles"; }
  const char* summary() const override {
    return "Voxelize the triangles no animation moves, once: the static voxel fragments every frame starts from.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class VoxelizeStage : public Stage {
 public:
  const char* id() const override { return "voxelize"; }
  const char* title() const override { return "Voxelize the scene"; }
  const char* summary() const override {
    return "Start from the still triangles' voxel fragments and append those of the moving triangles: project each "
           "along its dominant axis, rasterize it conservatively at the voxel resolution and append one voxel "
           "fragment per covered voxel.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class TriangleAxesStage : public Stage {
 public:
  const char* id() const override { return "triangle-axes"; }
  const char* title() const override { return "Projection axes"; }
  const char* summary() const override {
    return "Colour each triangle by the axis voxelization projects it along (x red, y green, z blue), seen from the "
           "camera.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

// Adds voxelize-static, voxelize and triangle-axes, in that order: the voxelization every
// technique that reads the shared "fragments" list starts with.
void addVoxelizeStages(Technique& technique);

// The fragment list a voxelization fills: its records and counter, and records to copy to its
// front before the passes append.
struct FragmentList {
  std::string records = "fragments";
  std::string count = "fragments.count";
  const Buffer* prefix = nullptr;  // null: the list starts empty
  uint32_t prefixCount = 0;        // records of 'prefix' copied
  // Records to allocate before the passes; 0 = initialFragmentCapacity's guess.
  size_t firstCapacity = 0;
};

// Fills a voxel fragment list (by default "fragments", counter "fragments.count"; per-axis
// triangle counts in scratch.axisCounts): resets the counters (the list's to the prefix copied to
// its front), binds the three, and runs 'passes' with the list's capacity in records. When the
// counter says more fragments were produced than fit, the list grows to that size and the passes
// run once more. Returns the records the list holds (prefix included); 'capacity' receives its
// final capacity.
uint32_t fillFragmentList(StageContext& ctx, int resolution, const std::function<void(uint32_t capacity)>& passes,
                          size_t& capacity, const FragmentList& list = {}, const VoxelizeScratch& scratch = {});

// The fragment-parallel pass: draws the scene with the program 'programFor' gives each material
// kind (common/world.vert + common/voxelize.geom/.frag; GpuScene::draw) over a resolution^2
// framebuffer without attachments, then makes its appends visible. Call inside
// fillFragmentList's passes. With 'ranges' it draws only those runs of triangles, not the whole
// scene.
void rasterizeVoxelFragments(StageContext& ctx, const GpuScene::ProgramForKind& programFor, int resolution,
                             const std::vector<DrawRange>* ranges = nullptr);

// The value of a 32-bit counter at byte 'offset' of 'buffer' (reads it back).
uint32_t readCounter(const Buffer& buffer, size_t offset = 0);

// Renders the scene from the camera into the 2D texture 'resource', each triangle coloured by the
// axis voxelization projects it along (x red, y green, z blue).
void renderTriangleAxes(StageContext& ctx, const std::string& resource);
TextureDesc triangleAxesDesc(const ViewState& view);

// Declares the fragment pool 'records' (its starting size; it grows to what the scene produces)
// for the resource budget: every stage that fills one through fillFragmentList calls this in
// declare().
// 'startRecords' = 0: fragmentPoolStart(voxel.resolution).
void declareFragmentPool(StageBuilder& b, const std::string& records = "fragments", size_t startRecords = 0);

// The smallest list the merging voxelize stage allocates (records): it sizes "fragments" to the
// still triangles' records plus a guess for the moving ones, so the static copy does not double
// the memory a still scene's fragments take.
inline constexpr size_t kMergedFragmentsStart = size_t(1) << 16;

// Parameter shared by every stage that needs the voxel grid size.
ParamDesc voxelResolutionParam();

}  // namespace voxlab
