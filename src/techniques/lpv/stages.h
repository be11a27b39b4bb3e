// The stages of lpv after the shared voxelize and shadow-map stages (overview in lpv.cpp).
#pragma once
#include <array>
#include <string>

#include "graph/stage.h"
#include "techniques/common/composite_stage.h"
#include "lpv/lpv_shared.h"

struct Scene;

namespace voxlab::lpv {

constexpr int kCascades = 2;

// Semantics with visualisers of their own (src/techniques/lpv/views/sh_volume.cpp, lpv_energy.cpp,
// lpv_cascades.cpp).
inline constexpr Semantic kShL1{"sh-l1"};              // RGBA32F volume: L1 SH (c00, c1-1, c10, c11) per cell
inline constexpr Semantic kLpvEnergy{"lpv-energy"};    // LpvEnergy records, step * 2 + cascade
inline constexpr Semantic kLpvOcclusion{"lpv-occlusion"};  // LpvOcclusion records, one per cell
inline constexpr Semantic kLpvProbe{"lpv-probe"};          // one LpvProbe record: the picked cell
inline constexpr Semantic kLpvCascades{"lpv-cascades"};  // LpvBox records: cascade boxes and blend shell
extern const char* const kCascadeNames[kCascades];  // "fine", "coarse"
extern const char* const kChannelNames[3];          // "red", "green", "blue"

// Resource names: "<prefix>-<cascade>-<channel>" (e.g. "vpl-fine-red", "light-coarse-blue").
std::string shVolume(const char* prefix, int cascade, int channel);

// Where the cascades sit for this scene, camera and parameters (snapped to their cell sizes).
// Fixed-point units per fragment voxel^2 of a cell's area word (LpvVoxel::area): 2^16, fewer
// where a cell spans so many voxels that its sum could pass 2^31 (each voxel adds at most about one
// voxel^2 of surface).
float areaUnits(float cellSize, float voxelSize);
std::array<gpu::LpvGrid, kCascades> placeGrids(const voxlab::Scene& scene, const ViewState& view, const ParamSet& params);

class PlaceStage : public Stage {
 public:
  const char* id() const override { return "place"; }
  const char* title() const override { return "Place the cascades"; }
  const char* summary() const override {
    return "Centre the fine and coarse grids (on the scene or ahead of the camera) and snap each to a multiple "
           "of its cell size, so a camera move of less than a cell changes nothing.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class BinStage : public Stage {
 public:
  const char* id() const override { return "bin"; }
  const char* title() const override { return "Voxelize into the LPV grids"; }
  const char* summary() const override {
    return "Bin the voxel fragments into each cascade's cells: colour with contrast and occupancy, and one normal "
           "per tetrahedron channel, each kept by atomicMax (order independent).";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class InjectStage : public Stage {
 public:
  const char* id() const override { return "inject"; }
  const char* title() const override { return "Inject the lit voxels as VPLs"; }
  const char* summary() const override {
    return "Light every occupied cell with the shadow-mapped light; its reflected flux becomes a virtual point "
           "light stored as a clamped-cosine lobe in L1 SH per colour channel.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class PropagateStage : public Stage {
 public:
  const char* id() const override { return "propagate"; }
  const char* title() const override { return "Propagate the light, one step per iteration"; }
  const char* summary() const override {
    return "Each cell gathers from its six neighbours over five faces each, attenuated by the voxels; step them "
           "one at a time to watch the wavefront grow by one cell per step.";
  }
  void declare(StageBuilder& b) const override;
  int iterations(const ParamSet& params) const override;
  void execute(StageContext& ctx) override;
};

class ReflectionStage : public Stage {
 public:
  const char* id() const override { return "reflection"; }
  const char* title() const override { return "Reflection grid and its mips"; }
  const char* summary() const override {
    return "A finer colour grid over the fine cascade's box, lit from the fine cascade's L0 light, then one mip "
           "level per iteration (each texel the mean of its 8 children) for glossy cones.";
  }
  void declare(StageBuilder& b) const override;
  int iterations(const ParamSet& params) const override;
  void execute(StageContext& ctx) override;
};

class GiStage : public Stage {
 public:
  const char* id() const override { return "gi"; }
  const char* title() const override { return "Look up the indirect light"; }
  const char* summary() const override {
    return "Per pixel, read each cascade's SH trilinearly, convolve with the cosine around the surface, blend the "
           "cascades in a shell at the fine grid's edge and turn the result into outgoing radiance.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

// The terms of this technique's composite (techniques/common/composite_stage.h).
CompositeTerms compositeTerms();

}  // namespace voxlab::lpv
