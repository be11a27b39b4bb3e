// The picture of a lesson step, rendered headless: what the viewer shows when it plays that step
// (its slice view of the step's output and level, a buffer's point view, and over camera images the
// step's voxel overlay and volume bounds), with what a caption needs to name it and reproduce it.
// `voxlab handout` renders every step through this; it drives the same HeadlessSession and
// StepCursor as `voxlab run`, and the same display mapping and SceneOverlay as the viewer.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/capture.h"
#include "graph/blackboard.h"
#include "lesson/lesson.h"

namespace voxlab {

class HeadlessSession;
class SceneOverlay;
class StepCursor;
struct ViewInstance;

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

// Area-averaged copy 'width' pixels wide, aspect kept (unchanged when not wider).
DisplayImage shrink(const DisplayImage& image, int width);
struct StepPicture {
  DisplayImage image;                 // RGB, top row first, at the size the viewer maps it (a slice's texels)
  int displayScale = 1;               // whole factor to show it at, nearest filtering (up to the step size)
  std::string address;                // technique/stage/output@level
  std::vector<std::string> changed;   // "name=value" for parameters that differ from the defaults
  std::string command;                // the `voxlab run` line that reproduces the state
  std::string notes;                  // iterations, overlays: what the run line does not say
};

class StepRenderer {
 public:
  StepRenderer(int width, int height);
  ~StepRenderer();
  // Renders one step of 'lesson'. Throws Error "lesson.md:LINE: what failed" for a step that
  // cannot be rendered (a level the output does not have, a stage without outputs, ...).
  StepPicture render(const Lesson& lesson, const LessonStep& step);

 private:
  StepPicture renderStep(const LessonStep& step);
  int width_, height_;
  std::unique_ptr<HeadlessSession> session_;
  std::unique_ptr<SceneOverlay> overlay_;
  std::string technique_, scene_;
};

}  // namespace voxlab
