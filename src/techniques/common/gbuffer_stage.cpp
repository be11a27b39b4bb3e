#include "techniques/common/gbuffer_stage.h"
#include "graph/scene_inputs.h"

#include <utility>

#include "gpu/shader_library.h"
#include "scene/gpu_scene.h"

namespace voxlab {

static TextureDesc screenDesc(const ViewState& view, GLenum format) {
  TextureDesc d;
  d.format = format;
  d.size = {view.width, view.height, 1};
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}

void GBufferStage::declare(StageBuilder& b) const {
  b.read(kSceneGeometryInput);  // rasterizes the scene's triangles
  b.readView();
  b.output("position", OutputKind::Image2D, Semantic::Scalar, "world position of the visible surface (xyz), w = 1 where covered");
  b.output("normal", OutputKind::Image2D, Semantic::Normal, "unit normal facing the camera");
  b.output("albedo", OutputKind::Image2D, Semantic::Color, "Lambertian albedo (base colour)");
  b.output("emission", OutputKind::Image2D, Semantic::RadianceHDR, "emitted radiance");
  b.output("depth", OutputKind::Image2D, Semantic::Depth, "depth buffer (0 near, 1 far)").alongside = true;
  const std::pair<const char*, GLenum> images[] = {{"position", GL_RGBA32F}, {"normal", GL_RGBA16F},
                                                   {"albedo", GL_RGBA8}, {"emission", GL_RGBA16F},
                                                   {"depth", GL_DEPTH_COMPONENT32F}};
  for (const auto& [name, format] : images)
    b.texture(name, [format = format](const ParamSet&, const ViewState& v) { return screenDesc(v, format); });
}

void GBufferStage::execute(StageContext& ctx) {
  Texture& position = ctx.board.ensureTexture("position", screenDesc(ctx.view, GL_RGBA32F));
  Texture& normal = ctx.board.ensureTexture("normal", screenDesc(ctx.view, GL_RGBA16F));
  Texture& albedo = ctx.board.ensureTexture("albedo", screenDesc(ctx.view, GL_RGBA8));
  Texture& emission = ctx.board.ensureTexture("emission", screenDesc(ctx.view, GL_RGBA16F));
  Texture& depth = ctx.board.ensureTexture("depth", screenDesc(ctx.view, GL_DEPTH_COMPONENT32F));
  Framebuffer fb("gbuffer.fbo");
  fb.attach(GL_COLOR_ATTACHMENT0, position);
  fb.attach(GL_COLOR_ATTACHMENT1, normal);
  fb.attach(GL_COLOR_ATTACHMENT2, albedo);
  fb.attach(GL_COLOR_ATTACHMENT3, emission);
  fb.attach(GL_DEPTH_ATTACHMENT, depth);
  fb.setDrawBuffers(4);
  fb.checkComplete();
  const float zero[4] = {0, 0, 0, 0};
  const float far = 1.0f;
  for (int i = 0; i < 4; ++i) glClearNamedFramebufferfv(fb.id(), GL_COLOR, i, zero);
  glClearNamedFramebufferfv(fb.id(), GL_DEPTH, 0, &far);
  glBindFramebuffer(GL_FRAMEBUFFER, fb.id());
  glViewport(0, 0, ctx.view.width, ctx.view.height);
  glEnable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  ctx.gpuScene.draw([&](const std::string& kind) {  // a program per material kind: no texture it lacks
    GLuint program = ctx.shaders.program({"common/camera.vert.glsl", "common/gbuffer.frag.glsl"}, kind);
    setUniform(program, "u_viewProj", ctx.view.viewProjection());
    setUniform(program, "u_cameraPos", ctx.view.position);
    return program;
  }, ctx.scene.draws);
  glDisable(GL_DEPTH_TEST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  ctx.board.setRenderedCamera({ctx.view.position, ctx.view.view, ctx.view.projection});  // the overlays' camera
}

}  // namespace voxlab
