// RsmStage: a reflective shadow map of the scene's light (Dachsbacher and Stamminger 2005; seed
// 000 section 2.2): per texel of the light's view, the surface it sees, its normal (turned toward
// the light) and what it reflects of the direct light. Shared by every technique that gathers
// one-bounce light from the light's view (near-field here; lpv and lrsm can read the same).
//
// It renders the views of the "light" uniform buffer that ShadowMapStage writes, so it follows the
// shared light model: spot lights perspective over the outer cone, directional lights
// orthographic over the scene, point lights six cube faces in a 3 x 2 atlas (lightMapFace and
// lightMapCoord in shaders/common/lights.glsl find a point's texel in every case).
//
// Outputs, per texel (empty texels are all zero):
//   rsm-position  xyz world position, w = the texel's footprint on the surface in metres
//                 (max edge of the parallelogram one texel covers; includes the 1/cos stretch)
//   rsm-normal    unit normal on the lit side, w = 1 where the texel sees a surface
//   rsm-radiance  reflected radiance of the direct light, albedo/pi * E * cos (Lambertian), W/(m^2 sr)
//   rsm-flux      reflected flux through the texel, albedo * E * cos * area (W): what a virtual
//                 point light at the texel emits (LPV-style injection)
// Texels see the first surface from the light, so they are lit by construction (no shadow test).
#pragma once
#include "graph/stage.h"

namespace voxlab {

class RsmStage : public Stage {
 public:
  const char* id() const override { return "rsm"; }
  const char* title() const override { return "Reflective shadow map"; }
  const char* summary() const override {
    return "Render the scene from the light: position, normal and the reflected radiance and flux of "
           "the directly lit surface in every texel.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

}  // namespace voxlab
