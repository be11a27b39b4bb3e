#include "run/frame_costs.h"

#include <algorithm>
#include <cmath>

#include "graph/scene_inputs.h"
#include "run/frames.h"
#include "run/session.h"
#include "scene/animation.h"
#include "scene/scene.h"

namespace voxlab {

namespace {

// Runs one frame after 'change' and records the stages it re-ran.
void timeFrame(HeadlessSession& session, FrameChangeCost& cost) {
  StepCursor& cursor = session.cursor();
  std::vector<int> stale;
  for (int i = 0; i <= session.untilStage(); ++i)
    if (cursor.record(i).state != StageState::Done) stale.push_back(i);
  session.run();
  double cpu = 0.0, gpu = 0.0;
  for (int i : stale) {
    if (cursor.record(i).state != StageState::Done) continue;  // not needed by the run: it did not run
    const std::string id = cursor.technique().stage(i).id();
    if (std::find(cost.stages.begin(), cost.stages.end(), id) == cost.stages.end()) cost.stages.push_back(id);
    cost.cpuMs[id].push_back(cursor.record(i).cpuMs);
    cost.gpuMs[id].push_back(cursor.record(i).gpuMs);
    cpu += cursor.record(i).cpuMs;
    gpu += cursor.record(i).gpuMs;
  }
  cost.frameCpuMs.push_back(cpu);
  cost.frameGpuMs.push_back(gpu);
}

// Keeps 'stages' in the technique's stage order.
void sortStages(HeadlessSession& session, FrameChangeCost& cost) {
  const Technique& t = session.cursor().technique();
  std::sort(cost.stages.begin(), cost.stages.end(),
            [&](const std::string& a, const std::string& b) { return t.stageIndex(a) < t.stageIndex(b); });
}

}  // namespace

std::vector<FrameChangeCost> timeFrameChanges(HeadlessSession& session, int frames) {
  StepCursor& cursor = session.cursor();
  session.run();
  std::vector<FrameChangeCost> costs;

  // Light move: the azimuth parameter, from the scene light's own direction.
  const char* azimuth = "light.0.azimuth";
  if (cursor.params().has(azimuth)) {
    FrameChangeCost cost{"light move", "light.0.azimuth turned by 2 degrees a frame", {}, {}, {}, {}, {}};
    const double held = cursor.params().value(azimuth);
    float az = 0.0f, el = 0.0f;
    sunAngles(cursor.scene().lights.at(0).direction, az, el);
    for (int k = 0; k < frames; ++k) {
      cursor.setParam(azimuth, std::fmod(double(az) + 2.0 * (k + 1) + 360.0, 360.0));
      timeFrame(session, cost);
    }
    cursor.setParam(azimuth, held);
    session.run();
    sortStages(session, cost);
    costs.push_back(cost);
  }

  // Camera move: sideways along the camera's right vector.
  {
    FrameChangeCost cost{"camera move", "the camera stepped sideways by 1% of the scene's size a frame", {}, {}, {}, {}, {}};
    const Camera held = cursor.camera();
    const float step = 0.01f * glm::length(cursor.scene().bounds.extent());
    const glm::vec3 right = glm::normalize(glm::cross(held.forward, held.up));
    for (int k = 0; k < frames; ++k) {
      Camera moved = held;
      moved.position += right * (step * float(k + 1));
      cursor.setCamera(moved);
      timeFrame(session, cost);
    }
    cursor.setCamera(held);
    session.run();
    sortStages(session, cost);
    costs.push_back(cost);
  }

  // Moving object: the scene's own animation, or the geometry marked moved.
  {
    const SceneAnimation& animation = session.animation();
    const bool animated = animation.movesGeometry();
    FrameChangeCost cost{"moving object",
                         animated ? "the scene's animation played over the frames"
                                  : "the scene's geometry marked moved each frame (a still scene)",
                         {}, {}, {}, {}, {}};
    for (int k = 0; k < frames; ++k) {
      if (animated) poseSessionScene(session, animation.duration * double(k + 1) / double(frames));
      else invalidateAllGeometry(cursor);
      timeFrame(session, cost);
    }
    if (animated) poseSessionScene(session, 0.0);
    session.run();
    sortStages(session, cost);
    costs.push_back(cost);
  }
  return costs;
}

}  // namespace voxlab
