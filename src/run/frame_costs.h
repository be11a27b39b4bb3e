// What one frame of change costs, stage by stage: `voxlab bench --frames N` times N frames of each
// of three changes on a session that has run once, and reports the stages each change re-ran
// (from the declarations, as the frame loop re-runs them) with their per-frame times.
//
//   light move      light.0.azimuth turned by 2 degrees a frame (the light stage and what reads it)
//   camera move     the camera stepped sideways by 1% of the scene's size a frame (what reads @view)
//   moving object   the scene's animation played over the frames when it moves vertices; a still
//                   scene has its geometry marked moved each frame (the same stages re-run on the
//                   same triangles: a moving object's cost without its motion)
//
// After each change the session is put back (parameter, camera, pose) and run again, so the next
// change starts from the same state.
#pragma once
#include <map>
#include <string>
#include <vector>

namespace voxlab {

class HeadlessSession;

struct FrameChangeCost {
  std::string change;  // "light move", "camera move", "moving object"
  std::string how;     // what changed each frame, in words
  std::vector<std::string> stages;  // ids of the stages re-run, in stage order (union over the frames)
  std::map<std::string, std::vector<double>> cpuMs, gpuMs;  // per re-run stage, one value per frame
  std::vector<double> frameCpuMs, frameGpuMs;               // per frame, its re-run stages together
};

std::vector<FrameChangeCost> timeFrameChanges(HeadlessSession& session, int frames);

}  // namespace voxlab
