#include "inspect/scene_overlay.h"

#include <chrono>

#include "gpu/shader_library.h"
#include "scene/gpu_scene.h"

namespace voxlab {

namespace {
const glm::vec4 kBoundsColor(1.0f, 0.85f, 0.2f, 1.0f);
}

std::vector<ViewInstance> volumeCubes(const VolumeRGBA& vol, glm::vec3 origin, glm::vec3 texel, size_t limit,
                                      size_t& candidates) {
  candidates = vol.nonEmpty;
  std::vector<ViewInstance> cubes;
  if (vol.nonEmpty > limit) return cubes;
  cubes.reserve(vol.nonEmpty);
  auto alphaAt = [&](glm::ivec3 q) { return vol.rgba[((size_t(q.z) * vol.size.y + q.y) * vol.size.x + q.x) * 4 + 3]; };
  for (int z = 0; z < vol.size.z; ++z)
    for (int y = 0; y < vol.size.y; ++y)
      for (int x = 0; x < vol.size.x; ++x) {
        const uint8_t* p = &vol.rgba[((size_t(z) * vol.size.y + y) * vol.size.x + x) * 4];
        if (p[3] == 0) continue;
        // Faces shared with a non-empty neighbour are never seen: draw only the others.
        int mask = 0;
        glm::ivec3 q(x, y, z);
        for (int f = 0; f < 6; ++f) {
          glm::ivec3 n = q;
          n[f >> 1] += (f & 1) ? 1 : -1;
          bool inside = glm::all(glm::greaterThanEqual(n, glm::ivec3(0))) && glm::all(glm::lessThan(n, vol.size));
          if (!inside || alphaAt(n) == 0) mask |= 1 << f;
        }
        if (mask == 0) continue;
        ViewInstance c;
        c.positionSize = glm::vec4(origin + glm::vec3(x, y, z) * texel, texel.x);
        c.color = glm::vec4(p[0] / 255.0f, p[1] / 255.0f, p[2] / 255.0f, float(mask));
        cubes.push_back(c);
      }
  return cubes;
}

SceneOverlay::SceneOverlay(ShaderLibrary& shaders) : shaders_(shaders) {}

void SceneOverlay::setCubes(const std::vector<ViewInstance>& cubes) {
  cubeCount_ = cubes.size();
  size_t bytes = std::max<size_t>(cubes.size(), 1) * sizeof(ViewInstance);
  if (cubes_.size() < bytes || cubes_.size() > 4 * bytes) cubes_ = Buffer("viewer.overlay.cubes", bytes);
  if (!cubes.empty()) cubes_.upload(cubes.data(), cubes.size() * sizeof(ViewInstance));
}

double SceneOverlay::render(int width, int height, const glm::mat4& viewProj, const GpuScene& scene,
                            const Options& o) {
  auto t0 = std::chrono::steady_clock::now();
  if (width != target_.width || height != target_.height) target_.create("viewer.overlay", width, height, GL_NEAREST);
  target_.begin(glm::vec4(0.0f), width, height);

  if (o.voxels && cubeCount_ > 0) {
    if (!o.xray) {
      // The scene's depth, pushed back a little: a voxel straddles the surface it was made from,
      // and the half in front of it should show.
      GLuint p = shaders_.program({"inspect/scene_depth.vert.glsl", "inspect/depth_only.frag.glsl"});
      glUseProgram(p);
      setUniform(p, "u_viewProj", viewProj);
      glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
      glEnable(GL_POLYGON_OFFSET_FILL);
      glPolygonOffset(1.0f, 64.0f);
      scene.draw(p);
      glDisable(GL_POLYGON_OFFSET_FILL);
      glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    }
    // X-ray: every voxel's edges, none hidden (by the scene or by other voxels), as a lattice.
    if (o.xray) glDisable(GL_DEPTH_TEST);
    GLuint p = shaders_.program({"inspect/cubes.vert.glsl", "inspect/cubes.frag.glsl"});
    glUseProgram(p);
    setUniform(p, "u_viewProj", viewProj);
    setUniform(p, "u_alpha", o.opacity);
    setUniform(p, "u_edgesOnly", o.xray ? 1 : 0);
    glBindVertexArray(emptyVao_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, cubes_.id());
    glDrawArraysInstanced(GL_TRIANGLES, 0, 36, GLsizei(cubeCount_));
  }
  if (o.bounds && box_) {
    // The 12 edges of the box, always on top.
    glDisable(GL_DEPTH_TEST);
    std::vector<ViewInstance> lines;
    appendBoxEdges(lines, box_->lo, box_->hi, kBoundsColor);
    glBindVertexArray(emptyVao_.id());
    drawLines(shaders_, viewProj, lines);
  }
  return endOffscreenRender(t0);
}

std::vector<uint8_t> SceneOverlay::readPixels() const {
  std::vector<uint8_t> px(size_t(target_.width) * target_.height * 4);
  if (px.empty()) return px;
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTextureImage(target_.color.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, GLsizei(px.size()), px.data());
  return px;
}

size_t SceneOverlay::coveredPixels() const {
  std::vector<uint8_t> px = readPixels();
  size_t n = 0;
  for (size_t i = 3; i < px.size(); i += 4) n += px[i] != 0;
  return n;
}

}  // namespace voxlab
