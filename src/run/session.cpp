#include "run/session.h"

#include <chrono>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <future>
#include <memory>
#include <thread>

#include "run/reference_error.h"
#include "capture/capture.h"
#include "core/error.h"
#include "core/paths.h"
#include "graph/reference_mode.h"
#include "scene/scene.h"

namespace voxlab {

using nlohmann::json;

Camera requestCamera(const Scene& scene, const RunRequest& request) {
  Camera c = scene.cameras.at(request.camera);
  if (!request.lookFrom && !request.lookAt) return c;
  if (!request.lookFrom || !request.lookAt) throw Error("--look-from and --look-at go together; give both or neither");
  glm::vec3 d = *request.lookAt - *request.lookFrom;
  if (glm::length(d) < 1e-6f) throw Error("--look-from and --look-at are the same point; the camera needs a direction");
  c.name = "free";
  c.position = *request.lookFrom;
  c.forward = glm::normalize(d);
  // Up: world +y, or +z when looking straight up or down.
  glm::vec3 worldUp = std::abs(c.forward.y) > 0.999f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
  c.up = glm::normalize(glm::cross(glm::cross(c.forward, worldUp), c.forward));
  return c;
}

HeadlessSession::HeadlessSession(const RunRequest& request) : request_(request) {
  // Everything that can be checked without GL first, so bad input never leaves partial output.
  auto technique = createTechnique(request.technique);
  untilStage_ = request.until.empty() ? technique->stageCount() - 1 : technique->stageIndex(request.until);
  ParamSet params = technique->defaultParams();
  for (const auto& s : request.sets) params.setAssignment(s);
  const auto loadStart = std::chrono::steady_clock::now();
  scene_ = std::make_shared<Scene>(loadScene(resolveScenePath(request.scene), animation_));
  sceneLoadMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - loadStart).count();
  int cameras = int(scene_->cameras.size());
  if (request.camera < 0 || request.camera >= cameras)
    throw Error("camera " + std::to_string(request.camera) + " does not exist in " + scene_->name +
                "; valid: 0.." + std::to_string(cameras - 1));

  requestCamera(*scene_, request);  // validates --look-from/--look-at

  context_ = createOffscreenContext();
  shaders_ = std::make_unique<ShaderLibrary>();
  cursor_ = std::make_unique<StepCursor>(std::move(technique), *shaders_);
  cursor_->setScene(scene_);
  cursor_->setParams(params);
  cursor_->setCamera(requestCamera(*scene_, request));
  cursor_->setViewSize(request.width, request.height);
}

HeadlessSession::~HeadlessSession() {
  cursor_.reset();
  shaders_.reset();
}

void HeadlessSession::run() { cursor_->runThrough(untilStage_); }

void HeadlessSession::demand(bool finalOnly, const std::vector<OutputAddress>& only) {
  const Technique& t = cursor_->technique();
  std::vector<std::pair<std::string, std::string>> outputs;
  if (finalOnly) outputs.push_back({t.finalStage(), t.finalOutput()});
  for (const auto& a : only) outputs.push_back({a.stage, a.output});
  if (outputs.empty())
    cursor_->demandEverything();
  else
    cursor_->demandOutputs(outputs);
}

json HeadlessSession::manifestHeader() const {
  json m;
  const auto& t = cursor_->technique();
  m["technique"] = t.id();
  m["scene"] = cursor_->scene().name;
  m["scene_path"] = cursor_->scene().path;
  m["scene_load_ms"] = sceneLoadMs_;  // parsing, decoding textures, flattening (CPU)
  m["scene_triangles"] = cursor_->scene().triangleCount();
  m["parameters"] = cursor_->params().formatted();
  // Which light light.0 starts from: the file's first light, or the loader's default sun.
  const auto& lights = cursor_->scene().lights;
  m["light"] = lights.empty() ? std::string("none")
               : lights[0].name == kDefaultSunName ? std::string(kDefaultSunName)
                                                   : "scene light '" + lights[0].name + "'";
  // Which camera the view starts from: a scene camera, the loader's framing camera, or
  // --look-from/--look-at (which starts from camera 'view.camera' and replaces its pose).
  const Camera& sceneCamera = cursor_->scene().cameras.at(request_.camera);
  m["camera"] = request_.lookFrom                           ? std::string("look-from/look-at")
                : sceneCamera.name == kFramingCameraName ? std::string(kFramingCameraName)
                                                          : "scene camera '" + sceneCamera.name + "'";
  m["view"] = {{"width", cursor_->view().width}, {"height", cursor_->view().height},
               {"camera", request_.camera}, {"camera_name", cursor_->camera().name}};
  if (request_.lookFrom) {
    const glm::vec3 &p = *request_.lookFrom, &q = *request_.lookAt;
    m["view"]["look_from"] = {p.x, p.y, p.z};
    m["view"]["look_at"] = {q.x, q.y, q.z};
  }
  m["gl"] = {{"renderer", glRenderer()}, {"version", glVersion()}, {"context", context_->kind()}};
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
  std::vector<json> stages;
  double totalCpu = 0, totalGpu = 0;
  // Outputs are read back here, on the GL thread, in declaration order; encoding and writing their
  // files and comparing them with the references (CPU only) run on worker threads, at most one
  // per core at a time, and their manifest entries are collected in the same order.
  std::vector<std::pair<size_t, std::future<json>>> pending;
  size_t waited = 0;
  const size_t workers = std::max(1u, std::thread::hardware_concurrency());
  // The references are of the scene's own light and sky: a run that changes the scene's
  // physics (parameters declared groundTruth()) is not compared with them.
  std::string physicsChanged;
  for (const auto& [name, desc] : cursor_->params().descs())
    if (desc.changesGroundTruth && !ParamDesc::sameValue(cursor_->params().value(name), desc.defaultValue))
      physicsChanged += (physicsChanged.empty() ? "" : ", ") + name + "=" + desc.format(cursor_->params().value(name));
  for (int i = 0; i <= untilStage_; ++i) {
    const StageRecord& r = cursor_->record(i);
    json s;
    s["id"] = t.stage(i).id();
    s["title"] = t.stage(i).title();
    s["state"] = r.state == StageState::NotRun && !cursor_->demandsEverything() ? "not needed" : stageStateName(r.state);
    s["cpu_ms"] = r.cpuMs;
    s["gpu_ms"] = r.gpuMs;
    s["iterations"] = r.iterationsRun;
    s["stats"] = r.stats;
    s["outputs"] = json::array();
    totalCpu += r.cpuMs;
    totalGpu += r.gpuMs;
    for (const auto& o : t.decl(i).outputs) {
      if (!cursor_->outputComputed(i, o.name)) continue;  // not needed by this run's demand
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
      auto cap = std::make_shared<CapturedOutput>(captureOutput(cursor_->board(), o));
      // The mode under this run's parameters ("indirect-{paths.bounces}" -> "indirect-2").
      cap->desc.referenceMode = referenceModeUnder(o, cursor_->params());
      if (onlyLevel >= 0) {
        if (onlyLevel >= int(cap->levels.size()))
          throw Error("output " + t.id() + "/" + t.stage(i).id() + "/" + o.name + " has levels 0.." +
                      std::to_string(int(cap->levels.size()) - 1) + ", not " + std::to_string(onlyLevel));
        cap->levels = {cap->levels[onlyLevel]};
      }
      std::string prefix = std::string(t.stage(i).id()) + "." + o.name +
                           (onlyLevel >= 0 ? "@" + std::to_string(onlyLevel) : "");
      std::string address = t.id() + "/" + t.stage(i).id() + "/" + o.name;
      // References are rendered from scene cameras; a free camera has none.
      const bool compare = !request_.lookFrom;
      std::string sceneName = cursor_->scene().name;
      int camera = request_.camera;
      while (pending.size() - waited >= workers) pending[waited++].second.wait();
      pending.emplace_back(size_t(i), std::async(std::launch::async, [=, name = o.name, help = o.help]() {
        json e = writeOutputFiles(*cap, dir, prefix);
        e["name"] = name;
        e["address"] = address;
        e["help"] = help;
        e["final"] = isFinal;
        // Outputs tagged with a reference mode: error against the checked-in ground truth, if any.
        json refErr;
        const std::string& mode = cap->desc.referenceMode;
        if (compare && !physicsChanged.empty() && !mode.empty() && fileExists(referenceImagePath(sceneName, mode)))
          refErr = {{"mode", mode},
                    {"skipped", "the run sets " + physicsChanged +
                                    "; the reference is of the scene's own light and sky"}};
        else if (compare)
          refErr = compareWithReference(*cap, sceneName, camera, dir, prefix);
        // The scene has references, but none of this output's mode: said, never replaced by another mode.
        if (compare && !mode.empty() && cap->desc.kind == OutputKind::Image2D &&
            !fileExists(referenceImagePath(sceneName, mode)) && hasReferences(sceneName))
          e["reference_missing"] = {{"mode", mode},
                                    {"reference", "tests/golden/reference/" + sceneName + "/" + mode + ".exr"}};
        if (!refErr.is_null()) {
          if (refErr.contains("files"))
            for (const auto& f : refErr["files"]) e["files"].push_back(f);
          e["reference_error"] = refErr;
        }
        return e;
      }));
    }
    stages.push_back(s);
  }
  for (auto& [stage, f] : pending) stages[stage]["outputs"].push_back(f.get());
  m["stages"] = stages;
  if (!request_.lookFrom && !physicsChanged.empty())
    m["references_skipped"] = "the run sets " + physicsChanged + "; the references are of the scene's own light and sky";
  m["total_cpu_ms"] = totalCpu;
  m["total_gpu_ms"] = totalGpu;
  m["resource_bytes"] = cursor_->board().totalBytes();
  m["complete"] = true;
  std::ofstream(dir + "/manifest.json") << m.dump(2) << "\n";
  return m;
}

}  // namespace voxlab
