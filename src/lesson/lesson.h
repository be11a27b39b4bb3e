// Lessons: Markdown files in lessons/ that walk a student through a technique stage by stage.
//
// A lesson is ordinary Markdown (the narrative) with one fenced block per step:
//
//   ```voxlab-step
//   {"technique": "vct-grid", "scene": "cornell-box", "stage": "mipmap", "output": "radiance",
//    "level": 2, "camera": 0, "set": {"mipmap.mode": "anisotropic"}}
//   ```
//
// The narrative of a step is the text between the previous block (or the start of the file) and
// its own block. A step's state is absolute: the technique's default parameters plus its "set",
// so steps can be replayed in any order. Only "stage" is required; "technique" carries over from
// the previous step (the first step needs it); a step without "scene" shows the lesson's scene,
// the first step's (default cornell-box), so a step that shows another scene says so itself. Optional: "iterations": N stops an iterative stage after N iterations (a partly
// built pyramid); "overlay": "stage/output@level" lays that volume level's voxels over camera
// images, "bounds": true the volume's box; "slice": N shows that slice of a volume (along "axis":
// "x", "y" or "z", default z) instead of the middle one; "beside": "reference" shows the reference path
// tracer's image of the output's reference mode (OutputDesc::referenceMode) beside it, as the
// viewer's compare view does side by side (a lesson's closing picture: the technique at its best
// next to ground truth); "sweep": "NAME=V1,V2,..." (or
// NAME=FROM:TO:STEPS) declares a sweep of one parameter of the step's technique on the step's scene
// (run/sweep.h): the viewer plots its error and time beside the view, with the value the view
// shows marked, and the handout embeds its slider page. A lesson's sweep runs small
// (kLessonSweepSize, with the step's "set" and "sweep_set", an object of name: value held for the
// sweep's runs only, e.g. a coarser grid) so handouts and lesson checks stay fast; "frames":
// {"count": N, "animate": ["NAME=FROM:TO", ...]} plays the step as N frames while those parameters
// move linearly (run/frames.h, as `voxlab run --frames N --animate ...`): the viewer's timeline plays
// them, highlighting the stages each frame re-runs, and the handout embeds the frames of the step's
// output as an animated PNG (kLessonFramesSize). Validation runs against the technique registry: an unknown technique, stage,
// output or parameter, or a bad value, is an Error naming "file:line".
#pragma once
#include <map>
#include <string>
#include <vector>

#include "run/frames.h"
#include "run/sweep.h"

namespace voxlab {

struct LessonStep {
  int line = 0;                 // line of the opening ```voxlab-step fence (1-based)
  std::string narrative;        // Markdown before the block (trimmed)
  std::string technique;
  std::string scene;            // name in scenes/ or a path
  std::string stage;
  std::string output;           // "" = the stage's first output
  int level = 0;
  int sliceAxis = 2;            // the volume slice shown: 0 = x, 1 = y, 2 = z
  int sliceIndex = -1;          // -1 = the middle slice (the viewer's default)
  int camera = 0;
  std::vector<std::pair<std::string, std::string>> sets;  // name, value (in file order)
  int iterations = 0;           // > 0: run only this many iterations of an iterative stage
  std::string overlay;          // "stage/output@level": that volume's voxels over camera images
  bool bounds = false;          // the voxel volume's bounds over camera images
  bool besideReference = false; // "beside": "reference"
  std::string referenceMode;    // with besideReference: the mode under the step's parameters ("indirect-1")
  std::string referenceImage;   // ... and its file (tests/golden/reference/<scene>/<mode>.exr, absolute)
  std::string sweep;            // "NAME=V1,V2,...": the step's sweep; "" = none
  std::vector<std::pair<std::string, std::string>> sweepSets;  // "sweep_set": for the sweep's runs only
  int frameCount = 0;                        // "frames": > 0 plays the step as this many frames
  std::vector<std::string> frameAnimate;     // ... its "animate" texts, as written
  std::vector<ParamAnimation> frameAnimations;  // ... while these parameters move (validated)
};

// The frames a lesson step may play: at least two (a change) and at most 64 (a few seconds of
// animation; each frame re-runs stages, so the handout and the viewer stay quick).
constexpr int kLessonMinFrames = 2, kLessonMaxFrames = 64;

// The image size of a lesson step's frames in its handout: the animated PNG holds every frame.
constexpr int kLessonFramesSize = 128;

// The image size of a lesson step's sweep runs: a quarter of the references' 256x256 per side,
// enough for the plots' trend at about a second per run.
constexpr int kLessonSweepSize = 64;

struct Lesson {
  std::string path;
  std::string title;            // the first "# " heading, or the file name
  std::string epilogue;         // narrative after the last block
  std::vector<LessonStep> steps;
};

// Parses and validates 'text' as the lesson at 'path' (the path only appears in messages).
// 'checkScenes' also resolves each scene name to a file.
Lesson parseLesson(const std::string& text, const std::string& path, bool checkScenes = true);
Lesson loadLesson(const std::string& path, bool checkScenes = true);  // reads, then parseLesson

// The sweep a step declares: its technique and scene at kLessonSweepSize, the step's "set" (less
// the swept parameter) and then its "sweep_set". Only for a step whose 'sweep' is not empty.
SweepRequest lessonSweepRequest(const LessonStep& step);

}  // namespace voxlab
