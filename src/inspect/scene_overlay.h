// SceneOverlay: draws inspection geometry over a camera image of the technique (the final render,
// the G-buffer, any image a stage renders from the view): the voxels of a volume level as cubes and
// the volume's world bounds, with the same camera, into a transparent texture of the image's size
// that the viewer lays over the image. The scene's own triangles fill the depth buffer first, so
// voxels behind surfaces stay hidden ("x-ray" instead draws every voxel's edges, none hidden).
//
// Everything is in world units: overlayContent builds the cubes from a captured volume and its
// WorldBox (Blackboard::placementOf), so any technique's volumes can be overlaid. The viewer and
// the handout's step pictures both draw their overlays through overlayContent and SceneOverlay.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "capture/capture.h"
#include "gpu/resources.h"
#include "graph/blackboard.h"
#include "inspect/view3d.h"

namespace voxlab {

class GpuScene;
class ShaderLibrary;
class StepCursor;

// Cubes for the non-empty texels of a display-mapped volume (alpha > 0) whose texel (0,0,0) has its
// minimum corner at 'origin' and whose texels measure 'texel'; faces shared with a non-empty
// neighbour are left out (the face mask in ViewInstance::color.a). Returns no cubes when there are
// more than 'limit' non-empty texels; 'candidates' is their count either way.
std::vector<ViewInstance> volumeCubes(const VolumeRGBA& volume, glm::vec3 origin, glm::vec3 texel, size_t limit,
                                      size_t& candidates);

class SceneOverlay {
 public:
  explicit SceneOverlay(ShaderLibrary& shaders);

  void setCubes(const std::vector<ViewInstance>& cubes);  // world units; empty = no voxels
  void setBox(const std::optional<WorldBox>& box) { box_ = box; }

  struct Options {
    bool voxels = true;
    bool bounds = true;
    bool xray = false;    // every voxel's edges, none hidden by surfaces or other voxels
    float opacity = 0.6f;  // of the voxel faces over the image
  };
  // Renders at width x height with the camera's view-projection; returns milliseconds (glFinish).
  double render(int width, int height, const glm::mat4& viewProj, const GpuScene& scene, const Options& options);
  GLuint texture() const { return target_.color.id(); }
  size_t cubeCount() const { return cubeCount_; }
  // Pixels with any overlay content (alpha > 0) in the last render; reads the texture back.
  size_t coveredPixels() const;
  std::vector<uint8_t> readPixels() const;  // RGBA8 of the last render, bottom row first

 private:
  ShaderLibrary& shaders_;
  ColorDepthTarget target_;
  VertexArray emptyVao_;
  Buffer cubes_;
  size_t cubeCount_ = 0;
  std::optional<WorldBox> box_;
};

// Whether an output of 'stage' is a camera image: a 2D image of the view's size written by a stage
// that depends on the view (the images the viewer lays overlays over).
bool isCameraImage(const StepCursor& cursor, int stage, const CapturedOutput& capture);

// What a volume overlay shows: cubes for the non-empty texels of one level of a volume output, in
// world units, and the box to outline. 'volume' is "stage/output"; level < 0 picks the finest level
// with at most 32 texels per axis. 'message' says what was built (or why nothing was).
struct OverlayContent {
  std::vector<ViewInstance> cubes;
  std::optional<WorldBox> box;
  int level = 0;
  int levelCount = 0;
  std::string message;
};
OverlayContent overlayContent(StepCursor& cursor, const std::string& volume, int level, bool voxels);

// 'over' (RGBA8, bottom row first, same size) blended over 'image' (RGB, top row first) as the
// viewer draws it: source alpha over the image.
void blendOverlay(DisplayImage& image, const std::vector<uint8_t>& over);

}  // namespace voxlab
