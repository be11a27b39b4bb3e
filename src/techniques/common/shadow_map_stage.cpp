#include "techniques/common/shadow_map_stage.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "scene/gpu_scene.h"

namespace voxlab {

static TextureDesc shadowMapDesc(int size) {
  TextureDesc d;
  d.format = GL_DEPTH_COMPONENT32F;
  d.size = {size, size, 1};
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}

void ShadowMapStage::declare(StageBuilder& b) const {
  b.param(ParamDesc::integer("shadow.resolution", 1024, 128, 4096, "shadow map width and height", "px").pow2());
  b.param(ParamDesc::real("shadow.normal-offset", 0.01, 0.0, 0.2,
                          "receivers are moved this far along their normal before the shadow test", "m"));
  b.write("light");
  b.output("shadow-map", OutputKind::Image2D, Semantic::Depth, "depth seen from the light (0 near, 1 far)");
  b.texture("shadow-map", [](const ParamSet& p, const ViewState&) { return shadowMapDesc(p.getInt("shadow.resolution")); });
}

void ShadowMapStage::execute(StageContext& ctx) {
  const int size = ctx.params.getInt("shadow.resolution");
  const Scene& scene = ctx.scene;
  gpu::GpuLight light{};
  light.spot = glm::vec4(1.0f, 0.0f, ctx.params.getFloat("shadow.normal-offset"), 0.0f);
  glm::vec3 center = scene.bounds.center();
  float radius = 0.5f * glm::length(scene.bounds.extent()) + 1e-3f;
  bool hasShadow = false;
  if (!scene.lights.empty()) {
    const Light& L = scene.lights[0];
    light.radiance = glm::vec4(L.color * L.intensity, 0.0f);
    light.directionRange = glm::vec4(glm::normalize(L.direction), L.range);
    glm::vec3 dir = glm::normalize(L.direction);
    glm::vec3 up = std::abs(dir.y) > 0.99f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
    if (L.type == LightType::Directional) {
      light.positionType = glm::vec4(center - dir * radius * 2.0f, VOXLAB_LIGHT_DIRECTIONAL);
      glm::mat4 view = glm::lookAt(center - dir * radius * 2.0f, center, up);
      glm::mat4 proj = glm::ortho(-radius, radius, -radius, radius, radius * 0.5f, radius * 3.5f);
      light.shadowViewProj = proj * view;
      hasShadow = true;
    } else if (L.type == LightType::Spot) {
      light.positionType = glm::vec4(L.position, VOXLAB_LIGHT_SPOT);
      light.spot.x = std::cos(L.innerConeAngle);
      light.spot.y = std::cos(L.outerConeAngle);
      float fov = std::min(2.0f * L.outerConeAngle + 0.05f, 3.0f);
      float far = glm::length(L.position - center) + radius;
      glm::mat4 view = glm::lookAt(L.position, L.position + dir, up);
      glm::mat4 proj = glm::perspective(fov, 1.0f, std::max(far * 1e-3f, 1e-3f), far);
      light.shadowViewProj = proj * view;
      hasShadow = true;
    } else {
      light.positionType = glm::vec4(L.position, VOXLAB_LIGHT_POINT);
    }
  }
  light.spot.w = hasShadow ? 1.0f : 0.0f;
  ctx.stats["shadowed"] = hasShadow ? 1 : 0;
  ctx.stats["lights_in_scene"] = double(scene.lights.size());

  Buffer& ubo = ctx.board.ensureBuffer("light", sizeof(gpu::GpuLight));
  ubo.upload(&light, sizeof(light));

  Texture& depth = ctx.board.ensureTexture("shadow-map", shadowMapDesc(size));
  Framebuffer fb("shadow-map.fbo");
  fb.attach(GL_DEPTH_ATTACHMENT, depth);
  fb.setDrawBuffers(0);
  fb.checkComplete();
  const float far = 1.0f;
  glClearNamedFramebufferfv(fb.id(), GL_DEPTH, 0, &far);
  if (hasShadow) {
    GLuint program = ctx.shaders.program({"common/camera.vert.glsl", "common/depth_only.frag.glsl"});
    setUniform(program, "u_viewProj", light.shadowViewProj);
    glBindFramebuffer(GL_FRAMEBUFFER, fb.id());
    glViewport(0, 0, size, size);
    glEnable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    ctx.gpuScene.draw(program);
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }
}

}  // namespace voxlab
