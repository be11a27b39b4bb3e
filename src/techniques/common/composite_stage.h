// The composite every technique ends with, written once: direct light (Lambert, shadowed by the
// shadow map or by a traced visibility image) plus emission, plus each indirect term times its
// weight, in linear radiance ("combined"); then exposure and the Reinhard operator x / (1 + x)
// ("final"). The probed pixel (probe.x, probe.y: a screen probe) is recorded step by step in the
// "probe-chain" output (Semantic::ProbeChain), one field per step with its unit, the terms named
// by their images and weights. A technique declares its terms (CompositeTerms: which images, weighed by which
// parameters, traced at which resolution) and adds CompositeStage(terms); the shader is
// shaders/common/composite.comp.glsl.
#pragma once
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "graph/param.h"
#include "graph/stage.h"
#include "scene/scene.h"
#include "techniques/common/traced_image.h"

namespace voxlab {

inline constexpr int kMaxCompositeTerms = 4;  // COMPOSITE_MAX_TERMS in shaders/common/composite.comp.glsl

// One term added to the direct light: the value of parameter 'weight' times image 'image'.
struct CompositeTerm {
  std::string image;   // "indirect-diffuse"
  std::string weight;  // "composite.indirect"
  bool traced = true;  // at the traced resolution (upsampled along surfaces); false: one texel per pixel
};

// The direct light's visibility comes from the shadow map unless the choice parameter 'param' is
// 'tracedOption'; then from the red channel of the traced image 'image' (a soft-shadow cone's).
struct CompositeVisibility {
  std::string param, tracedOption, image;
};

struct CompositeTerms {
  std::string summary;        // the stage's summary
  std::string combinedHelp;   // what the "combined" output holds
  std::vector<ParamDesc> params;  // the stage's parameters in declaration order (composite.exposure, the weights, ...)
  std::vector<CompositeTerm> indirect;  // at most kMaxCompositeTerms, added in this order
  std::optional<CompositeVisibility> visibility;  // none: always the shadow map
  std::optional<TracedImages> traced;  // the resolution of the traced images (none: every image is full size)
  // Metres: a traced pixel farther than this from the shaded pixel's plane gets no weight when
  // upsampling (unused without traced images).
  std::function<float(const ParamSet&, const Scene&)> planeDistance;
  bool sky = true;  // declares sky.radiance (after 'params'): pixels that see no surface show the sky
  // Where probe.y points before a click (fraction of the height from the top); a technique whose
  // other stages declare probe.y declares it with the same default.
  double probeDefaultY = 0.5;
};

// composite.exposure: the scale applied before tonemapping.
ParamDesc compositeExposureParam();
// composite.specular: the weight of a cone tracer's specular term (0 by default: Lambertian materials).
ParamDesc compositeSpecularParam();

class CompositeStage : public Stage {
 public:
  explicit CompositeStage(CompositeTerms terms);
  const char* id() const override { return "composite"; }
  const char* title() const override { return "Composite the final image"; }
  const char* summary() const override { return terms_.summary.c_str(); }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;

 private:
  CompositeTerms terms_;
};

}  // namespace voxlab
