// The stages of the volumetric technique (see volumetric.cpp for the overview). The shadow map
// and the G-buffer are the shared stages of src/techniques/common.
#pragma once
#include <string>

#include "graph/stage.h"
#include "scene/scene.h"

namespace voxlab::volumetric {

// The medium's coefficients are given per scene: as optical depths over the scene's largest
// extent L (mediumLength), so sigma_s = depth / L in 1/m. The same defaults then make a medium
// as transparent across a 0.56 m Cornell box as across a 37 m atrium (a coefficient in 1/m that
// suits one is a fog or nothing in the other). kHazeOpticalDepth: the haze's optical depth over L
// (0.6 /m in the Cornell box, 0.009 /m in Sponza); kParticleOpticalDepth: what one particle per
// voxel adds over L (0.25 /m per particle in the Cornell box at the default 32^3 grid). The
// particles' counts per voxel do not depend on the scene's size (the plume is placed and sized in
// fractions of the bounds), so the smoke's optical depth is scene-independent too.
inline constexpr double kHazeOpticalDepth = 0.336;
inline constexpr double kParticleOpticalDepth = 0.14;
float mediumLength(const Scene& scene);  // the scene's largest extent (m)

// The probed pixel's ray, one RaySample per march sample (its visualiser plots and checks them).
inline constexpr Semantic kRaySamples{"volumetric-ray"};

// definesVoxelSpace: the density grid is the technique's voxel space (the viewer places the
// particles' and the ray record's voxel coordinates in it); false when appended to a technique
// that has its own (volumetric.h).
class DensityStage : public Stage {
 public:
  explicit DensityStage(bool definesVoxelSpace = true) : definesVoxelSpace_(definesVoxelSpace) {}
  const char* id() const override { return "density"; }
  const char* title() const override { return "Deposit smoke particles into a density grid"; }
  const char* summary() const override {
    return "Each particle of a rising smoke plume adds 1 to its voxel's count with an integer atomic; the "
           "counts times the scattering per particle give the scattering coefficient the march samples.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;

 private:
  bool definesVoxelSpace_;
};

class PhaseStage : public Stage {
 public:
  const char* id() const override { return "phase"; }
  const char* title() const override { return "The phase function for the current g"; }
  const char* summary() const override {
    return "Sample and plot Henyey-Greenstein p(mu) with the thesis' (1-g)^2 version beside it; the "
           "statistics print each one's integral over the sphere (HG: 1; thesis: (1-g)/(1+g)).";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class MarchStage : public Stage {
 public:
  const char* id() const override { return "march"; }
  const char* title() const override { return "Ray march the single scattering"; }
  const char* summary() const override {
    return "From the camera to the surface, one sample per iteration: shadow test, scattering from the "
           "density, phase, transmittance and step length. Dithered start offsets trade banding for noise.";
  }
  void declare(StageBuilder& b) const override;
  int iterations(const ParamSet& params) const override;
  void execute(StageContext& ctx) override;
};

class BlurStage : public Stage {
 public:
  const char* id() const override { return "blur"; }
  const char* title() const override { return "Bilateral blur of the dither noise"; }
  const char* summary() const override {
    return "Average neighbouring marched pixels on the same surface (a 4-pixel period kernel, x then y), so "
           "the 16 dither offsets of each 4x4 tile blend into one smooth estimate.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class UpsampleStage : public Stage {
 public:
  const char* id() const override { return "upsample"; }
  const char* title() const override { return "Bilateral upsampling to full resolution"; }
  const char* summary() const override {
    return "Interpolate the marched image to every pixel, weighting samples by how close their surface is "
           "to the pixel's, so light does not bleed across depth edges.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

// surfaceInput: "" composes over this technique's own direct light; the name of another
// technique's image resource (e.g. vct-grid's "combined") composes over that image instead,
// when the volumetric stages are appended to that technique's stages (volumetric.h).
class ComposeStage : public Stage {
 public:
  explicit ComposeStage(std::string surfaceInput = "") : surfaceInput_(std::move(surfaceInput)) {}
  const char* id() const override { return "compose"; }
  const char* title() const override { return "Compose the medium over the surfaces"; }
  const char* summary() const override {
    return "Surface radiance times the transmittance in front of it, plus the in-scattered light; tonemapped.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;

 private:
  std::string surfaceInput_;
};

}  // namespace voxlab::volumetric
