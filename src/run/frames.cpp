#include "run/frames.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "capture/capture.h"
#include "core/error.h"
#include "graph/scene_inputs.h"
#include "scene/animation.h"
#include "run/session.h"

namespace voxlab {

using nlohmann::json;

ParamAnimation parseAnimation(const ParamSet& params, const std::string& text) {
  const size_t eq = text.find('='), colon = text.find(':', eq == std::string::npos ? 0 : eq);
  if (eq == std::string::npos || eq == 0 || colon == std::string::npos)
    throw Error("--animate '" + text + "': expected NAME=FROM:TO, e.g. light.0.azimuth=0:90");
  ParamAnimation a;
  a.name = text.substr(0, eq);
  const ParamDesc& d = params.desc(a.name);  // throws listing the valid names
  if (d.type == ParamType::Bool || d.type == ParamType::Choice)
    throw Error("--animate " + a.name + ": a " + d.typeName() + " (" + d.rangeText() +
                ") cannot be animated; valid: a number parameter (voxlab list names each one's range)");
  auto number = [&](const std::string& s, const char* which) {
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(v))
      throw Error("--animate " + a.name + ": " + which + " '" + s + "' is not a number; valid: " + d.rangeText());
    d.validate(v);  // throws naming the parameter and its range
    return v;
  };
  a.from = number(text.substr(eq + 1, colon - eq - 1), "FROM");
  a.to = number(text.substr(colon + 1), "TO");
  return a;
}

std::pair<double, double> parseTimeRange(const std::string& text) {
  const size_t colon = text.find(':');
  auto number = [&](const std::string& s, const char* which) {
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(v) || v < 0.0)
      throw Error(std::string("--time-range ") + which + " '" + s + "' is not a number of seconds >= 0");
    return v;
  };
  if (colon == std::string::npos) throw Error("--time-range '" + text + "': expected FROM:TO in seconds, e.g. 0:2.5");
  const double from = number(text.substr(0, colon), "FROM"), to = number(text.substr(colon + 1), "TO");
  if (to < from) throw Error("--time-range '" + text + "': TO is before FROM");
  return {from, to};
}

ScenePoseChange poseCursorScene(StepCursor& cursor, Scene& scene, const SceneAnimation& animation, double time,
                                int followCamera) {
  if (!cursor.hasScene() || &cursor.scene() != &scene)
    throw Error("posing a scene the step cursor does not render (its owner must pose the cursor's own scene)");
  const ScenePoseChange change = poseScene(scene, animation, float(time));
  if (change.geometry) {
    uploadPosedVertices(cursor.gpuScene(), scene, animation);
    invalidateMovedGeometry(cursor);  // the still nodes' triangles stay where they were
  }
  if (change.lights) invalidateSceneInput(cursor, kSceneLightsInput);
  if (change.cameras && followCamera >= 0) cursor.setCamera(scene.cameras.at(size_t(followCamera)));
  return change;
}

ScenePoseChange poseSessionScene(HeadlessSession& session, double time) {
  return poseCursorScene(session.cursor(), session.scene(), session.animation(), time,
                         session.request().lookFrom ? -1 : session.request().camera);
}

namespace {

// Mean of the first three channels of level 0, and the mean absolute difference from 'previous'
// (same size) over the same channels.
double meanValue(const LevelData& L) {
  double sum = 0.0;
  const int c = std::min(L.channels, 3);
  for (size_t i = 0; i < L.values.size(); ++i)
    if (int(i % size_t(L.channels)) < c) sum += L.values[i];
  return sum / std::max<double>(1.0, double(L.values.size() / size_t(L.channels) * size_t(c)));
}

}  // namespace

double meanAbsoluteChange(const LevelData& a, const LevelData& b) {
  double sum = 0.0;
  size_t n = 0;
  const int c = std::min(a.channels, 3);
  for (size_t i = 0; i < a.values.size() && i < b.values.size(); ++i)
    if (int(i % size_t(a.channels)) < c) sum += std::abs(double(a.values[i]) - double(b.values[i])), ++n;
  return n ? sum / double(n) : 0.0;
}

FrameValues animatedFrame(const ParamSet& params, const std::vector<ParamAnimation>& animations, int frame, int frames,
                          const std::optional<std::pair<double, double>>& sceneTimes) {
  const double s = frames > 1 ? double(frame) / double(frames - 1) : 0.0;
  FrameValues values;
  if (sceneTimes) values.sceneTime = sceneTimes->first + (sceneTimes->second - sceneTimes->first) * s;
  for (const ParamAnimation& a : animations) {
    double v = a.from + (a.to - a.from) * s;
    if (params.desc(a.name).type == ParamType::Int) v = std::round(v);
    values.params.emplace_back(a.name, v);
  }
  return values;
}

std::vector<int> staleStages(const StepCursor& cursor, int until) {
  std::vector<int> stale;
  for (int i = 0; i <= until; ++i)
    if (cursor.record(i).state != StageState::Done) stale.push_back(i);
  return stale;
}

json runFrames(HeadlessSession& session, const FramesRequest& request, const std::string& dir,
               const std::function<void(int, const std::vector<std::string>&)>& progress) {
  if (request.frames < 1) throw Error("--frames must be 1 or more");
  StepCursor& cursor = session.cursor();
  const Technique& t = cursor.technique();
  const int until = session.untilStage();
  // The temporal metrics follow the technique's final output when the run reaches it.
  const std::string measuredStage = request.measure ? request.measure->stage : t.finalStage();
  const std::string measuredOutput = request.measure ? request.measure->output : t.finalOutput();
  const int finalStage = t.stageIndex(measuredStage);
  const OutputDesc* finalDesc = finalStage <= until ? t.findOutput(measuredStage, measuredOutput).second : nullptr;

  // The scene's animation plays over the frames (a still scene has none to play): the session read
  // it with the scene and poses its scene in place.
  const SceneAnimation& animation = session.animation();
  if (request.timeRange && !animation.animated())
    throw Error("--time-range: scene '" + cursor.scene().name + "' has no animation (its glTF file has no node animations)");
  const std::pair<double, double> times =
      request.timeRange ? *request.timeRange : std::pair<double, double>(0.0, double(animation.duration));
  const std::optional<std::pair<double, double>> sceneTimes =
      animation.animated() ? std::optional<std::pair<double, double>>(times) : std::nullopt;

  json m = session.manifestHeader();
  json frames = json::array(), energy = json::array(), flicker = json::array();
  LevelData previous;
  double flickerSum = 0.0;
  for (int k = 0; k < request.frames; ++k) {
    const FrameValues frameValues = animatedFrame(cursor.params(), request.animations, k, request.frames, sceneTimes);
    json changed = json::array();
    const double time = frameValues.sceneTime.value_or(0.0);
    if (frameValues.sceneTime) {
      const ScenePoseChange change = poseSessionScene(session, time);
      if (change.geometry) changed.push_back("geometry");
      if (change.lights) changed.push_back("lights");
      if (change.cameras) changed.push_back("camera");
    }
    json values = json::object();
    for (const auto& [name, v] : frameValues.params) {
      cursor.setParam(name, v);
      values[name] = v;
    }
    const std::vector<int> stale = staleStages(cursor, until);
    session.run();
    json reran = json::array();
    std::vector<std::string> reranIds;
    double cpu = 0.0;
    for (int i : stale) {
      // A stale stage the run did not need (none of its outputs demanded, e.g. under --final-only)
      // stays stale: it did not run.
      if (cursor.record(i).state != StageState::Done) continue;
      reran.push_back({{"stage", t.stage(i).id()}, {"cpu_ms", cursor.record(i).cpuMs}, {"gpu_ms", cursor.record(i).gpuMs}});
      reranIds.push_back(t.stage(i).id());
      cpu += cursor.record(i).cpuMs;
    }
    char name[16];
    std::snprintf(name, sizeof name, "%04d", k);
    const std::string frameDir = dir + "/frames/" + name;
    session.writeOutputs(frameDir, request.finalOnly, request.only);
    json frame = {{"frame", k}, {"dir", std::string("frames/") + name}, {"parameters", values},
                  {"stages_run", reran}, {"cpu_ms", cpu}};
    if (animation.animated()) {
      frame["time"] = time;
      frame["scene_changed"] = changed;
    }
    if (finalDesc) {
      CapturedOutput cap = captureOutput(cursor.board(), *finalDesc);
      const LevelData& L = cap.levels.at(0);
      energy.push_back(meanValue(L));
      if (k > 0) {
        const double f = meanAbsoluteChange(L, previous);
        flicker.push_back(f);
        flickerSum += f;
        frame["flicker"] = f;
      }
      previous = L;
    }
    frames.push_back(frame);
    if (progress) progress(k + 1, reranIds);
  }
  m["frames"] = frames;
  json animated = json::array();
  for (const ParamAnimation& a : request.animations) animated.push_back({{"name", a.name}, {"from", a.from}, {"to", a.to}});
  m["animate"] = animated;
  if (animation.animated())
    m["animation"] = {{"names", animation.names}, {"duration", animation.duration},
                      {"time_range", {times.first, times.second}}};
  if (finalDesc) {
    double energySum = 0.0;
    for (const auto& e : energy) energySum += e.get<double>();
    m["temporal"] = {{"output", t.id() + "/" + measuredStage + "/" + measuredOutput},
                     {"energy", energy},
                     {"mean_energy", energySum / double(energy.size())},
                     {"flicker", flicker},
                     {"mean_flicker", flicker.empty() ? 0.0 : flickerSum / double(flicker.size())},
                     {"measure", "flicker: mean |I_k - I_(k-1)| over pixels and colour channels of the output; "
                                 "energy: its mean"}};
  } else {
    m["temporal"] = {{"skipped", "the run stops before the final output (--until)"}};
  }
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/manifest.json") << m.dump(2) << "\n";
  return m;
}

}  // namespace voxlab
