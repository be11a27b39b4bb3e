// GBufferStage: the visible surface per pixel from the camera (position, normal, albedo,
// emission, depth). Shared by every technique that shades or marches per pixel (vct-grid's cone
// tracing and composite, volumetric's ray march and compose).
#pragma once
#include "graph/stage.h"

namespace voxlab {

class GBufferStage : public Stage {
 public:
  const char* id() const override { return "gbuffer"; }
  const char* title() const override { return "G-buffer from the camera"; }
  const char* summary() const override {
    return "Rasterize the visible surface per pixel: position, normal, albedo, emission and depth.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

}  // namespace voxlab
