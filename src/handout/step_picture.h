// The picture of a lesson step, rendered headless: what the viewer shows when it plays that step
// (its slice view of the step's output and level, a buffer's point view, and over camera images the
// step's voxel overlay and volume bounds), with what a caption needs to name it and reproduce it.
// `voxlab handout` renders every step through this; it drives the same HeadlessSession and
// StepCursor as `voxlab run`, and the same display mapping and overlay (overlayContent,
// SceneOverlay, blendOverlay: inspect/scene_overlay.h) as the viewer.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/capture.h"
#include "graph/blackboard.h"
#include "inspect/scene_overlay.h"
#include "lesson/lesson.h"
#include "run/frames.h"

namespace voxlab {

class HeadlessSession;

// Area-averaged copy 'width' pixels wide, aspect kept (unchanged when not wider).
DisplayImage shrink(const DisplayImage& image, int width);

struct StepPicture {
  DisplayImage image;                 // RGB, top row first, at the size the viewer maps it (a slice's texels)
  int displayScale = 1;               // whole factor to show it at, nearest filtering (up to the step size)
  std::string address;                // technique/stage/output@level
  std::vector<std::string> changed;   // "name=value" for parameters that differ from the defaults
  std::string command;                // the `voxlab run` line that reproduces the state
  // A step with frames: the `voxlab run --frames N --animate ...` line that plays them (from the
  // step's own parameters; the picture itself is the last frame, where the viewer stops).
  std::string framesCommand;
  std::string notes;                  // iterations, overlays: what the run line does not say
};

class StepRenderer {
 public:
  StepRenderer(int width, int height);
  ~StepRenderer();
  // Renders one step of 'lesson'. Throws Error "lesson.md:LINE: what failed" for a step that
  // cannot be rendered (a level the output does not have, a stage without outputs, ...). A step
  // with frames is pictured at its last frame: the viewer plays the frames once and stops there.
  StepPicture render(const Lesson& lesson, const LessonStep& step);
  // The pictures of a step's frames ("frames"): the step's picture at every frame's parameter
  // values and, on an animated scene, scene time over its whole animation (run/frames.h
  // animatedFrame, as the viewer's timeline), each re-running only what the frame's change
  // invalidates.
  std::vector<DisplayImage> renderFrames(const Lesson& lesson, const LessonStep& step);
  // Closes the session and its GL context (the next render opens them again): before something
  // else, such as a sweep, opens contexts of its own.
  void release();

 private:
  StepPicture renderStep(const LessonStep& step, const FrameValues* frame = nullptr);
  // The session for the step's technique and scene (opened again when either differs).
  HeadlessSession& sessionFor(const LessonStep& step);
  // Frame k of the step's frames.
  FrameValues stepFrame(const LessonStep& step, int k);
  int width_, height_;
  std::unique_ptr<HeadlessSession> session_;
  std::unique_ptr<SceneOverlay> overlay_;
  std::string technique_, scene_;
};

}  // namespace voxlab
