// View3D: the viewer's 3D views of a volume level or of buffer records, rendered offscreen into a
// small texture (kSize^2) with an orbit camera of its own, only when what is shown changes.
//
// Everything is in "view units": level-0 voxels of the volume (a level L texel spans 2^L of them).
//   volume  ray-marched front to back (shaders/inspect/volume_raymarch.frag.glsl)
//   cubes   one instanced cube per non-empty texel or per record (up to kCubeLimit)
//   points  buffer records as points
//   spheres + lines: cone samples (disc of the sample's diameter) and cone axes, volume bounds
// The content is set by the viewer from captured outputs; this class knows no stage.
#pragma once
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gpu/gl.h"
#include "gpu/resources.h"
#include "inspect/inspect_logic.h"

namespace voxlab {

class ShaderLibrary;

enum class ViewMode { Slice, Volume, Cubes };
const char* viewModeName(ViewMode mode);  // "slice", "3d", "cubes"

// One instance record (matches shaders/inspect/instances.glsl).
struct ViewInstance {
  glm::vec4 positionSize{0.0f};  // corner (cubes) or centre (points, spheres); edge or radius
  glm::vec4 color{1.0f};         // display-encoded rgb, opacity (cubes: bit mask of the faces to draw)
};

// The 12 edges of the box [lo, hi] as line ends (pairs), appended to 'lines'.
void appendBoxEdges(std::vector<ViewInstance>& lines, glm::vec3 lo, glm::vec3 hi, glm::vec4 color);
// Draws line segments (pairs of ends) with the inspect line program into the bound framebuffer.
void drawLines(ShaderLibrary& shaders, const glm::mat4& viewProj, const std::vector<ViewInstance>& lines);

// An RGBA8 colour + 24-bit depth framebuffer for the viewer's offscreen renders.
struct ColorDepthTarget {
  Texture color, depth;
  Framebuffer fbo;
  int width = 0, height = 0;
  void create(const std::string& label, int w, int h, GLenum colorFilter);
  // Binds it, sets the viewport and the state every offscreen render starts from, clears it.
  void begin(glm::vec4 clearColor, int viewportWidth, int viewportHeight) const;
};

// Unbinds what an offscreen render bound, waits for the GPU and returns milliseconds since t0.
double endOffscreenRender(std::chrono::steady_clock::time_point t0);

class View3D {
 public:
  static constexpr int kSize = 384;
  static constexpr size_t kCubeLimit = 200000;

  explicit View3D(ShaderLibrary& shaders);

  // --- content (view units) ---
  void clear();  // nothing but the background
  void setBox(glm::vec3 lo, glm::vec3 hi) { boxLo_ = lo, boxHi_ = hi; }
  // The volume spans [0, extent]; its texels are level texels. Keeps a copy for the cubes.
  void setVolume(const VolumeRGBA& volume, glm::vec3 extent, float opacityScale);
  void setCubes(std::vector<ViewInstance> cubes);    // replaces the cubes the volume made (all faces)
  void setPoints(std::vector<ViewInstance> points);  // centres
  void setSpheres(std::vector<ViewInstance> spheres);
  void setLines(std::vector<ViewInstance> ends);     // pairs of ends
  size_t cubeCandidates() const { return cubeCandidates_; }  // non-empty texels or records
  bool cubesOverLimit() const { return cubeCandidates_ > kCubeLimit; }

  // --- rendering ---
  // Renders into the lower-left size x size pixels of the view texture (the viewer renders at half
  // size while the user drags, a quarter of the pixels); returns milliseconds including glFinish.
  double render(ViewMode mode, const OrbitCamera& camera, int size = kSize);
  int lastSize() const { return lastSize_; }  // of the last render
  GLuint texture() const { return target_.color.id(); }
  // The last render's content beyond its background and bounds (inspect_logic.h: viewContent; reads the texture back).
  ViewContent content() const;
  std::vector<uint8_t> readPixels() const;  // RGBA8, bottom row first

 private:
  GLuint uploadInstances(const std::vector<ViewInstance>& v, Buffer& buf, size_t& count);

  ShaderLibrary& shaders_;
  ColorDepthTarget target_;
  VertexArray vao_;
  GLHandle<TextureDeleter> volumeTex_;
  glm::ivec3 volumeSize_{0};
  glm::vec3 volumeExtent_{1.0f};
  float opacityScale_ = 1.0f;
  bool hasVolume_ = false;
  glm::vec3 boxLo_{0.0f}, boxHi_{1.0f};
  Buffer cubes_, points_, spheres_;
  std::vector<ViewInstance> lines_;
  size_t cubeCount_ = 0, pointCount_ = 0, sphereCount_ = 0;
  size_t cubeCandidates_ = 0;
  int lastSize_ = kSize;
};

}  // namespace voxlab
