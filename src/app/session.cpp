#include "app/session.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "app/reference_error.h"
#include "capture/capture.h"
#include "core/error.h"
#include "scene/scene.h"

namespace voxlab {

using nlohmann::json;

HeadlessSession::HeadlessSession(const RunRequest& request) : request_(request) {
  // Everything that can be checked without GL first, so bad input never leaves partial output.
  auto technique = createTechnique(request.technique);
  untilStage_ = request.until.empty() ? technique->stageCount() - 1 : technique->stageIndex(request.until);
  ParamSet params = technique->defaultParams();
  for (const auto& s : request.sets) params.setAssignment(s);
  auto scene = std::make_shared<Scene>(loadScene(resolveScenePath(request.scene)));
  int cameras = int(scene->cameras.size());
  if (request.camera < 0 || request.camera >= cameras)
    throw Error("camera " + std::to_string(request.camera) + " does not exist in " + scene->name +
                "; valid: 0.." + std::to_string(cameras - 1));

  context_ = createOffscreenContext();
  shaders_ = std::make_unique<ShaderLibrary>();
  cursor_ = std::make_unique<StepCursor>(std::move(technique), *shaders_);
  cursor_->setScene(scene);
  cursor_->setParams(params);
  cursor_->useSceneCamera(request.camera);
  cursor_->setViewSize(request.width, request.height);
}

HeadlessSession::~HeadlessSession() {
  cursor_.reset();
  shaders_.reset();
}

void HeadlessSession::run() { cursor_->runThrough(untilStage_); }

json HeadlessSession::manifestHeader() const {
  json m;
  const auto& t = cursor_->technique();
  m["technique"] = t.id();
  m["scene"] = cursor_->scene().name;
  m["scene_path"] = cursor_->scene().path;
  m["parameters"] = cursor_->params().formatted();
  m["view"] = {{"width", cursor_->view().width}, {"height", cursor_->view().height},
               {"camera", request_.camera}, {"camera_name", cursor_->camera().name}};
  m["gl"] = {{"renderer", glRenderer()}, {"version", glVersion()}};
  return m;
}

json HeadlessSession::writeOutputs(const std::string& dir, bool finalOnly, const std::vector<OutputAddress>& only) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error("cannot create output folder '" + dir + "': " + ec.message());
  fs::remove(dir + "/manifest.json", ec);  // a stale manifest must not describe new files

  const Technique& t = cursor_->technique();
  json m = manifestHeader();
  json stages = json::array();
  double totalCpu = 0, totalGpu = 0;
  for (int i = 0; i <= untilStage_; ++i) {
    const StageRecord& r = cursor_->record(i);
    json s;
    s["id"] = t.stage(i).id();
    s["title"] = t.stage(i).title();
    s["state"] = stageStateName(r.state);
    s["cpu_ms"] = r.cpuMs;
    s["gpu_ms"] = r.gpuMs;
    s["iterations"] = r.iterationsRun;
    s["stats"] = r.stats;
    totalCpu += r.cpuMs;
    totalGpu += r.gpuMs;
    json outs = json::array();
    for (const auto& o : t.decl(i).outputs) {
      bool isFinal = t.finalStage() == t.stage(i).id() && t.finalOutput() == o.name;
      if (finalOnly && !isFinal) continue;
      int onlyLevel = -1;
      if (!only.empty()) {
        auto hit = std::find_if(only.begin(), only.end(), [&](const OutputAddress& a) {
          return a.stage == t.stage(i).id() && a.output == o.name;
        });
        if (hit == only.end()) continue;
        onlyLevel = hit->level;
      }
      CapturedOutput cap = captureOutput(cursor_->board(), o);
      if (onlyLevel >= 0) {
        if (onlyLevel >= int(cap.levels.size()))
          throw Error("output " + t.id() + "/" + t.stage(i).id() + "/" + o.name + " has levels 0.." +
                      std::to_string(int(cap.levels.size()) - 1) + ", not " + std::to_string(onlyLevel));
        cap.levels = {cap.levels[onlyLevel]};
      }
      std::string prefix = std::string(t.stage(i).id()) + "." + o.name +
                           (onlyLevel >= 0 ? "@" + std::to_string(onlyLevel) : "");
      json e = writeOutputFiles(cap, dir, prefix);
      e["name"] = o.name;
      e["address"] = t.id() + "/" + t.stage(i).id() + "/" + o.name;
      e["help"] = o.help;
      e["final"] = isFinal;
      // Outputs tagged with a reference mode: error against the checked-in ground truth, if any.
      json refErr = compareWithReference(cap, cursor_->scene().name, request_.camera, dir, prefix);
      if (!refErr.is_null()) {
        if (refErr.contains("files"))
          for (const auto& f : refErr["files"]) e["files"].push_back(f);
        e["reference_error"] = refErr;
      }
      outs.push_back(e);
    }
    s["outputs"] = outs;
    stages.push_back(s);
  }
  m["stages"] = stages;
  m["total_cpu_ms"] = totalCpu;
  m["total_gpu_ms"] = totalGpu;
  m["resource_bytes"] = cursor_->board().totalBytes();
  m["complete"] = true;
  std::ofstream(dir + "/manifest.json") << m.dump(2) << "\n";
  return m;
}

}  // namespace voxlab
