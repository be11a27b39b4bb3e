// Viewer: the interactive front end (`voxlab view`). It steps any technique stage by stage and
// inspects every declared output, working from the stage declarations alone: the timeline comes
// from the stage list, the parameter panel from the ParamDescs, every view of an output from the
// visualiser of its kind and semantic (src/inspect/visualisers), and the probes from the stages'
// probe declarations (StageBuilder::probe, OutputDesc::probeRecord). No stage-specific code.
// The panels are one file each around the state in viewer_state.h.
//
// Stages run on the GL thread one per frame (StepCursor::runThrough to the next stage only), so
// the UI is drawn between stages and never freezes for a whole technique. A script (--script)
// replays the same actions a user performs, for tests under Xvfb.
#pragma once
#include <memory>
#include <string>

namespace voxlab {

struct ViewerOptions {
  std::string technique;   // technique id to open (voxlab view defaults it)
  std::string scene = "cornell-box";
  std::string lesson;      // lesson file to open (optional)
  std::string script;      // script file to replay (optional); the viewer quits at its end
  int width = 512, height = 512;                // render size of the technique's view
  int windowWidth = 1280, windowHeight = 720;   // window size
  float uiScale = 1.0f;    // text and widget size (a projector in a lecture hall wants 1.5-2)
  bool present = false;    // start in presenter mode (view + large narrative; P / F11 toggle)
};

// Runs the viewer until the window closes or the script quits. Returns the exit code; a script
// error throws Error ("FILE:LINE: message").
int runViewer(const ViewerOptions& options);

}  // namespace voxlab
