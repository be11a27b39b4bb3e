#include "inspect/scene_overlay.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "gpu/shader_library.h"
#include "graph/step_cursor.h"
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

bool isCameraImage(const StepCursor& cursor, int stage, const CapturedOutput& c) {
  if (c.desc.kind != OutputKind::Image2D || c.levels.empty()) return false;
  if (!cursor.technique().dependsOnView(stage)) return false;
  return c.levels[0].size.x == cursor.view().width && c.levels[0].size.y == cursor.view().height;
}

OverlayContent overlayContent(StepCursor& cursor, const std::string& volume, int level, bool voxels) {
  OverlayContent r;
  r.box = cursor.board().voxelSpace();
  if (volume.empty()) return r;
  const Technique& t = cursor.technique();
  size_t slash = volume.find('/');
  auto [stage, desc] = t.findOutput(volume.substr(0, slash), volume.substr(slash + 1));
  if (auto placed = cursor.board().placementOf(desc->resourceName())) r.box = placed;
  if (!voxels) return r;
  if (!cursor.outputHeld(stage, desc->name)) {  // an output on demand the run has not computed (yet)
    r.message = volume + " is not computed yet; showing nothing";
    return r;
  }
  CapturedOutput c = captureOutput(cursor.board(), *desc);
  if (c.levels.empty()) return r;
  if (level < 0) {  // the finest level with at most 32 texels per axis: blocks large enough to see
    level = 0;
    while (level + 1 < int(c.levels.size()) && c.levels[level].size.x > 32) ++level;
  }
  r.level = std::clamp(level, 0, int(c.levels.size()) - 1);
  r.levelCount = int(c.levels.size());
  const LevelData& L = c.levels[r.level];
  if (!c.world) {
    r.message = volume + " has no world placement (Blackboard::place); showing nothing";
    return r;
  }
  VolumeRGBA v = mapVolume(L, desc->semantic, DisplaySettings{});
  size_t candidates = 0;
  r.cubes = volumeCubes(v, c.world->lo, (c.world->hi - c.world->lo) / glm::vec3(L.size), View3D::kCubeLimit, candidates);
  char buf[200];
  if (r.cubes.empty() && candidates > 0)
    std::snprintf(buf, sizeof buf, "%zu voxels at level %d, over the limit of %zu: pick a coarser level", candidates,
                  r.level, View3D::kCubeLimit);
  else
    std::snprintf(buf, sizeof buf, "%s level %d (%dx%dx%d): %zu voxels", volume.c_str(), r.level, L.size.x, L.size.y,
                  L.size.z, candidates);
  r.message = buf;
  return r;
}

void blendOverlay(DisplayImage& image, const std::vector<uint8_t>& over) {
  if (over.size() != size_t(image.width) * image.height * 4) return;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const uint8_t* o = &over[(size_t(image.height - 1 - y) * image.width + x) * 4];
      uint8_t* p = &image.rgb[(size_t(y) * image.width + x) * 3];
      for (int c = 0; c < 3; ++c) {
        float v = p[c];
        p[c] = uint8_t(std::lround(v + (o[c] - v) * (o[3] / 255.0f)));
      }
    }
}

}  // namespace voxlab
