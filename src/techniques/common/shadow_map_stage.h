// ShadowMapStage: depth from the light LightStage wrote (the scene's first light after the
// light.0.* parameters; add LightStage before this stage), and the
// light's parameters as a uniform buffer ("light") that later stages shade with.
//
// Spot lights get a perspective shadow map covering their outer cone, directional lights an
// orthographic one fitted to the scene's bounds seen from the light, point lights six 90-degree
// views, one per cube face, in a 3 x 2 atlas of the same map (shaders/common/lights.glsl reads it).
#pragma once
#include <array>
#include <functional>

#include <glm/glm.hpp>

#include "common/shared.h"
#include "graph/stage.h"

namespace voxlab {

// World -> clip space of a point light's six cube faces (+x -x +y -y +z -z), 90 degrees each.
std::array<glm::mat4, 6> pointLightFaceViewProj(glm::vec3 position, float far);

// Calls 'draw' once per view of the light's maps with the viewport of a width x height map set:
// the whole map for a spot or directional light, each face's tile for a point light.
void forEachLightMapView(const gpu::GpuLight& light, int width, int height,
                         const std::function<void(const glm::mat4& viewProj)>& draw);

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
