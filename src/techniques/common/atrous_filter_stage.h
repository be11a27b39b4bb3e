// The edge-aware a-trous wavelet filter of Dammertz et al. 2010, written once for the techniques
// that estimate indirect light from a few random rays per pixel (near-field, voxel-path-tracing)
// or from a pattern that varies over a tile of pixels (lrsm's interleaved step phases):
// passes of the 5-tap B3 spline with holes 1, 2, 4, ... traced pixels, each tap weighted by
// edge-stopping functions of the G-buffer (distance from the centre's plane: depth along its
// normal; normal difference), normalised by the weights. The number of passes follows the number
// of rays per pixel: the fewest whose kernel averages filter.samples rays (fewer rays, a wider
// kernel), unless filter.passes fixes it. The unfiltered image stays an output of the stage that
// traced it; this stage's output is the filtered one. Shader: shaders/common/atrous_filter.comp.glsl.
#pragma once
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "graph/param.h"
#include "graph/stage.h"
#include "scene/scene.h"
#include "techniques/common/traced_image.h"

namespace voxlab {

struct AtrousFilterConfig {
  std::string source = "indirect";             // the noisy image (written by an earlier stage)
  std::string output = "indirect-filtered";    // the filtered image
  std::string referenceMode = "indirect";      // what the filtered image approximates (OutputDesc::referenceMode)
  std::string raysParam;                       // the integer parameter holding the rays per pixel ("rays.count")
  int raysPerPixel = 1;                        // the rays per pixel where raysParam is empty (a fixed count)
  TracedImages traced = kTracedRays;           // the resolution the source is traced at
  std::vector<ParamDesc> sharedParams;         // parameters depthScale reads, declared by other stages too
  // Metres: the depth scale of the edge-stopping function (a neighbour this far off the centre's
  // plane keeps exp(-1) of its weight).
  std::function<float(const ParamSet&, const Scene&)> depthScale;
};

// Effective number of pixels the equivalent kernel of 'passes' B3 a-trous passes averages in 2D
// (1 / sum of squared weights) on a flat surface with no edge: 1 for 0 passes, 13.4 for 1, 65.6 for
// 2, 274.5 for 3, 1110 for 4.
double atrousEffectivePixels(int passes);
// The fewest passes (at most 'maxPasses') whose effective pixels times 'raysPerPixel' reach 'samples'.
int atrousPassesFor(double samples, int raysPerPixel, int maxPasses);

class AtrousFilterStage : public Stage {
 public:
  explicit AtrousFilterStage(AtrousFilterConfig config) : config_(std::move(config)) {}
  const char* id() const override { return "filter"; }
  const char* title() const override { return "Edge-aware a-trous filter"; }
  const char* summary() const override {
    return "Average the noisy indirect light over neighbours on the same surface: a-trous wavelet passes (Dammertz "
           "et al. 2010) with holes 1, 2, 4, ... pixels, each tap weighted by depth off the centre's plane and normal "
           "difference; as many passes as the rays per pixel need. One pass per iteration; 0 passes copies.";
  }
  void declare(StageBuilder& b) const override;
  int iterations(const ParamSet& params) const override;
  void execute(StageContext& ctx) override;
  int passes(const ParamSet& params) const;
  int raysPerPixel(const ParamSet& params) const;

 private:
  AtrousFilterConfig config_;
};

}  // namespace voxlab
