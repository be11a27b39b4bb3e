// The stages of lrsm after the shared ones (lrsm.cpp has the overview, lrsm.h the decisions).
#pragma once
#include "graph/output.h"
#include "graph/stage.h"
#include "techniques/common/atrous_filter_stage.h"
#include "techniques/common/composite_stage.h"
#include "techniques/lrsm/lrsm.h"

namespace voxlab {
struct Scene;
class Blackboard;
}  // namespace voxlab

namespace voxlab::lrsm {

// Semantics of the layered data (visualisers in src/techniques/lrsm/views/lrsm_*.cpp).
inline constexpr Semantic kLayerRadiance{"lrsm-layer-radiance"};  // atlas of n layers: rgb = A*R, a = alpha
inline constexpr Semantic kLayerNormal{"lrsm-layer-normal"};      // atlas: xyz = alpha * n, w = alpha
inline constexpr Semantic kLayerDepth{"lrsm-layer-depth"};        // atlas: alpha * z'^k, k = 1..4 (alpha: the normal's .w)
inline constexpr Semantic kLayerId{"lrsm-layer-id"};              // per RSM texel: layer id, 255 = empty
inline constexpr Semantic kGatherRecords{"lrsm-gather"};          // LrsmGatherRecord[] of the probed pixel

// The layer layout of the current light and scene from the parameters (zNear, zFar from the
// scene's bounds seen from the light: planar for a directional light, radial for a spot).
LayerLayout layoutFor(const Scene& scene, Blackboard& board, const ParamSet& params);
// Levels of an LRSM chain whose base is 'width' texels per layer: log2(width) + 1.
int lrsmLevels(int width);

class OcclusionVoxelsStage : public Stage {
 public:
  const char* id() const override { return "occlusion-voxels"; }
  const char* title() const override { return "Binary occlusion voxels"; }
  const char* summary() const override {
    return "Write 1 into an R8 3D texture (1 byte per voxel) for every voxel of the conservative fragment list: "
           "occupancy only, no colour; every writer writes the same value, so no atomics.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class OcclusionMipsStage : public Stage {
 public:
  const char* id() const override { return "occlusion-mips"; }
  const char* title() const override { return "Isotropic occlusion mips"; }
  const char* summary() const override {
    return "Copy the base, then each level is the mean of the 8 children below it (filtered occupancy alpha). "
           "One level per iteration.";
  }
  void declare(StageBuilder& b) const override;
  int iterations(const ParamSet& params) const override;
  void execute(StageContext& ctx) override;
};

class LayersStage : public Stage {
 public:
  const char* id() const override { return "layers"; }
  const char* title() const override { return "Layer assignment and depth warp"; }
  const char* summary() const override {
    return "One thread per 2x2 RSM block: each texel's layer from static depth and <n.l> partitions, texels of a "
           "layer merged, depth warped into the layer's range, z and z^2 stored premultiplied by coverage.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class LrsmMipsStage : public Stage {
 public:
  const char* id() const override { return "lrsm-mips"; }
  const char* title() const override { return "LRSM mips"; }
  const char* summary() const override {
    return "Box-filter every layer's radiance, normal and moments, and sum the layers' coverage. One level per "
           "iteration.";
  }
  void declare(StageBuilder& b) const override;
  int iterations(const ParamSet& params) const override;
  void execute(StageContext& ctx) override;
};

class ConeGatherStage : public Stage {
 public:
  const char* id() const override { return "cone-gather"; }
  const char* title() const override { return "Cone gathering"; }
  const char* summary() const override {
    return "Per pixel 6 diffuse cones (60 deg), 1 specular (10 deg) and a shadow cone march sphere samples: "
           "alpha from the occlusion mips, L from the layers whose depth range holds the sample (Algorithm 1: "
           "back-face test, Gaussian visibility, overlap falloff), composited front to back.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

// The terms of this technique's composite (techniques/common/composite_stage.h).
CompositeTerms compositeTerms();
AtrousFilterConfig filterConfig();

}  // namespace voxlab::lrsm
