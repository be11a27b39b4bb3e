#include "inspect/view3d.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>

#include "gpu/shader_library.h"
#include "inspect/scene_overlay.h"

namespace voxlab {

namespace {
const glm::vec3 kBackground(0.11f, 0.11f, 0.13f);
const glm::vec3 kBoxColor(0.85f, 0.75f, 0.35f);
const char* kFullscreen = "inspect/fullscreen.vert.glsl";
}  // namespace

const char* viewModeName(ViewMode mode) {
  switch (mode) {
    case ViewMode::Slice: return "slice";
    case ViewMode::Volume: return "3d";
    case ViewMode::Cubes: return "cubes";
  }
  return "?";
}

void appendBoxEdges(std::vector<ViewInstance>& lines, glm::vec3 lo, glm::vec3 hi, glm::vec4 color) {
  for (int e = 0; e < 12; ++e) {
    int axis = e / 4, a = e % 4;  // four edges along each axis, at the corners a of the other two
    glm::vec3 p0, p1;
    for (int k = 0, bit = 0; k < 3; ++k) {
      if (k == axis) {
        p0[k] = lo[k], p1[k] = hi[k];
      } else {
        p0[k] = p1[k] = ((a >> bit) & 1) ? hi[k] : lo[k];
        ++bit;
      }
    }
    lines.push_back({glm::vec4(p0, 0), color});
    lines.push_back({glm::vec4(p1, 0), color});
  }
}

double endOffscreenRender(std::chrono::steady_clock::time_point t0) {
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, 0);
  glDisable(GL_DEPTH_TEST);
  glUseProgram(0);
  glBindVertexArray(0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glFinish();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void drawLines(ShaderLibrary& shaders, const glm::mat4& viewProj, const std::vector<ViewInstance>& lines) {
  if (lines.empty()) return;
  Buffer buf("viewer.lines", lines.size() * sizeof(ViewInstance), lines.data());
  GLuint p = shaders.program({"inspect/lines.vert.glsl", "inspect/color.frag.glsl"});
  glUseProgram(p);
  setUniform(p, "u_viewProj", viewProj);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buf.id());
  glDrawArrays(GL_LINES, 0, GLsizei(lines.size()));
}

void ColorDepthTarget::create(const std::string& label, int w, int h, GLenum colorFilter) {
  TextureDesc c;
  c.format = GL_RGBA8;
  c.size = {w, h, 1};
  c.minFilter = c.magFilter = colorFilter;
  color = Texture(label + ".color", c);
  TextureDesc d = c;
  d.format = GL_DEPTH_COMPONENT24;
  d.minFilter = d.magFilter = GL_NEAREST;
  depth = Texture(label + ".depth", d);
  fbo = Framebuffer(label);
  fbo.attach(GL_COLOR_ATTACHMENT0, color);
  fbo.attach(GL_DEPTH_ATTACHMENT, depth);
  fbo.setDrawBuffers(1);
  fbo.checkComplete();
  width = w, height = h;
}

void ColorDepthTarget::begin(glm::vec4 clearColor, int viewportWidth, int viewportHeight) const {
  glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
  glViewport(0, 0, viewportWidth, viewportHeight);
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDepthMask(GL_TRUE);
  glClearColor(clearColor.x, clearColor.y, clearColor.z, clearColor.w);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
}

View3D::View3D(ShaderLibrary& shaders) : shaders_(shaders) { target_.create("viewer.view3d", kSize, kSize, GL_LINEAR); }

void View3D::clear() {
  hasVolume_ = false;
  cubeCount_ = pointCount_ = sphereCount_ = 0;
  lines_.clear();
  cubeCandidates_ = 0;
}

GLuint View3D::uploadInstances(const std::vector<ViewInstance>& v, Buffer& buf, size_t& count) {
  count = v.size();
  size_t bytes = std::max<size_t>(v.size() * sizeof(ViewInstance), sizeof(ViewInstance));
  if (buf.size() < bytes || buf.size() > 4 * bytes) buf = Buffer("viewer.view3d.instances", bytes);
  if (!v.empty()) buf.upload(v.data(), v.size() * sizeof(ViewInstance));
  return buf.id();
}

void View3D::setVolume(const VolumeRGBA& vol, glm::vec3 extent, float opacityScale) {
  if (vol.size != volumeSize_ || !volumeTex_) {
    GLuint id = 0;
    glCreateTextures(GL_TEXTURE_3D, 1, &id);
    volumeTex_ = GLHandle<TextureDeleter>(id);
    glTextureStorage3D(id, 1, GL_RGBA8, std::max(vol.size.x, 1), std::max(vol.size.y, 1), std::max(vol.size.z, 1));
    glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glObjectLabel(GL_TEXTURE, id, -1, "viewer.view3d.volume");
    volumeSize_ = vol.size;
  }
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  if (!vol.rgba.empty())
    glTextureSubImage3D(volumeTex_.id(), 0, 0, 0, 0, vol.size.x, vol.size.y, vol.size.z, GL_RGBA, GL_UNSIGNED_BYTE,
                        vol.rgba.data());
  volumeExtent_ = extent;
  opacityScale_ = opacityScale;
  hasVolume_ = true;
  // Cubes: one per non-empty texel, only under the limit (the viewer shows the count otherwise).
  glm::vec3 texel = extent / glm::vec3(glm::max(vol.size, glm::ivec3(1)));
  std::vector<ViewInstance> cubes = volumeCubes(vol, glm::vec3(0.0f), texel, kCubeLimit, cubeCandidates_);
  uploadInstances(cubes, cubes_, cubeCount_);
}

void View3D::setCubes(std::vector<ViewInstance> cubes) {
  cubeCandidates_ = cubes.size();
  for (auto& c : cubes) c.color.w = 63.0f;  // every face
  if (cubes.size() > kCubeLimit) cubes.clear();
  uploadInstances(cubes, cubes_, cubeCount_);
}

void View3D::setPoints(std::vector<ViewInstance> points) { uploadInstances(points, points_, pointCount_); }
void View3D::setSpheres(std::vector<ViewInstance> spheres) { uploadInstances(spheres, spheres_, sphereCount_); }
void View3D::setLines(std::vector<ViewInstance> ends) { lines_ = std::move(ends); }

double View3D::render(ViewMode mode, const OrbitCamera& camera, int size) {
  auto t0 = std::chrono::steady_clock::now();
  size = std::clamp(size, 16, kSize);
  lastSize_ = size;
  glm::mat4 view = camera.view(), proj = camera.projection(1.0f), viewProj = proj * view;
  target_.begin(glm::vec4(kBackground, 1.0f), size, size);
  glBindVertexArray(vao_.id());

  if (mode == ViewMode::Volume && hasVolume_) {
    // The ray march writes every pixel (background included) and the depth of its first opaque hit.
    glDepthFunc(GL_ALWAYS);
    GLuint p = shaders_.program({kFullscreen, "inspect/volume_raymarch.frag.glsl"});
    glUseProgram(p);
    glBindTextureUnit(0, volumeTex_.id());
    setUniform(p, "u_volume", 0);
    setUniform(p, "u_volumeSize", volumeSize_);
    setUniform(p, "u_boxMax", volumeExtent_);
    setUniform(p, "u_invViewProj", glm::inverse(viewProj));
    setUniform(p, "u_viewProj", viewProj);
    setUniform(p, "u_eye", camera.eye());
    setUniform(p, "u_opacityScale", opacityScale_);
    setUniform(p, "u_background", kBackground);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDepthFunc(GL_LESS);
  }
  if (mode == ViewMode::Cubes && cubeCount_ > 0) {
    GLuint p = shaders_.program({"inspect/cubes.vert.glsl", "inspect/cubes.frag.glsl"});
    glUseProgram(p);
    setUniform(p, "u_viewProj", viewProj);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, cubes_.id());
    glDrawArraysInstanced(GL_TRIANGLES, 0, 36, GLsizei(cubeCount_));
  }
  if (mode == ViewMode::Volume && pointCount_ > 0) {
    GLuint p = shaders_.program({"inspect/points.vert.glsl", "inspect/color.frag.glsl"});
    glUseProgram(p);
    glEnable(GL_PROGRAM_POINT_SIZE);
    setUniform(p, "u_viewProj", viewProj);
    setUniform(p, "u_pointSize", 2.0f);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, points_.id());
    glDrawArrays(GL_POINTS, 0, GLsizei(pointCount_));
    glDisable(GL_PROGRAM_POINT_SIZE);
  }
  // Bounds (12 edges) and any extra lines (cone axes), depth-tested.
  std::vector<ViewInstance> lines;
  appendBoxEdges(lines, boxLo_, boxHi_, glm::vec4(kBoxColor, 1.0f));
  lines.insert(lines.end(), lines_.begin(), lines_.end());
  drawLines(shaders_, viewProj, lines);
  if (sphereCount_ > 0) {
    GLuint p = shaders_.program({"inspect/spheres.vert.glsl", "inspect/spheres.frag.glsl"});
    glUseProgram(p);
    setUniform(p, "u_view", view);
    setUniform(p, "u_projection", proj);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glDepthMask(GL_FALSE);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, spheres_.id());
    glDrawArraysInstanced(GL_TRIANGLES, 0, 6, GLsizei(sphereCount_));
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
  }
  return endOffscreenRender(t0);
}

std::vector<uint8_t> View3D::readPixels() const {
  std::vector<uint8_t> px(size_t(kSize) * kSize * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTextureImage(target_.color.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, GLsizei(px.size()), px.data());
  return px;
}

ViewContent View3D::content() const {
  // The bounds' lines are drawn in one exact colour and do not count as content.
  uint8_t bg[3], box[3];
  for (int k = 0; k < 3; ++k) {
    bg[k] = uint8_t(std::lround(kBackground[k] * 255.0f));
    box[k] = uint8_t(std::lround(kBoxColor[k] * 255.0f));
  }
  return viewContent(readPixels(), bg, box);
}

}  // namespace voxlab
