// The stages of vct-grid after voxelization and the shadow map (see vct_grid.cpp for the overview).
#pragma once
#include "graph/stage.h"

namespace voxlab::vct {

// Names of the six anisotropic volumes (+x -x +y -y +z -z) and the parameter that enables them.
extern const char* const kDirectionalVolumes[6];
ParamDesc mipmapModeParam();

class InjectStage : public Stage {
 public:
  const char* id() const override { return "inject"; }
  const char* title() const override { return "Inject direct light into the voxels"; }
  const char* summary() const override {
    return "Light each voxel fragment (Lambert, shadow-mapped, plus emission) and average the fragments "
           "of each voxel into an RGBA8 radiance grid: exact fixed-point sums with integer atomics, then one "
           "division (or, inject.average=compare-and-swap, a running average with an atomic compare-and-swap loop).";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class OcclusionFixStage : public Stage {
 public:
  const char* id() const override { return "occlusion-fix"; }
  const char* title() const override { return "Make occupied voxels opaque"; }
  const char* summary() const override {
    return "While averaging, alpha counted fragments; set it to 1 in every non-empty voxel so cones see solid voxels.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class MipmapStage : public Stage {
 public:
  const char* id() const override { return "mipmap"; }
  const char* title() const override { return "Prefilter the grid into mip levels"; }
  const char* summary() const override {
    return "Average each 2x2x2 block into the next level (our own compute pass per level), so a wide cone "
           "can read a whole region in one sample. One iteration per level: step them to watch the pyramid grow.";
  }
  void declare(StageBuilder& b) const override;
  int iterations(const ParamSet& params) const override;
  void execute(StageContext& ctx) override;
};

class ConeTraceStage : public Stage {
 public:
  const char* id() const override { return "cone-trace"; }
  const char* title() const override { return "Trace cones through the voxels"; }
  const char* summary() const override {
    return "Per pixel, march diffuse cones around the normal, a specular cone along the reflection and a "
           "shadow cone toward the light, sampling coarser mip levels as each cone widens. Traced in "
           "four bands of rows, one per iteration, so the viewer shows progress.";
  }
  static constexpr int kBands = 4;
  void declare(StageBuilder& b) const override;
  int iterations(const ParamSet&) const override { return kBands; }
  void execute(StageContext& ctx) override;
};

class CompositeStage : public Stage {
 public:
  const char* id() const override { return "composite"; }
  const char* title() const override { return "Composite the final image"; }
  const char* summary() const override {
    return "Add direct light, indirect diffuse and indirect specular, then tonemap.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

}  // namespace voxlab::vct
