// LightStage: the scene's first light as parameters (light.0.*), the one owner of the light that
// every light-reading stage depends on through the resource it writes ("light-source").
//
// Design: declarations are static per technique while the number of lights depends on the scene,
// so there is one fixed slot, light.0, that edits the scene's first light (every scene has one:
// the loader adds a default sun to a scene without lights). Each light.0.* parameter defaults to
// "scene" (ParamDesc::fromScene): the value the loaded scene gives; a number overrides it. A
// change re-runs this stage and, through the read/write graph, the shadow map, the injection and
// what follows them, never the voxelization (which does not read the light).
#pragma once
#include <string>

#include "graph/stage.h"
#include "scene/scene.h"

namespace voxlab {

// The light after the light.0.* overrides in 'params' (those not "scene") are applied to
// 'sceneLight'. Azimuth/elevation set the direction of directional and spot lights (see
// sunDirection in scene/scene.h); x/y/z the position of point and spot lights.
Light applyLightParams(const Light& sceneLight, const ParamSet& params);
// The parameter names, e.g. "light.0.azimuth".
inline constexpr const char* kLightAzimuth = "light.0.azimuth";
inline constexpr const char* kLightElevation = "light.0.elevation";

// The blackboard record "light-source" holds (a CPU-side copy: stages read it with lightSource()).
struct LightSourceRecord {
  int32_t type = 0;  // LightType
  float intensity = 1.0f, range = 0.0f, innerConeAngle = 0.0f, outerConeAngle = 0.0f;
  float position[3] = {0, 0, 0}, direction[3] = {0, -1, 0}, color[3] = {1, 1, 1};
};
Light lightSource(Blackboard& board);  // the light the "light-source" resource holds
// The defines of a program built for the type of the scene's light (the light.0.* parameters
// never change it; shaders/common/lights.glsl, lightType()): "#define VOXLAB_LIGHT_KIND" and the
// type's VOXLAB_LIGHT_* value, so that the code of the other types is compiled out. A stage that
// uses it reads kSceneLightsInput.
std::string lightKindDefines(const Scene& scene);

class LightStage : public Stage {
 public:
  const char* id() const override { return "light"; }
  const char* title() const override { return "The light"; }
  const char* summary() const override {
    return "Take the scene's first light (or the default sun) and apply the light.0.* parameters: direction, "
           "position, colour, intensity, cone angles.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

}  // namespace voxlab
