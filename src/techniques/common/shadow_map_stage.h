// ShadowMapStage: depth from the light LightStage wrote (the scene's first light after the
// light.0.* parameters; add LightStage before this stage), and the
// light's parameters as a uniform buffer ("light") that later stages shade with.
//
// Spot lights get a perspective shadow map covering their outer cone, directional lights an
// orthographic one fitted to the scene's bounds seen from the light; point lights are shaded without a shadow map (the
// manifest says so in the stage's statistics).
#pragma once
#include "graph/stage.h"

namespace voxlab {

class ShadowMapStage : public Stage {
 public:
  const char* id() const override { return "shadow-map"; }
  const char* title() const override { return "Shadow map from the light"; }
  const char* summary() const override {
    return "Render the scene's depth from the light, so injection and shading can tell lit from shadowed points.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

}  // namespace voxlab
