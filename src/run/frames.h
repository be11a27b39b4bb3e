// Frames: one technique run as a sequence of frames while the scene plays its animation and
// parameters change (an object moving, the sun sweeping, a spot turning, a parameter ramp), each
// frame re-running only the stages its change invalidates. What is stale is decided by the
// declarations (StepCursor: a stage that declares a changed parameter, a stage reading the scene's
// geometry when vertices moved, its lights when a light moved, the view when the camera moved, and
// every stage reading what a stale stage wrote), so no technique is named here.
// `voxlab run --frames N [--time-range FROM:TO] [--animate NAME=FROM:TO]...` drives it.
//
// Per frame k of N, the scene is posed at time FROM + (TO - FROM) k / (N - 1) of its animation
// (by default over its whole duration; a still scene stays as it is), and every animated parameter
// is FROM + (TO - FROM) k / (N - 1) (linear; N = 1 holds FROM); the frame's outputs go to
// DIR/frames/NNNN/ (with its own manifest.json), and
// DIR/manifest.json holds the run's header, the frames (their parameter values, the stages each
// re-ran with their CPU times) and a temporal section over the technique's final output: per
// frame its mean value (energy) and, from the second frame on, its flicker, the mean absolute
// change of every pixel's channels from the frame before, and their means.
#pragma once
#include <functional>
#include <optional>
#include <utility>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "capture/capture.h"
#include "graph/output.h"
#include "graph/param.h"
#include "graph/step_cursor.h"
#include "scene/animation.h"

namespace voxlab {

class HeadlessSession;

struct ParamAnimation {
  std::string name;  // a numeric parameter of the technique
  double from = 0.0, to = 0.0;
};

// "NAME=FROM:TO" against 'params': throws Error in one line naming what is wrong (the form, a name
// that is not a parameter, a choice or switch, a value out of the parameter's range).
ParamAnimation parseAnimation(const ParamSet& params, const std::string& text);

// What frame k of an animation sets: every animated parameter's value and the time the scene is
// posed at. The frame loop here, the viewer's timeline and the handout's frames step frames only
// through animatedFrame.
struct FrameValues {
  std::vector<std::pair<std::string, double>> params;  // name, value (in the animations' order)
  std::optional<double> sceneTime;  // seconds of the scene's animation; unset for a still scene
};

// Frame 'frame' of 'frames' (0-based): FROM + (TO - FROM) k / (N - 1) per animation, rounded for an
// integer parameter of 'params' (N = 1 holds FROM), and the same fraction of 'sceneTimes' (FROM, TO
// in seconds) when the scene plays its animation.
FrameValues animatedFrame(const ParamSet& params, const std::vector<ParamAnimation>& animations, int frame, int frames,
                          const std::optional<std::pair<double, double>>& sceneTimes = std::nullopt);

// The stages up to 'until' that are not Done: what the next run re-runs once a frame's values are set.
std::vector<int> staleStages(const StepCursor& cursor, int until);

// Mean absolute change of every pixel's first three channels between two frames of one output
// (the same size): the flicker measure of the temporal section.
double meanAbsoluteChange(const LevelData& a, const LevelData& b);
// "FROM:TO" in seconds (FROM <= TO, both >= 0): throws Error in one line naming what is wrong.
std::pair<double, double> parseTimeRange(const std::string& text);

struct FramesRequest {
  int frames = 1;
  // Seconds of the scene's animation the frames span; unset = 0 to its duration. Setting it on a
  // still scene is an error (runFrames says the scene has no animation).
  std::optional<std::pair<double, double>> timeRange;
  std::vector<ParamAnimation> animations;
  bool finalOnly = false;            // per frame, only the final output (as run --final-only)
  std::vector<OutputAddress> only;   // per frame, only these outputs (as run --only)
  // The output the temporal section measures; unset = the technique's final output.
  std::optional<OutputAddress> measure;
};

// Poses 'scene', the scene 'cursor' renders (its owner's non-const handle on it), at 'time'
// (seconds) of 'animation' (read in the same load) and makes stale what moved, from the
// declarations: the readers of the scene's geometry when vertices moved (their GPU copy updated),
// of its lights when a light moved, of the view when scene camera 'followCamera' moved (it becomes
// the cursor's camera; -1: a free camera, which stays). Returns what changed. Throws Error when
// 'scene' is not the cursor's scene.
ScenePoseChange poseCursorScene(StepCursor& cursor, Scene& scene, const SceneAnimation& animation, double time,
                                int followCamera);

// poseCursorScene on the session's scene and animation, following the request's scene camera
// unless it looks from --look-from.
ScenePoseChange poseSessionScene(HeadlessSession& session, double time);

// Runs the frames and writes DIR/frames/NNNN/ and DIR/manifest.json; returns that manifest.
// 'progress' (optional) is told after every frame (1-based) and the stages it re-ran.
nlohmann::json runFrames(HeadlessSession& session, const FramesRequest& request, const std::string& dir,
                         const std::function<void(int frame, const std::vector<std::string>& reran)>& progress = {});

}  // namespace voxlab
