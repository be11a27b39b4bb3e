#include "techniques/common/shadow_map_stage.h"
#include "graph/scene_inputs.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "scene/gpu_scene.h"
#include "techniques/common/light_stage.h"

namespace voxlab {

std::array<glm::mat4, 6> pointLightFaceViewProj(glm::vec3 position, float far) {
  static const glm::vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  // Near a fixed fraction of far, as for a spot: the depth distribution does not depend on the unit.
  const glm::mat4 proj = glm::perspective(glm::half_pi<float>(), 1.0f, far * 1e-3f, far);
  std::array<glm::mat4, 6> out;
  for (int f = 0; f < 6; ++f) {
    const glm::vec3 up = f == 2 || f == 3 ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
    out[size_t(f)] = proj * glm::lookAt(position, position + axes[f], up);
  }
  return out;
}

void forEachLightMapView(const gpu::GpuLight& light, int width, int height,
                         const std::function<void(const glm::mat4& viewProj)>& draw) {
  if (light.positionType.w != VOXLAB_LIGHT_POINT) {
    glViewport(0, 0, width, height);
    draw(light.shadowViewProj);
    return;
  }
  const int tileW = width / 3, tileH = height / 2;
  for (int f = 0; f < 6; ++f) {
    glViewport((f % 3) * tileW, (f / 3) * tileH, tileW, tileH);
    draw(light.faceViewProj[f]);
  }
}

static TextureDesc shadowMapDesc(int size) {
  TextureDesc d;
  d.format = GL_DEPTH_COMPONENT32F;
  d.size = {size, size, 1};
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}

void ShadowMapStage::declare(StageBuilder& b) const {
  b.read(kSceneGeometryInput);  // rasterizes the scene's triangles from the light
  b.param(ParamDesc::integer("shadow.resolution", 1024, 128, 4096, "shadow map width and height", "px").pow2());
  // 1.5 texels: the 3x3 PCF's taps lie up to 1.5 texels beside the receiver. Measured with
  // vct-grid's direct image against the reference tracer (512^2): Cornell box rmse 0.0129 /
  // 0.0139 / 0.0152 at 1 / 1.5 / 2 texels, but below 1.5 acne stripes the tall block's face that
  // the spot grazes; Sponza 0.0315 / 0.0329 / - (0.0310 with the former half texel, which left
  // acne on the floor of tests/unit/test_directional_light.cpp's sun at 19 degrees: with the
  // offset scaled by the slope, 1 of the 9 taps failed there).
  b.param(ParamDesc::real("shadow.normal-offset", 1.5, 0.0, 8.0,
                          "receivers are moved along their normal before the shadow test by this many shadow-map "
                          "texels at the receiver (follows the map's resolution and the scene's size; no absolute "
                          "length)",
                          "texels"));
  b.read("light-source");  // the light (techniques/common/light_stage.h), after light.0.* overrides
  b.write("light");
  b.output("shadow-map", OutputKind::Image2D, Semantic::Depth, "depth seen from the light (0 near, 1 far)");
  b.texture("shadow-map", [](const ParamSet& p, const ViewState&) { return shadowMapDesc(p.getInt("shadow.resolution")); });
}

void ShadowMapStage::execute(StageContext& ctx) {
  const int size = ctx.params.getInt("shadow.resolution");
  const Scene& scene = ctx.scene;
  gpu::GpuLight light{};
  // spot.z: the normal offset per unit of the receiver's clip w (shaders/common/lights.glsl
  // multiplies by it): an orthographic map's texel is the same everywhere (w = 1), a perspective
  // map's grows with the view depth w. Both follow the scene's size, never an absolute length.
  const float offsetTexels = ctx.params.getFloat("shadow.normal-offset");
  light.spot = glm::vec4(1.0f, 0.0f, 0.0f, 0.0f);
  glm::vec3 center = scene.bounds.center();
  // Every length here is relative to the scene's size, so the picture does not depend on its unit.
  float radius = std::max(0.5f * glm::length(scene.bounds.extent()), 1e-20f) * 1.001f;
  bool hasShadow = false;
  {
    const Light L = lightSource(ctx.board);
    light.radiance = glm::vec4(L.color * L.intensity, 0.0f);
    light.directionRange = glm::vec4(glm::normalize(L.direction), L.range);
    glm::vec3 dir = glm::normalize(L.direction);
    glm::vec3 up = std::abs(dir.y) > 0.99f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
    if (L.type == LightType::Directional) {
      // Fitted to the part of the voxel volume that holds geometry: the light-space box of the
      // scene's bounds (the volume contains them), grown by 1% so that surfaces on the bounds
      // stay inside. For Sponza: 26 x 41 m instead of the bounding sphere's 47 x 47 m.
      glm::vec3 eye = center - dir * radius * 2.0f;
      // Up: the world axis most perpendicular to the light, so the map's axes follow the box's.
      glm::vec3 a = glm::abs(dir);
      glm::vec3 boxUp = a.x <= a.y && a.x <= a.z ? glm::vec3(1, 0, 0) : (a.y <= a.z ? glm::vec3(0, 1, 0) : glm::vec3(0, 0, 1));
      glm::mat4 view = glm::lookAt(eye, center, boxUp);
      glm::vec3 lo(1e30f), hi(-1e30f);
      for (int k = 0; k < 8; ++k) {
        glm::vec3 corner((k & 1) ? scene.bounds.max.x : scene.bounds.min.x, (k & 2) ? scene.bounds.max.y : scene.bounds.min.y,
                         (k & 4) ? scene.bounds.max.z : scene.bounds.min.z);
        glm::vec3 v = glm::vec3(view * glm::vec4(corner, 1.0f));
        lo = glm::min(lo, v);
        hi = glm::max(hi, v);
      }
      glm::vec3 pad = 0.01f * (hi - lo) + glm::vec3(1e-6f * radius);  // the second term: flat scenes
      lo -= pad;
      hi += pad;
      light.positionType = glm::vec4(eye, VOXLAB_LIGHT_DIRECTIONAL);
      // View space looks down -z: near and far are the negated z range.
      glm::mat4 proj = glm::ortho(lo.x, hi.x, lo.y, hi.y, -hi.z, -lo.z);
      light.shadowViewProj = proj * view;
      ctx.stats["shadow_extent_x_m"] = hi.x - lo.x;
      ctx.stats["shadow_extent_y_m"] = hi.y - lo.y;
      // An orthographic texel has one world size everywhere (the larger of its two sides).
      const float texel = std::max(hi.x - lo.x, hi.y - lo.y) / float(size);
      light.spot.z = offsetTexels * texel;
      ctx.stats["texel_m"] = texel;
      ctx.stats["normal_offset_m"] = light.spot.z;
      hasShadow = true;
    } else if (L.type == LightType::Spot) {
      light.positionType = glm::vec4(L.position, VOXLAB_LIGHT_SPOT);
      light.spot.x = std::cos(L.innerConeAngle);
      light.spot.y = std::cos(L.outerConeAngle);
      float fov = std::min(2.0f * L.outerConeAngle + 0.05f, 3.0f);
      float far = glm::length(L.position - center) + radius;
      glm::mat4 view = glm::lookAt(L.position, L.position + dir, up);
      // Near plane a fixed fraction of the far one (no absolute floor): the map's depth
      // distribution, and so the picture, is the same for the scene in any unit.
      glm::mat4 proj = glm::perspective(fov, 1.0f, far * 1e-3f, far);
      light.shadowViewProj = proj * view;
      // A texel at view depth w spans 2 w tan(fov / 2) / size.
      const float texelPerDepth = 2.0f * std::tan(0.5f * fov) / float(size);
      light.spot.z = offsetTexels * texelPerDepth;
      ctx.stats["texel_per_depth"] = texelPerDepth;
      hasShadow = true;
    } else {
      // Six 90-degree views, one per cube face, in a 3 x 2 atlas of the map (lightMapTile in
      // shaders/common/lights.glsl); far reaches the scene's farthest corner.
      light.positionType = glm::vec4(L.position, VOXLAB_LIGHT_POINT);
      const float far = glm::length(L.position - center) + radius;
      const auto faces = pointLightFaceViewProj(L.position, far);
      for (int f = 0; f < 6; ++f) light.faceViewProj[f] = faces[size_t(f)];
      // A face's texel at view depth w spans 2 w / (tile texels); the tile is size / 3 wide.
      const float texelPerDepth = 2.0f / float(size / 3);
      light.spot.z = offsetTexels * texelPerDepth;
      ctx.stats["texel_per_depth"] = texelPerDepth;
      hasShadow = true;
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
    glBindFramebuffer(GL_FRAMEBUFFER, fb.id());
    glEnable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    forEachLightMapView(light, size, size, [&](const glm::mat4& viewProj) {
      // A program per material kind: a material without alpha mask has no fragment code to run.
      ctx.gpuScene.draw([&](const std::string& kind) {
        GLuint program = ctx.shaders.program({"common/camera.vert.glsl", "common/depth_only.frag.glsl"}, kind);
        setUniform(program, "u_viewProj", viewProj);
        return program;
      }, ctx.scene.draws);
    });
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }
}

}  // namespace voxlab
