#include "techniques/common/rsm_stage.h"
#include "graph/scene_inputs.h"

#include <cstring>
#include <utility>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "scene/gpu_scene.h"
#include "techniques/common/light_stage.h"
#include "techniques/common/shadow_map_stage.h"

namespace voxlab {

// The light-space images at rsm.resolution: position and flux RGBA32F, normal and radiance
// RGBA16F. Used by declare() and execute().
static TextureDesc rsmDesc(int size, GLenum format) {
  TextureDesc d;
  d.size = {size, size, 1};
  d.minFilter = d.magFilter = GL_NEAREST;
  d.format = format;
  return d;
}

void RsmStage::declare(StageBuilder& b) const {
  b.read(kSceneGeometryInput);  // rasterizes the scene's triangles from the light
  b.param(ParamDesc::integer("rsm.resolution", 512, 64, 4096, "reflective shadow map width and height", "px").pow2());
  b.read("light");
  b.read(kSceneLightsInput);  // the light's type: the program is built for it (lightKindDefines)
  b.output("rsm-position", OutputKind::Image2D, Semantic::Scalar,
           "world position seen from the light (xyz), w = texel footprint on the surface (m), 0 = empty");
  b.output("rsm-normal", OutputKind::Image2D, Semantic::Normal, "unit normal on the lit side, w = 1 where covered");
  b.output("rsm-radiance", OutputKind::Image2D, Semantic::RadianceHDR,
           "reflected radiance of the direct light: albedo / pi * irradiance");
  b.output("rsm-flux", OutputKind::Image2D, Semantic::RadianceHDR,
           "reflected flux per texel (W): albedo * irradiance * texel area on the surface").alongside = true;
  for (auto [name, format] : {std::pair<const char*, GLenum>{"rsm-position", GL_RGBA32F},
                              {"rsm-normal", GL_RGBA16F}, {"rsm-radiance", GL_RGBA16F}, {"rsm-flux", GL_RGBA32F}})
    b.texture(name, [format = format](const ParamSet& p, const ViewState&) {
      return rsmDesc(p.getInt("rsm.resolution"), format);
    });
}

void RsmStage::execute(StageContext& ctx) {
  const int size = ctx.params.getInt("rsm.resolution");
  gpu::GpuLight light{};
  auto bytes = ctx.board.buffer("light").download(sizeof(light));
  std::memcpy(&light, bytes.data(), sizeof(light));
  const bool hasMap = light.spot.w > 0.5f;

  Texture& position = ctx.board.ensureTexture("rsm-position", rsmDesc(size, GL_RGBA32F));
  Texture& normal = ctx.board.ensureTexture("rsm-normal", rsmDesc(size, GL_RGBA16F));
  Texture& radiance = ctx.board.ensureTexture("rsm-radiance", rsmDesc(size, GL_RGBA16F));
  Texture& flux = ctx.board.ensureTexture("rsm-flux", rsmDesc(size, GL_RGBA32F));
  TextureDesc depthDesc = rsmDesc(size, GL_RGBA32F);
  depthDesc.format = GL_DEPTH_COMPONENT32F;
  Texture depth("rsm.depth", depthDesc);
  Framebuffer fb("rsm.fbo");
  fb.attach(GL_COLOR_ATTACHMENT0, position);
  fb.attach(GL_COLOR_ATTACHMENT1, normal);
  fb.attach(GL_COLOR_ATTACHMENT2, radiance);
  fb.attach(GL_COLOR_ATTACHMENT3, flux);
  fb.attach(GL_DEPTH_ATTACHMENT, depth);
  fb.setDrawBuffers(4);
  fb.checkComplete();
  const float zero[4] = {0, 0, 0, 0};
  const float far = 1.0f;
  for (int i = 0; i < 4; ++i) glClearNamedFramebufferfv(fb.id(), GL_COLOR, i, zero);
  glClearNamedFramebufferfv(fb.id(), GL_DEPTH, 0, &far);
  if (hasMap) {
    glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
    glBindFramebuffer(GL_FRAMEBUFFER, fb.id());
    glEnable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    forEachLightMapView(light, size, size, [&](const glm::mat4& viewProj) {
      ctx.gpuScene.draw([&](const std::string& kind) {  // a program per material kind
        GLuint program =
            ctx.shaders.program({"common/camera.vert.glsl", "common/rsm.frag.glsl"}, kind + lightKindDefines(ctx.scene));
        setUniform(program, "u_viewProj", viewProj);
        return program;
      }, ctx.scene.draws);
    });
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }
  ctx.stats["has_map"] = hasMap ? 1 : 0;
  ctx.stats["texels"] = double(size) * size;
}

}  // namespace voxlab
