#include "inspect/viewer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <deque>
#include <functional>
#include <optional>
#include <sstream>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include "capture/capture.h"
#include "capture/image_files.h"
#include "core/args.h"
#include "core/error.h"
#include "core/paths.h"
#include "gpu/gl.h"
#include "gpu/shader_library.h"
#include "graph/step_cursor.h"
#include "inspect/inspect_logic.h"
#include "inspect/scene_overlay.h"
#include "inspect/view3d.h"
#include "lesson/lesson.h"
#include "platform/glfw_window.h"
#include "scene/scene.h"

namespace voxlab {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

std::string fmtBytes(size_t b) {
  char buf[64];
  if (b >= (1u << 20)) std::snprintf(buf, sizeof buf, "%.1f MiB", double(b) / (1 << 20));
  else if (b >= 1024) std::snprintf(buf, sizeof buf, "%.1f KiB", double(b) / 1024);
  else std::snprintf(buf, sizeof buf, "%zu B", b);
  return buf;
}

// Reads an 8-bit image (PNG) as bytes (channels as stored) for the script's image comparisons.
std::vector<uint8_t> readImageBytes(const std::string& path, int& w, int& h) {
  ImageFileData img = readImageFile(path);
  w = img.width;
  h = img.height;
  std::vector<uint8_t> px(img.pixels.size());
  for (size_t i = 0; i < px.size(); ++i) px[i] = uint8_t(std::lround(std::clamp(img.pixels[i], 0.0f, 1.0f) * 255.0f));
  return px;
}

// A GL texture holding one RGBA8 image for ImGui::Image.
struct DisplayTexture {
  GLuint id = 0;
  int width = 0, height = 0;
  void upload(int w, int h, const uint8_t* rgba) {
    if (id == 0 || w != width || h != height) {
      if (id) glDeleteTextures(1, &id);
      glCreateTextures(GL_TEXTURE_2D, 1, &id);
      glTextureStorage2D(id, 1, GL_RGBA8, std::max(w, 1), std::max(h, 1));
      glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
      glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
      glObjectLabel(GL_TEXTURE, id, -1, "viewer.display");
      width = w;
      height = h;
    }
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(id, 0, 0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
  }
  ~DisplayTexture() {
    if (id) glDeleteTextures(1, &id);
  }
};

class Viewer {
 public:
  explicit Viewer(const ViewerOptions& o);
  ~Viewer();
  int loop();

 private:
  // --- state changes (shared by the UI, the keyboard, lessons and scripts) ---
  void switchTechnique(const std::string& id);
  bool loadSceneNamed(const std::string& name);  // false + sceneError_ on failure
  void selectStage(int i);
  void selectOutput(const std::string& name);
  void requestRun(int stage) { runTarget_ = std::max(runTarget_, std::min(stage, cursor_->stageCount() - 1)); }
  void paramsChanged() {
    if (autoRerun_) requestRun(std::max(selected_, lastRunRequest_));
  }
  void setCameraIndex(int i);
  // Orbit and fly move the live camera at once; the technique's camera follows whenever no stage is
  // queued, so overlays track the mouse while a slow render catches up.
  const Camera& liveCamera() const { return pendingCamera_ ? *pendingCamera_ : cursor_->camera(); }
  void moveCamera(const Camera& c);
  void applyPendingCamera();
  void orbit(float yawDeg, float pitchDeg);
  void handleFly();  // right mouse over a camera image: mouse looks, W/A/S/D/Q/E move
  void frameScene();
  // Queues iterations of the selected stage until 'count' of them have run (after the stages
  // before it); by default one more than now.
  void stepIteration(int count = -1) {
    const StageRecord& r = cursor_->record(selected_);
    iterateStage_ = selected_;
    iterateTo_ = count > 0 ? count : (r.state == StageState::Partial ? r.iterationsRun : 0) + 1;
  }
  void probePixel(int x, int y);
  void applyLessonStep(int i);
  // Rebuilds programs whose files changed. fromWatch: the periodic file check, which stays quiet
  // when nothing changed.
  void reloadShaders(bool fromWatch = false);
  std::string commandLine() const;
  SliceSpec sliceOf(const LevelData& level) const { return sliceToShow(level, slice_); }
  int probeStage() const;  // stage with a ConeSamples output and probe.x/probe.y params, or -1
  // An image at the view's size from a stage whose results depend on the camera
  // (Technique::dependsOnView): probing and scene overlays apply to these.
  bool isCameraImage(int stage, const CapturedOutput& c) const;

  // --- per frame ---
  bool runPendingStage();  // runs at most one stage; true when one ran
  void refreshCapture();
  void drawUi();
  void drawLeftPanel();
  void drawView();
  // 3D views (View3D) of volumes and of buffers with a Position field.
  bool has3DView(const OutputDesc& d) const;
  bool update3D();  // builds the 3D content and renders it when anything shown changed; false = no 3D view
  void build3DContent();
  void draw3DView();
  void drawRightPanel();
  void drawInspector();
  void drawProbe();
  void drawStatsTable(const char* id, const nlohmann::json& stats);
  // Scene overlays over camera images: voxels of a volume level and the volume's bounds.
  void drawOverlayControls();
  void updateOverlay();  // re-renders the overlay when anything it shows changed
  std::vector<std::string> overlayVolumes() const;  // "stage/output" of every volume that has run
  void drawTiming();
  void drawLesson();
  void drawExport();
  void handleKeys();
  void takeScreenshot(const std::string& path);
  // Rebuilds the font at the scale's size and scales the style (outside a frame); Ctrl+= / Ctrl+-
  // and the Camera/Export tab change it.
  void applyUiScale(float scale);
  float uiScale_ = 1.0f, wantUiScale_ = 1.0f;
  // What the view panel shows: the 3D view, or the image with its overlay blended in.
  DisplayImage viewportImage() const;

  // --- script ---
  bool scriptBusy() const {
    return runTarget_ >= 0 || iterateStage_ >= 0 || pendingCamera_ || !pendingScreenshot_.empty() || waitFrames_ > 0;
  }
  void stepScript();
  void execute(const ScriptAction& a);
  [[noreturn]] void scriptFail(const ScriptAction& a, const std::string& msg) const;
  // Expands walk-stages into the actions that walk every stage and output of the technique.
  std::vector<ScriptAction> walkStagesActions(const ScriptAction& a) const;
  void printFrameStats() const;

  ViewerOptions opt_;
  std::unique_ptr<GlfwWindow> window_;
  std::unique_ptr<ShaderLibrary> shaders_;
  std::unique_ptr<StepCursor> cursor_;
  std::shared_ptr<const Scene> scene_;
  std::string sceneName_;
  std::string sceneError_, shaderError_, status_;
  char scenePath_[512] = {0};

  int selected_ = 0;          // selected stage
  int outputIndex_ = 0;       // output of the selected stage
  int level_ = 0;
  SliceSpec slice_;
  DisplaySettings display_;
  int cameraIndex_ = 0;       // scene camera in use (-1 after an orbit or fly)
  std::optional<Camera> pendingCamera_;
  bool flying_ = false;
  double lastFlyTime_ = 0.0;
  int runTarget_ = -1;        // stage to run through, one stage per frame (-1 = idle)
  int iterateStage_ = -1;     // stage to run iterations of, after the stages before it (-1 = none)
  int iterateTo_ = 0;         // ... until this many of its iterations have run
  std::vector<std::deque<std::pair<float, float>>> timeHistory_;  // per stage: (cpu, gpu) ms of recent runs
  int lastRunRequest_ = -1;
  bool autoRerun_ = true;
  bool watchShaders_ = true;     // rebuild programs when their files change on disk
  double lastShaderCheck_ = 0.0;
  long generation_ = 0;       // bumps whenever a stage runs or the technique/scene changes

  // Capture of the selected output (refreshed when selection or generation changes).
  CapturedOutput cap_;
  nlohmann::json capStats_, capRecords_;  // of cap_, computed once per capture (not per frame)
  std::string capError_;
  long capKey_[4] = {-1, -1, -1, -1};
  long texKey_[8] = {0};
  DisplayTexture viewTex_;
  SliceImage viewImage_;
  std::vector<ConeSeries> cones_;
  bool hover_ = false;
  glm::ivec3 hoverTexel_{0}, pickTexel_{-1};
  bool dragging_ = false, orbiting_ = false;
  ImVec2 dragStart_{0, 0};

  // Scene overlay.
  std::unique_ptr<SceneOverlay> overlay_;
  SceneOverlay::Options overlayOpt_{false, false, false, 0.6f};
  std::string overlayVolume_;  // "stage/output"; "" = the latest volume before the selected stage
  int overlayLevel_ = -1;      // -1 = the finest level with at most 32 texels per axis
  int overlayLevelCount_ = 1;  // levels of the overlaid volume (for the slider)
  std::string overlayKey_, overlayContentKey_, overlayMsg_;
  double overlayMs_ = 0.0;

  Lesson lesson_;
  int lessonStep_ = -1;

  std::vector<ScriptAction> script_;
  size_t pc_ = 0;
  int waitFrames_ = 0;
  std::string pendingScreenshot_;
  int screenshotDelay_ = 0;
  bool quit_ = false;
  bool scripted_ = false;

  std::vector<double> idleFrameMs_;  // frames where no stage ran and no capture was refreshed
  bool frameHeavy_ = false;
  std::string copied_;
  std::string wantTab_;  // tab to bring to front on the next frame ("" = leave as is)

  // 3D views.
  ViewMode viewMode_ = ViewMode::Slice;
  std::unique_ptr<View3D> view3d_;
  OrbitCamera orbit3d_;
  const Scene* orbitScene_ = nullptr;  // the orbit starts along the scene camera once per scene
  long content3dKey_[7] = {-1, -1, -1, -1, -1, -1, -1};
  double render3dKey_[6] = {-1, 0, 0, 0, 0, 0};
  std::string info3d_, msg3d_;
  std::vector<double> render3dMs_;
  bool dragging3d_ = false;
  bool scriptDragging_ = false;  // view-dragging on: render as while the mouse drags
};

// --- Construction ------------------------------------------------------------------------------

Viewer::Viewer(const ViewerOptions& o) : opt_(o) {
  // Validate input that needs no window first, so bad options fail with one line.
  createTechnique(o.technique);
  if (!o.lesson.empty()) lesson_ = loadLesson(o.lesson);
  if (!o.script.empty()) {
    if (!fileExists(o.script)) throw Error("script file '" + o.script + "' does not exist");
    script_ = parseScript(readTextFile(o.script), o.script);
    scripted_ = true;
  }
  auto scene = std::make_shared<Scene>(loadScene(resolveScenePath(o.scene)));

  window_ = std::make_unique<GlfwWindow>(o.windowWidth, o.windowHeight, "voxlab");
  shaders_ = std::make_unique<ShaderLibrary>();
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // layout is fixed; no imgui.ini next to the binary
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window_->handle(), true);
  ImGui_ImplOpenGL3_Init("#version 450 core");
  applyUiScale(o.uiScale);

  scene_ = scene;
  sceneName_ = o.scene;
  std::snprintf(scenePath_, sizeof scenePath_, "%s", o.scene.c_str());
  switchTechnique(o.technique);
  if (!lesson_.steps.empty()) {
    applyLessonStep(0);
  } else if (!scripted_) {
    // A person opening the viewer sees the technique run, stage by stage, to its final image;
    // scripts start from nothing run and drive every step themselves.
    const int last = cursor_->stageCount() - 1;
    selectStage(last);
    lastRunRequest_ = last;
    requestRun(last);
  }
}

Viewer::~Viewer() {
  view3d_.reset();
  cursor_.reset();
  shaders_.reset();
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
}

// --- State changes -----------------------------------------------------------------------------

void Viewer::switchTechnique(const std::string& id) {
  auto t = createTechnique(id);
  cursor_ = std::make_unique<StepCursor>(std::move(t), *shaders_);
  cursor_->setScene(scene_);
  cursor_->setViewSize(opt_.width, opt_.height);
  cameraIndex_ = 0;
  selected_ = 0;
  outputIndex_ = 0;
  level_ = 0;
  runTarget_ = lastRunRequest_ = iterateStage_ = -1;
  pendingCamera_.reset();
  timeHistory_.assign(cursor_->stageCount(), {});
  overlayVolume_.clear();
  overlayLevel_ = -1;
  ++generation_;
}

bool Viewer::loadSceneNamed(const std::string& name) {
  try {
    auto scene = std::make_shared<Scene>(loadScene(resolveScenePath(name)));
    scene_ = scene;
    sceneName_ = name;
    cursor_->setScene(scene_);
    cursor_->setViewSize(opt_.width, opt_.height);
    cameraIndex_ = 0;
    runTarget_ = iterateStage_ = -1;
    pendingCamera_.reset();
    sceneError_.clear();
    ++generation_;
    if (autoRerun_ && lastRunRequest_ >= 0) requestRun(lastRunRequest_);
    return true;
  } catch (const Error& e) {
    sceneError_ = e.what();  // keep the current scene
    return false;
  }
}

void Viewer::selectStage(int i) {
  i = std::clamp(i, 0, cursor_->stageCount() - 1);
  if (i != selected_) {
    // The final stage opens on the technique's final output; any other stage on its first output.
    outputIndex_ = 0;
    const Technique& t = cursor_->technique();
    if (t.finalStage() == t.stage(i).id()) {
      const auto& outs = t.decl(i).outputs;
      for (size_t k = 0; k < outs.size(); ++k)
        if (outs[k].name == t.finalOutput()) outputIndex_ = int(k);
    }
    level_ = 0;
    pickTexel_ = glm::ivec3(-1);
  }
  selected_ = i;
}

void Viewer::selectOutput(const std::string& name) {
  const auto& outs = cursor_->technique().decl(selected_).outputs;
  for (size_t k = 0; k < outs.size(); ++k)
    if (outs[k].name == name) {
      outputIndex_ = int(k);
      return;
    }
  cursor_->technique().findOutput(cursor_->technique().stage(selected_).id(), name);  // throws listing names
}

void Viewer::setCameraIndex(int i) {
  cursor_->useSceneCamera(i);
  pendingCamera_.reset();
  cameraIndex_ = i;
  paramsChanged();
}

void Viewer::moveCamera(const Camera& c) {
  pendingCamera_ = c;
  cameraIndex_ = -1;
}

void Viewer::applyPendingCamera() {
  if (!pendingCamera_ || runTarget_ >= 0 || iterateStage_ >= 0) return;
  cursor_->setCamera(*pendingCamera_);
  pendingCamera_.reset();
  paramsChanged();
}

void Viewer::orbit(float yawDeg, float pitchDeg) {
  moveCamera(orbitCamera(liveCamera(), scene_->bounds.center(), yawDeg, pitchDeg));
}

void Viewer::handleFly() {
  ImGuiIO& io = ImGui::GetIO();
  double now = glfwGetTime();
  float dt = float(std::clamp(now - lastFlyTime_, 0.0, 0.1));  // a slow frame moves no further than a fast one
  lastFlyTime_ = now;
  Camera c = liveCamera();
  bool moved = false;
  if (io.MouseDelta.x != 0.0f || io.MouseDelta.y != 0.0f) {
    c = lookCamera(c, -io.MouseDelta.x * 0.25f, -io.MouseDelta.y * 0.25f);
    moved = true;
  }
  // Speed: a third of the scene's diagonal per second, four times that with Shift.
  float speed = 0.35f * glm::length(scene_->bounds.extent()) * (io.KeyShift ? 4.0f : 1.0f) * dt;
  auto axis = [](int plus, int minus) { return float(ImGui::IsKeyDown(plus)) - float(ImGui::IsKeyDown(minus)); };
  float f = axis(GLFW_KEY_W, GLFW_KEY_S), r = axis(GLFW_KEY_D, GLFW_KEY_A), u = axis(GLFW_KEY_E, GLFW_KEY_Q);
  if (f != 0.0f || r != 0.0f || u != 0.0f) {
    c = flyCamera(c, r * speed, u * speed, f * speed);
    moved = true;
  }
  if (moved) moveCamera(c);
}

void Viewer::frameScene() {
  moveCamera(frameBounds(scene_->bounds, liveCamera().yfov));
}

bool Viewer::isCameraImage(int stage, const CapturedOutput& c) const {
  if (c.desc.kind != OutputKind::Image2D || c.levels.empty()) return false;
  if (!cursor_->technique().dependsOnView(stage)) return false;
  return c.levels[0].size.x == cursor_->view().width && c.levels[0].size.y == cursor_->view().height;
}

int Viewer::probeStage() const {
  const Technique& t = cursor_->technique();
  for (int i = 0; i < t.stageCount(); ++i) {
    bool samples = false, px = false, py = false;
    for (const auto& o : t.decl(i).outputs) samples = samples || o.semantic == Semantic::ConeSamples;
    for (const auto& p : t.decl(i).params) {
      px = px || p.name == "probe.x";
      py = py || p.name == "probe.y";
    }
    if (samples && px && py) return i;
  }
  return -1;
}

void Viewer::probePixel(int x, int y) {
  int p = probeStage();
  if (p < 0) throw Error("technique " + cursor_->technique().id() + " has no stage with a cone-samples output and probe.x/probe.y");
  const ViewState& v = cursor_->view();
  x = std::clamp(x, 0, v.width - 1);
  y = std::clamp(y, 0, v.height - 1);
  cursor_->setParam("probe.x", (x + 0.5) / v.width);
  cursor_->setParam("probe.y", (y + 0.5) / v.height);
  requestRun(std::max(p, std::max(selected_, lastRunRequest_)));
  status_ = "probed pixel " + std::to_string(x) + "," + std::to_string(y);
  wantTab_ = "probe";
}

void Viewer::applyLessonStep(int i) {
  if (lesson_.steps.empty()) return;
  i = std::clamp(i, 0, int(lesson_.steps.size()) - 1);
  const LessonStep& s = lesson_.steps[i];
  if (s.technique != cursor_->technique().id()) switchTechnique(s.technique);
  if (s.scene != sceneName_ && !loadSceneNamed(s.scene))
    throw Error(lesson_.path + ":" + std::to_string(s.line) + ": " + sceneError_);
  ParamSet p = cursor_->technique().defaultParams();
  for (const auto& [n, v] : s.sets) p.setText(n, v);
  cursor_->setParams(p);
  if (s.camera != cameraIndex_ || pendingCamera_) {
    cursor_->useSceneCamera(s.camera);
    pendingCamera_.reset();
    cameraIndex_ = s.camera;
  }
  selectStage(cursor_->technique().stageIndex(s.stage));
  if (!s.output.empty()) selectOutput(s.output);
  level_ = s.level;
  if (lessonStep_ < 0) wantTab_ = "lesson";
  lessonStep_ = i;
  overlayOpt_.bounds = s.bounds;
  overlayOpt_.voxels = !s.overlay.empty();
  if (!s.overlay.empty()) {
    size_t at = s.overlay.find('@');
    overlayVolume_ = s.overlay.substr(0, at);
    overlayLevel_ = at == std::string::npos ? -1 : std::stoi(s.overlay.substr(at + 1));
  }
  if (s.iterations > 0) {
    // Stop the stage after that many iterations: run what comes before, then step it.
    cursor_->invalidate(selected_);
    stepIteration(s.iterations);
    return;
  }
  lastRunRequest_ = selected_;
  requestRun(selected_);
}

void Viewer::reloadShaders(bool fromWatch) {
  auto errors = shaders_->reloadChanged();
  if (fromWatch && errors.empty() && shaders_->lastReloadCount() == 0) return;
  if (errors.empty()) {
    shaderError_.clear();
    cursor_->invalidateAll();
    status_ = "shaders reloaded; every stage is stale";
    if (autoRerun_ && lastRunRequest_ >= 0) requestRun(lastRunRequest_);
  } else {
    shaderError_ = joinNames(errors, "\n");  // the last good programs stay in use
    status_ = "shader reload failed";
  }
}

std::string Viewer::commandLine() const {
  const Technique& t = cursor_->technique();
  std::string until = selected_ == t.stageCount() - 1 ? "" : t.stage(selected_).id();
  // A scene camera by its index; an orbit or fly camera as --look-from/--look-at (with camera 0's field
  // of view, which orbit and fly keep).
  return reproduceCommand(t.id(), sceneName_, cursor_->params(), t.defaultParams(), cursor_->view().width,
                          cursor_->view().height, std::max(cameraIndex_, 0), until, "out",
                          cameraIndex_ < 0 ? &liveCamera() : nullptr);
}

// --- Per frame -----------------------------------------------------------------------------------

bool Viewer::runPendingStage() {
  // One stage (or one iteration) per frame, so the window stays live while a technique runs.
  const int target = iterateStage_ >= 0 ? iterateStage_ : runTarget_;
  if (target < 0) return false;
  // The first stage that is not Done: before the iterated stage, or up to the run target.
  int next = -1;
  for (int i = 0; i < target + (iterateStage_ >= 0 ? 0 : 1) && next < 0; ++i)
    if (cursor_->record(i).state != StageState::Done) next = i;
  if (next < 0 && iterateStage_ < 0) {
    lastRunRequest_ = std::max(lastRunRequest_, runTarget_);
    runTarget_ = -1;
    return false;
  }
  const int ran = next >= 0 ? next : target;
  try {
    if (next >= 0 && cursor_->iterations(next) > 1) {
      cursor_->runIteration(next);  // iterative stages one iteration per frame: the timeline shows progress
    } else if (next >= 0) {
      cursor_->runThrough(next);  // earlier stages are Done, so this runs exactly one stage
    } else {
      int k = cursor_->runIteration(target);
      if (k + 1 >= iterateTo_ || cursor_->record(target).state == StageState::Done) iterateStage_ = -1;
      status_ = std::string(cursor_->technique().stage(target).id()) + ": iteration " + std::to_string(k + 1) + " of " +
                std::to_string(cursor_->record(target).iterationsTotal);
    }
  } catch (const ShaderError& e) {
    shaderError_ = e.what();
    runTarget_ = iterateStage_ = -1;
    if (scripted_) throw;
  }
  const StageRecord& r = cursor_->record(ran);
  if (r.state == StageState::Done) {
    auto& h = timeHistory_.at(ran);
    h.emplace_back(float(r.cpuMs), float(r.gpuMs));
    if (h.size() > 32) h.pop_front();
  }
  ++generation_;
  return true;
}

void Viewer::refreshCapture() {
  const Technique& t = cursor_->technique();
  const auto& outs = t.decl(selected_).outputs;
  if (outs.empty()) {
    capError_ = "this stage declares no outputs";
    cap_ = CapturedOutput();
    return;
  }
  outputIndex_ = std::clamp(outputIndex_, 0, int(outs.size()) - 1);
  long key[4] = {long(cursor_.get() != nullptr ? generation_ : 0), selected_, outputIndex_, 0};
  if (std::equal(key, key + 4, capKey_)) return;
  std::copy(key, key + 4, capKey_);
  frameHeavy_ = true;
  cones_.clear();
  const StageRecord& r = cursor_->record(selected_);
  cap_ = CapturedOutput();
  cap_.desc = outs[outputIndex_];
  capStats_ = capRecords_ = nlohmann::json();
  capError_.clear();
  if (r.state == StageState::NotRun) {
    capError_ = "not run yet: press Run to here (R)";
    return;
  }
  try {
    cap_ = captureOutput(cursor_->board(), outs[outputIndex_]);
  } catch (const Error& e) {
    capError_ = e.what();
    return;
  }
  if (cap_.desc.semantic == Semantic::ConeSamples) cones_ = decodeConeSamples(cap_);
  capStats_ = outputStatistics(cap_);
  capRecords_ = cap_.desc.kind == OutputKind::Buffer ? recordsJson(cap_, 32) : nlohmann::json();
}

void Viewer::handleKeys() {
  ImGuiIO& io = ImGui::GetIO();
  if (io.WantCaptureKeyboard || flying_) return;  // while flying, W/A/S/D/Q/E move the camera
  if (ImGui::IsKeyPressed(GLFW_KEY_I) && cursor_->iterations(selected_) > 1) stepIteration();
  if (ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_RightArrow))) {
    selectStage(selected_ + 1);
    lastRunRequest_ = std::max(lastRunRequest_, selected_);
    requestRun(selected_);
  }
  if (ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_LeftArrow))) selectStage(selected_ - 1);
  if (ImGui::IsKeyPressed(GLFW_KEY_R)) {
    lastRunRequest_ = std::max(lastRunRequest_, selected_);
    requestRun(selected_);
  }
  if (ImGui::IsKeyPressed(GLFW_KEY_A)) {
    lastRunRequest_ = cursor_->stageCount() - 1;
    requestRun(lastRunRequest_);
  }
  if (ImGui::IsKeyPressed(GLFW_KEY_F5)) reloadShaders();
  if (io.KeyCtrl && (ImGui::IsKeyPressed(GLFW_KEY_EQUAL) || ImGui::IsKeyPressed(GLFW_KEY_KP_ADD))) wantUiScale_ = uiScale_ + 0.25f;
  if (io.KeyCtrl && (ImGui::IsKeyPressed(GLFW_KEY_MINUS) || ImGui::IsKeyPressed(GLFW_KEY_KP_SUBTRACT)))
    wantUiScale_ = uiScale_ - 0.25f;
  // Watch the shader files: about once a second, rebuild the programs whose files changed.
  if (watchShaders_ && glfwGetTime() - lastShaderCheck_ > 1.0) {
    lastShaderCheck_ = glfwGetTime();
    reloadShaders(true);
  }
  if (ImGui::IsKeyPressed(GLFW_KEY_PAGE_DOWN) && !lesson_.steps.empty()) applyLessonStep(lessonStep_ + 1);
  if (ImGui::IsKeyPressed(GLFW_KEY_PAGE_UP) && !lesson_.steps.empty()) applyLessonStep(lessonStep_ - 1);
}

void Viewer::applyUiScale(float scale) {
  scale = std::clamp(scale, 0.75f, 3.0f);
  ImGuiIO& io = ImGui::GetIO();
  io.Fonts->Clear();
  ImFontConfig font;
  font.SizePixels = std::round(13.0f * scale);  // the default font is drawn for 13 px
  io.Fonts->AddFontDefault(&font);
  ImGui_ImplOpenGL3_DestroyFontsTexture();
  ImGui_ImplOpenGL3_CreateFontsTexture();
  ImGuiStyle style;
  ImGui::StyleColorsDark(&style);
  style.ScaleAllSizes(scale);
  ImGui::GetStyle() = style;
  uiScale_ = wantUiScale_ = scale;
}

void Viewer::takeScreenshot(const std::string& path) {
  int w, h;
  window_->framebufferSize(w, h);
  std::vector<uint8_t> rgba(size_t(w) * h * 4);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  DisplayImage img;
  img.width = w;
  img.height = h;
  img.rgb.resize(size_t(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        img.rgb[(size_t(h - 1 - y) * w + x) * 3 + c] = rgba[(size_t(y) * w + x) * 4 + c];
  std::error_code ec;
  fs::path p(path);
  if (p.has_parent_path()) fs::create_directories(p.parent_path(), ec);
  writePng(img, path);
}

DisplayImage Viewer::viewportImage() const {
  DisplayImage img;
  if (viewMode_ != ViewMode::Slice && view3d_ && has3DView(cap_.desc)) {
    std::vector<uint8_t> px = view3d_->readPixels();  // kSize^2, bottom row first; the render fills a corner
    int n = view3d_->lastSize();
    img.width = img.height = n;
    for (int y = n - 1; y >= 0; --y)
      for (int x = 0; x < n; ++x)
        img.rgb.insert(img.rgb.end(), &px[(size_t(y) * View3D::kSize + x) * 4], &px[(size_t(y) * View3D::kSize + x) * 4] + 3);
    return img;
  }
  img.width = viewImage_.width;
  img.height = viewImage_.height;
  std::vector<uint8_t> over;
  if (overlay_ && !overlayKey_.empty() && isCameraImage(selected_, cap_)) over = overlay_->readPixels();
  const bool blend = over.size() == size_t(img.width) * img.height * 4;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = &viewImage_.rgba[(size_t(y) * img.width + x) * 4];
      const uint8_t* o = blend ? &over[(size_t(img.height - 1 - y) * img.width + x) * 4] : nullptr;
      for (int c = 0; c < 3; ++c) {
        float v = p[c];
        if (o) v = v + (o[c] - v) * (o[3] / 255.0f);  // as ImGui draws it: source alpha over the image
        img.rgb.push_back(uint8_t(std::lround(v)));
      }
    }
  return img;
}

int Viewer::loop() {
  while (!window_->shouldClose() && !quit_) {
    auto t0 = Clock::now();
    frameHeavy_ = false;
    window_->pollEvents();
    if (scripted_) stepScript();
    if (quit_) break;
    if (runPendingStage()) frameHeavy_ = true;
    applyPendingCamera();
    if (wantUiScale_ != uiScale_) {
      applyUiScale(wantUiScale_);
      frameHeavy_ = true;
    }

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    handleKeys();
    refreshCapture();
    drawUi();
    ImGui::Render();
    int w, h;
    window_->framebufferSize(w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, w, h);
    glClearColor(0.08f, 0.08f, 0.09f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    if (!pendingScreenshot_.empty() && --screenshotDelay_ <= 0) {
      takeScreenshot(pendingScreenshot_);
      std::printf("screenshot %s\n", pendingScreenshot_.c_str());
      pendingScreenshot_.clear();
      frameHeavy_ = true;
    }
    window_->swapBuffers();
    glFinish();  // count the frame's GPU work (llvmpipe) in its time
    double ms = msSince(t0);
    if (!frameHeavy_) idleFrameMs_.push_back(ms);
    if (waitFrames_ > 0) --waitFrames_;
  }
  if (scripted_) printFrameStats();
  return 0;
}

// --- UI --------------------------------------------------------------------------------------------


void Viewer::drawUi() {
  ImGuiIO& io = ImGui::GetIO();
  // Side panels grow with the UI scale but leave the view at least 40 % of the window.
  const float kLeftWidth = std::min(330.0f * uiScale_, 0.28f * io.DisplaySize.x);
  const float kRightWidth = std::min(380.0f * uiScale_, 0.32f * io.DisplaySize.x);
  ImGuiWindowFlags fixed = ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse;
  ImGui::SetNextWindowPos(ImVec2(0, 0));
  ImGui::SetNextWindowSize(ImVec2(kLeftWidth, io.DisplaySize.y));
  ImGui::Begin("Technique", nullptr, fixed);
  drawLeftPanel();
  ImGui::End();

  ImGui::SetNextWindowPos(ImVec2(kLeftWidth, 0));
  ImGui::SetNextWindowSize(ImVec2(io.DisplaySize.x - kLeftWidth - kRightWidth, io.DisplaySize.y));
  ImGui::Begin("View", nullptr, fixed);
  drawView();
  ImGui::End();

  ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - kRightWidth, 0));
  ImGui::SetNextWindowSize(ImVec2(kRightWidth, io.DisplaySize.y));
  ImGui::Begin("Details", nullptr, fixed);
  drawRightPanel();
  ImGui::End();
}

void Viewer::drawLeftPanel() {
  Technique& t = cursor_->technique();
  // Technique and scene pickers.
  if (ImGui::BeginCombo("technique", t.id().c_str())) {
    for (const auto& e : techniqueRegistry())
      if (ImGui::Selectable(e.id.c_str(), e.id == t.id()) && e.id != t.id()) switchTechnique(e.id);
    ImGui::EndCombo();
  }
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", t.title().c_str());
  if (ImGui::BeginCombo("scene", scene_->name.c_str())) {
    std::error_code ec;
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(projectPath("scenes"), ec)) {
      auto ext = e.path().extension().string();
      if (ext == ".gltf" || ext == ".glb") names.push_back(e.path().stem().string());
    }
    std::sort(names.begin(), names.end());
    for (const auto& n : names)
      if (ImGui::Selectable(n.c_str(), n == scene_->name)) loadSceneNamed(n);
    ImGui::EndCombo();
  }
  ImGui::InputText("##scenepath", scenePath_, sizeof scenePath_);
  ImGui::SameLine();
  if (ImGui::Button("Load")) loadSceneNamed(scenePath_);
  if (!sceneError_.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", sceneError_.c_str());

  // Stage timeline.
  ImGui::Separator();
  ImGui::TextUnformatted("Stages");
  for (int i = 0; i < t.stageCount(); ++i) {
    const StageRecord& r = cursor_->record(i);
    ImVec4 col = r.state == StageState::Done    ? ImVec4(0.4f, 0.9f, 0.4f, 1)
                 : r.state == StageState::Stale ? ImVec4(0.95f, 0.75f, 0.3f, 1)
                                                : ImVec4(0.6f, 0.6f, 0.6f, 1);
    bool running = (runTarget_ >= i && r.state != StageState::Done) || iterateStage_ == i;
    char state[48];
    if (r.state == StageState::Partial)
      std::snprintf(state, sizeof state, "partial %d/%d", r.iterationsRun, r.iterationsTotal);
    else
      std::snprintf(state, sizeof state, "%s", running ? "(queued)" : stageStateName(r.state));
    char label[160];
    std::snprintf(label, sizeof label, "%d. %-14s %s##stage%d", i + 1, t.stage(i).id(), state, i);
    ImGui::PushStyleColor(ImGuiCol_Text, col);
    if (ImGui::Selectable(label, selected_ == i)) selectStage(i);
    ImGui::PopStyleColor();
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s\n%s", t.stage(i).title(), t.stage(i).summary());
  }
  if (ImGui::Button("< Prev")) selectStage(selected_ - 1);
  ImGui::SameLine();
  if (ImGui::Button("Next >")) {
    selectStage(selected_ + 1);
    lastRunRequest_ = std::max(lastRunRequest_, selected_);
    requestRun(selected_);
  }
  ImGui::SameLine();
  if (ImGui::Button("Run to here")) {
    lastRunRequest_ = std::max(lastRunRequest_, selected_);
    requestRun(selected_);
  }
  ImGui::SameLine();
  if (ImGui::Button("Run all")) {
    lastRunRequest_ = t.stageCount() - 1;
    requestRun(lastRunRequest_);
  }
  const int iterations = cursor_->iterations(selected_);
  if (iterations > 1) {
    const StageRecord& r = cursor_->record(selected_);
    if (ImGui::Button("Step iteration")) stepIteration();
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("run the next of this stage's %d iterations (after the stages before it)", iterations);
    ImGui::SameLine();
    if (r.state == StageState::Partial)
      ImGui::Text("iteration %d of %d done", r.iterationsRun, r.iterationsTotal);
    else
      ImGui::TextDisabled("%d iterations", iterations);
  }
  ImGui::TextDisabled("keys: Left/Right stage, R run, A all, I iteration, F5 reload");
  if (runTarget_ >= 0) ImGui::TextColored(ImVec4(0.95f, 0.75f, 0.3f, 1), "running through stage %d ...", runTarget_ + 1);

  // Parameters, generated from the declarations of every stage.
  ImGui::Separator();
  ImGui::Checkbox("auto re-run", &autoRerun_);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("after a change, re-run the stale stages up to the last run one");
  ImGui::SameLine();
  if (ImGui::Button("Defaults")) {
    cursor_->setParams(t.defaultParams());
    paramsChanged();
  }
  ImGui::BeginChild("params", ImVec2(0, 0), false);
  for (int i = 0; i < t.stageCount(); ++i) {
    const auto& decl = t.decl(i);
    if (decl.params.empty()) continue;
    bool open = ImGui::TreeNodeEx(t.stage(i).id(), i == selected_ ? ImGuiTreeNodeFlags_DefaultOpen : 0);
    if (!open) continue;
    for (const auto& p : decl.params) {
      ImGui::PushID((std::to_string(i) + p.name).c_str());
      double v = cursor_->params().value(p.name);
      double nv = v;
      switch (p.type) {
        case ParamType::Int: {
          int iv = int(v);
          if (ImGui::SliderInt(p.name.c_str(), &iv, int(p.minValue), int(p.maxValue))) {
            if (p.powerOfTwo) {
              int k = 1;
              while (k < iv) k <<= 1;
              iv = (k - iv <= iv - k / 2) ? k : k / 2;
              iv = std::clamp(iv, int(p.minValue), int(p.maxValue));
            }
            nv = iv;
          }
          break;
        }
        case ParamType::Float: {
          float fv = float(v);
          if (ImGui::SliderFloat(p.name.c_str(), &fv, float(p.minValue), float(p.maxValue), "%.3f")) nv = fv;
          break;
        }
        case ParamType::Bool: {
          bool b = v != 0.0;
          if (ImGui::Checkbox(p.name.c_str(), &b)) nv = b ? 1.0 : 0.0;
          break;
        }
        case ParamType::Choice: {
          int c = int(v);
          if (ImGui::BeginCombo(p.name.c_str(), p.choices.at(c).c_str())) {
            for (size_t k = 0; k < p.choices.size(); ++k)
              if (ImGui::Selectable(p.choices[k].c_str(), int(k) == c)) nv = double(k);
            ImGui::EndCombo();
          }
          break;
        }
      }
      if (ImGui::IsItemHovered())
        ImGui::SetTooltip("%s\n%s%s%s", p.help.c_str(), p.rangeText().c_str(), p.unit.empty() ? "" : ", ",
                          p.unit.c_str());
      if (nv != v) {
        try {
          cursor_->setParam(p.name, nv);  // marks every stage that declares it (and its readers) stale
          paramsChanged();
        } catch (const Error& e) {
          status_ = e.what();
        }
      }
      ImGui::PopID();
    }
    ImGui::TreePop();
  }
  ImGui::EndChild();
}

void Viewer::drawView() {
  const Technique& t = cursor_->technique();
  const StageRecord& rec = cursor_->record(selected_);
  const auto& outs = t.decl(selected_).outputs;
  ImGui::Text("%s / %s", t.id().c_str(), t.stage(selected_).title());
  if (!outs.empty()) {
    ImGui::SameLine();
    ImGui::SetNextItemWidth(200);
    if (ImGui::BeginCombo("output", outs[outputIndex_].name.c_str())) {
      for (size_t k = 0; k < outs.size(); ++k)
        if (ImGui::Selectable(outs[k].name.c_str(), int(k) == outputIndex_)) {
          outputIndex_ = int(k);
          level_ = 0;
          pickTexel_ = glm::ivec3(-1);
        }
      ImGui::EndCombo();
    }
  }
  if (rec.state == StageState::Stale) ImGui::TextColored(ImVec4(0.95f, 0.75f, 0.3f, 1), "stale: showing the last run's data");
  if (!capError_.empty()) {
    ImGui::TextWrapped("%s", capError_.c_str());
    return;
  }
  const OutputDesc& d = cap_.desc;
  ImGui::TextDisabled("%s, %s, %s: %s", kindName(d.kind), semanticName(d.semantic), cap_.format.c_str(), d.help.c_str());
  if (has3DView(d)) {
    int mode = int(viewMode_);
    ImGui::TextUnformatted("view");
    ImGui::SameLine();
    ImGui::RadioButton(d.kind == OutputKind::Buffer ? "points 2D" : "slice", &mode, int(ViewMode::Slice));
    ImGui::SameLine();
    ImGui::RadioButton("3D", &mode, int(ViewMode::Volume));
    ImGui::SameLine();
    ImGui::RadioButton("cubes", &mode, int(ViewMode::Cubes));
    viewMode_ = ViewMode(mode);
    if (viewMode_ != ViewMode::Slice) {
      draw3DView();
      return;
    }
  }

  // Build the displayed image: a slice of the selected level, or the point view of a buffer.
  long key[8] = {capKey_[0], capKey_[1], capKey_[2], level_, slice_.axis, slice_.index, display_.channel,
                 long(display_.exposure * 1000)};
  bool isBuffer = d.kind == OutputKind::Buffer;
  if (!std::equal(key, key + 8, texKey_)) {
    std::copy(key, key + 8, texKey_);
    frameHeavy_ = true;
    if (isBuffer) {
      DisplayImage pv = pointView(cap_, 512);
      viewImage_ = SliceImage();
      viewImage_.width = pv.width;
      viewImage_.height = pv.height;
      viewImage_.rgba.resize(size_t(pv.width) * pv.height * 4);
      for (size_t i = 0; i < size_t(pv.width) * pv.height; ++i) {
        for (int c = 0; c < 3; ++c) viewImage_.rgba[i * 4 + c] = pv.rgb[i * 3 + c];
        viewImage_.rgba[i * 4 + 3] = 255;
      }
    } else if (!cap_.levels.empty()) {
      level_ = std::clamp(level_, 0, int(cap_.levels.size()) - 1);
      viewImage_ = mapSlice(cap_.levels[level_], d.semantic, sliceOf(cap_.levels[level_]), display_);
    } else {
      viewImage_ = SliceImage();
    }
    if (viewImage_.width > 0) viewTex_.upload(viewImage_.width, viewImage_.height, viewImage_.rgba.data());
  }
  if (viewImage_.width == 0) return;
  const bool cameraImage = !isBuffer && isCameraImage(selected_, cap_);
  if (cameraImage) drawOverlayControls();

  // Fit the image into the panel, keeping its aspect; nearest filtering shows voxels as squares.
  ImVec2 avail = ImGui::GetContentRegionAvail();
  avail.y -= 60;
  float scale = std::min(avail.x / viewImage_.width, avail.y / viewImage_.height);
  ImVec2 size(viewImage_.width * scale, viewImage_.height * scale);
  ImVec2 origin = ImGui::GetCursorScreenPos();
  ImGui::Image(reinterpret_cast<ImTextureID>(intptr_t(viewTex_.id)), size);
  hover_ = false;
  bool imageHovered = ImGui::IsItemHovered();
  ImVec2 m = ImGui::GetIO().MousePos;
  int px = int((m.x - origin.x) / scale), py = int((m.y - origin.y) / scale);
  if (imageHovered && !isBuffer && px >= 0 && py >= 0 && px < viewImage_.width && py < viewImage_.height) {
    hover_ = true;
    hoverTexel_ = sliceTexel(cap_.levels[level_], sliceOf(cap_.levels[level_]), px, py);
  }
  // Camera images: the overlay (voxels, bounds) drawn with the live camera over the image.
  auto* dl = ImGui::GetWindowDrawList();
  if (cameraImage) {
    updateOverlay();
    if (!overlayKey_.empty())
      dl->AddImage(reinterpret_cast<ImTextureID>(intptr_t(overlay_->texture())), origin,
                   ImVec2(origin.x + size.x, origin.y + size.y), ImVec2(0, 1), ImVec2(1, 0));
  }
  // On camera images a left drag orbits the camera and a right drag flies it (mouse looks,
  // W/A/S/D/Q/E move); a left click probes or picks.
  ImGuiIO& io = ImGui::GetIO();
  if (imageHovered && ImGui::IsMouseClicked(ImGuiMouseButton_Left)) {
    dragging_ = true;
    orbiting_ = false;
    dragStart_ = m;
  }
  if (dragging_) {
    if (cameraImage && !orbiting_ && std::abs(m.x - dragStart_.x) + std::abs(m.y - dragStart_.y) > 4.0f) orbiting_ = true;
    if (orbiting_ && (io.MouseDelta.x != 0.0f || io.MouseDelta.y != 0.0f)) orbit(-io.MouseDelta.x * 0.3f, io.MouseDelta.y * 0.3f);
    if (ImGui::IsMouseReleased(ImGuiMouseButton_Left)) {
      dragging_ = false;
      if (!orbiting_ && hover_) {
        pickTexel_ = hoverTexel_;
        if (cameraImage && probeStage() >= 0) probePixel(px, py);
      }
      orbiting_ = false;
    }
  }
  if (cameraImage && imageHovered && ImGui::IsMouseClicked(ImGuiMouseButton_Right)) {
    flying_ = true;
    lastFlyTime_ = glfwGetTime();
  }
  if (flying_) {
    if (!ImGui::IsMouseDown(ImGuiMouseButton_Right)) flying_ = false;
    else handleFly();
  }
  // Mark the probed pixel on camera images.
  if (cameraImage && probeStage() >= 0) {
    float qx = origin.x + float(cursor_->params().value("probe.x")) * size.x;
    float qy = origin.y + float(cursor_->params().value("probe.y")) * size.y;
    dl->AddCircle(ImVec2(qx, qy), 6.0f, IM_COL32(255, 60, 200, 255), 12, 2.0f);
    dl->AddLine(ImVec2(qx - 10, qy), ImVec2(qx + 10, qy), IM_COL32(255, 60, 200, 255));
    dl->AddLine(ImVec2(qx, qy - 10), ImVec2(qx, qy + 10), IM_COL32(255, 60, 200, 255));
  }

  // Value under the cursor and the picked texel.
  auto valueText = [&](const glm::ivec3& tx) {
    const LevelData& L = cap_.levels[level_];
    std::string s;
    char buf[64];
    for (int c = 0; c < L.channels; ++c) {
      std::snprintf(buf, sizeof buf, "%s%.4g", c ? ", " : "", L.at(tx.x, tx.y, tx.z, c));
      s += buf;
    }
    return s;
  };
  if (!isBuffer) {
    const LevelData& L = cap_.levels[level_];
    if (hover_)
      ImGui::Text("%s (%d, %d, %d) = (%s)", L.size.z > 1 ? "voxel" : "pixel", hoverTexel_.x,
                  L.size.z > 1 ? hoverTexel_.y : L.size.y - 1 - hoverTexel_.y, hoverTexel_.z, valueText(hoverTexel_).c_str());
    else if (cameraImage)
      ImGui::TextDisabled("hover for values; click to %s; left drag orbits, right drag + W/A/S/D/Q/E flies",
                          probeStage() >= 0 ? "probe cones" : "pick");
    else
      ImGui::TextDisabled("hover for values; click to pick");
    if (pickTexel_.x >= 0 && pickTexel_.x < L.size.x && pickTexel_.y < L.size.y && pickTexel_.z < L.size.z)
      ImGui::Text("picked (%d, %d, %d) = (%s)", pickTexel_.x, L.size.z > 1 ? pickTexel_.y : L.size.y - 1 - pickTexel_.y,
                  pickTexel_.z, valueText(pickTexel_).c_str());
  } else {
    ImGui::Text("%u records (point view)", cap_.recordCount);
  }
  if (pendingCamera_)
    ImGui::TextColored(ImVec4(0.95f, 0.75f, 0.3f, 1), "camera moving: the image follows when the stages have re-run");
  if (!status_.empty()) ImGui::TextDisabled("%s", status_.c_str());
}

// --- Scene overlay -----------------------------------------------------------------------------------

std::vector<std::string> Viewer::overlayVolumes() const {
  const Technique& t = cursor_->technique();
  std::vector<std::string> names;
  for (int i = 0; i < t.stageCount(); ++i) {
    if (cursor_->record(i).state == StageState::NotRun) continue;
    for (const auto& o : t.decl(i).outputs)
      if (o.kind == OutputKind::Volume3D) names.push_back(std::string(t.stage(i).id()) + "/" + o.name);
  }
  return names;
}

void Viewer::drawOverlayControls() {
  ImGui::Checkbox("bounds", &overlayOpt_.bounds);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("the voxel volume's box in the scene");
  ImGui::SameLine();
  ImGui::Checkbox("voxels", &overlayOpt_.voxels);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("the non-empty voxels of a volume level over the image");
  if (!overlayOpt_.voxels) return;
  auto volumes = overlayVolumes();
  ImGui::SameLine();
  ImGui::SetNextItemWidth(190);
  if (ImGui::BeginCombo("##overlayvolume", overlayVolume_.empty() ? "(latest volume)" : overlayVolume_.c_str())) {
    for (const auto& v : volumes)
      if (ImGui::Selectable(v.c_str(), v == overlayVolume_)) overlayVolume_ = v, overlayLevel_ = -1;
    ImGui::EndCombo();
  }
  ImGui::SameLine();
  ImGui::SetNextItemWidth(80);
  int level = std::max(overlayLevel_, 0);
  if (ImGui::SliderInt("level##overlay", &level, 0, std::max(overlayLevelCount_ - 1, 0))) overlayLevel_ = level;
  ImGui::Checkbox("x-ray", &overlayOpt_.xray);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("draw the edges of every voxel, none hidden by surfaces or other voxels");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(90);
  ImGui::SliderFloat("opacity##overlay", &overlayOpt_.opacity, 0.1f, 1.0f, "%.2f");
  if (!overlayMsg_.empty()) {
    ImGui::SameLine();
    ImGui::TextColored(ImVec4(0.95f, 0.75f, 0.3f, 1), "%s", overlayMsg_.c_str());
  }
}

void Viewer::updateOverlay() {
  SceneOverlay::Options o = overlayOpt_;
  o.bounds = o.bounds || pendingCamera_.has_value() || flying_ || orbiting_;  // show where the camera goes
  if (!o.bounds && !o.voxels) {
    overlayKey_.clear();
    return;
  }
  if (!overlay_) overlay_ = std::make_unique<SceneOverlay>(*shaders_);
  const Technique& t = cursor_->technique();
  // The volume: the chosen one, else the latest of a stage up to the selected one.
  auto volumes = overlayVolumes();
  std::string volume = overlayVolume_;
  if (std::find(volumes.begin(), volumes.end(), volume) == volumes.end()) {
    volume.clear();
    for (const auto& v : volumes)
      if (t.stageIndex(v.substr(0, v.find('/'))) <= selected_ || volume.empty()) volume = v;
  }
  // Content: re-read the volume only when the data or the choice changed.
  auto contentKey = [&] {
    return std::to_string(generation_) + "|" + volume + "|" + std::to_string(overlayLevel_) + "|" + std::to_string(o.voxels);
  };
  if (contentKey() != overlayContentKey_) {
    overlayMsg_.clear();
    std::vector<ViewInstance> cubes;
    std::optional<WorldBox> box = cursor_->board().voxelSpace();
    if (!volume.empty()) {
      try {
        size_t slash = volume.find('/');
        auto [stage, desc] = t.findOutput(volume.substr(0, slash), volume.substr(slash + 1));
        (void)stage;
        if (auto placed = cursor_->board().placementOf(desc->resourceName())) box = placed;
        CapturedOutput c;
        if (o.voxels) c = captureOutput(cursor_->board(), *desc);
        if (o.voxels && !c.levels.empty()) {
          int level = overlayLevel_;
          if (level < 0) {  // the finest level with at most 32 texels per axis: blocks large enough to see
            level = 0;
            while (level + 1 < int(c.levels.size()) && c.levels[level].size.x > 32) ++level;
          }
          level = std::clamp(level, 0, int(c.levels.size()) - 1);
          overlayLevel_ = level;
          overlayLevelCount_ = int(c.levels.size());
          const LevelData& L = c.levels[level];
          if (!c.world) {
            overlayMsg_ = volume + " has no world placement (Blackboard::place); showing nothing";
          } else {
            VolumeRGBA v = mapVolume(L, desc->semantic, DisplaySettings{});
            size_t candidates = 0;
            cubes = volumeCubes(v, c.world->lo, (c.world->hi - c.world->lo) / glm::vec3(L.size), View3D::kCubeLimit,
                                candidates);
            char buf[200];
            if (cubes.empty() && candidates > 0)
              std::snprintf(buf, sizeof buf, "%zu voxels at level %d, over the limit of %zu: pick a coarser level",
                            candidates, level, View3D::kCubeLimit);
            else
              std::snprintf(buf, sizeof buf, "%s level %d (%dx%dx%d): %zu voxels", volume.c_str(), level, L.size.x,
                            L.size.y, L.size.z, candidates);
            overlayMsg_ = buf;
          }
        }
      } catch (const Error& e) {
        overlayMsg_ = e.what();
      }
    }
    overlay_->setCubes(cubes);
    overlay_->setBox(box);
    overlayContentKey_ = contentKey();  // with the resolved level, so the next frame matches
    overlayKey_.clear();
  }
  const Camera& cam = liveCamera();
  char key[512];
  std::snprintf(key, sizeof key, "%s|%d%d|%.3f|%g,%g,%g|%g,%g,%g", overlayContentKey_.c_str(), o.bounds, o.xray,
                o.opacity, cam.position.x, cam.position.y, cam.position.z, cam.forward.x, cam.forward.y, cam.forward.z);
  if (overlayKey_ == key) return;
  overlayKey_ = key;
  const ViewState& vs = cursor_->view();
  glm::mat4 viewProj = cam.projection(float(vs.width) / float(vs.height)) * cam.view();
  try {
    overlayMs_ = overlay_->render(vs.width, vs.height, viewProj, cursor_->gpuScene(), o);
  } catch (const ShaderError& e) {
    shaderError_ = e.what();
    if (scripted_) throw;
  }
  frameHeavy_ = true;
}

// --- 3D views -----------------------------------------------------------------------------------------

bool Viewer::has3DView(const OutputDesc& d) const {
  if (d.kind == OutputKind::Volume3D) return true;
  if (d.kind != OutputKind::Buffer) return false;
  return std::any_of(d.layout.fields.begin(), d.layout.fields.end(),
                     [](const BufferField& f) { return f.role == FieldRole::Position; });
}

namespace {

float srgb(float x) {
  x = std::clamp(x, 0.0f, 1.0f);
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}

const glm::vec3 kPointLight = glm::normalize(glm::vec3(0.45f, 0.8f, 0.4f));

// Accumulated opacity 0 -> 1 as blue -> magenta -> orange -> yellow.
glm::vec3 opacityColour(float a) {
  static const glm::vec3 stops[4] = {{0.15f, 0.45f, 1.0f}, {0.85f, 0.25f, 0.85f}, {1.0f, 0.55f, 0.15f}, {1.0f, 0.95f, 0.3f}};
  float t = std::clamp(a, 0.0f, 1.0f) * 3.0f;
  int i = std::min(int(t), 2);
  return glm::mix(stops[i], stops[i + 1], t - float(i));
}

}  // namespace

void Viewer::build3DContent() {
  const Technique& t = cursor_->technique();
  const OutputDesc& d = cap_.desc;
  view3d_->clear();
  msg3d_.clear();
  info3d_.clear();
  glm::vec3 lo(0.0f), hi(1.0f);
  char buf[256];
  // The context volume of a buffer: the first volume output of the last stage before the selected
  // one that wrote volumes and has run (its level 0 spans the voxel space that buffer positions use).
  auto contextVolume = [&](CapturedOutput& out, std::string& name) {
    for (int i = selected_ - 1; i >= 0; --i) {
      if (cursor_->record(i).state == StageState::NotRun) continue;
      for (const auto& o : t.decl(i).outputs)
        if (o.kind == OutputKind::Volume3D) {
          try {
            out = captureOutput(cursor_->board(), o);
          } catch (const Error&) {
            continue;
          }
          if (out.levels.empty()) continue;
          name = std::string(t.stage(i).id()) + "/" + o.name;
          return true;
        }
    }
    return false;
  };

  if (d.kind == OutputKind::Volume3D) {
    if (cap_.levels.empty()) return;
    level_ = std::clamp(level_, 0, int(cap_.levels.size()) - 1);
    const LevelData& L = cap_.levels[level_];
    VolumeRGBA vol = mapVolume(L, d.semantic, display_);
    hi = glm::vec3(cap_.levels[0].size);
    view3d_->setVolume(vol, hi, 1.0f);
    std::snprintf(buf, sizeof buf, "level %d: %dx%dx%d, %zu non-empty texels", level_, L.size.x, L.size.y, L.size.z, vol.nonEmpty);
    info3d_ = buf;
  } else if (d.semantic == Semantic::ConeSamples) {
    // World positions -> texels of the context volume's level 0, through its world placement.
    CapturedOutput ctx;
    std::string ctxName;
    std::function<glm::vec3(glm::vec3)> toView = [](glm::vec3 p) { return p; };
    float scale = 1.0f;
    bool haveCtx = contextVolume(ctx, ctxName) && ctx.world;
    if (haveCtx) {
      hi = glm::vec3(ctx.levels[0].size);
      const glm::vec3 origin = ctx.world->lo, texelsPerMetre = hi / (ctx.world->hi - ctx.world->lo);
      toView = [origin, texelsPerMetre](glm::vec3 p) { return (p - origin) * texelsPerMetre; };
      scale = texelsPerMetre.x;
      view3d_->setVolume(mapVolume(ctx.levels[0], ctx.desc.semantic, DisplaySettings{}), hi, 0.3f);
    }
    std::vector<ViewInstance> spheres, lines;
    glm::vec3 plo(1e30f), phi(-1e30f);
    size_t samples = 0;
    for (const auto& c : cones_) {
      if (c.position.empty()) continue;
      for (size_t i = 0; i < c.position.size(); ++i) {
        glm::vec3 p = toView(c.position[i]);
        float r = 0.5f * c.diameter[i] * scale;
        spheres.push_back({glm::vec4(p, r), glm::vec4(opacityColour(c.opacity[i]), 0.28f)});
        plo = glm::min(plo, p - r);
        phi = glm::max(phi, p + r);
        ++samples;
      }
      // The cone's axis: from its apex (first sample minus its distance) through the last sample.
      glm::vec3 first = c.position.front(), last = c.position.back();
      glm::vec3 dir = glm::length(last - first) > 1e-6f ? glm::normalize(last - first) : glm::vec3(0, 0, 1);
      glm::vec3 apex = first - dir * c.distance.front();
      lines.push_back({glm::vec4(toView(apex), 0), glm::vec4(1.0f)});
      lines.push_back({glm::vec4(toView(last), 0), glm::vec4(1.0f)});
    }
    view3d_->setSpheres(std::move(spheres));
    view3d_->setLines(std::move(lines));
    if (!haveCtx) {
      lo = samples ? plo : glm::vec3(0.0f);
      hi = samples ? phi : glm::vec3(1.0f);
    }
    std::snprintf(buf, sizeof buf, "%zu cones, %zu samples: disc = sample diameter, colour = accumulated opacity (blue 0, yellow 1)%s%s",
                  cones_.size(), samples, haveCtx ? "; context: " : "", haveCtx ? (ctxName + " level 0").c_str() : "");
    info3d_ = buf;
    if (samples == 0) msg3d_ = "no cone samples recorded: probe a pixel first";
  } else {
    std::vector<RecordPoint> pts = recordPoints(cap_);
    bool integer = false;
    for (const auto& f : d.layout.fields)
      if (f.role == FieldRole::Position)
        integer = f.type == FieldType::Packed10_10_10 || f.type == FieldType::U32 || f.type == FieldType::I32;
    std::vector<ViewInstance> points, cubes;
    glm::vec3 plo(1e30f), phi(-1e30f);
    for (const auto& r : pts) {
      glm::vec3 c = r.position + (integer ? 0.5f : 0.0f);  // integer positions name voxels: show their centres
      glm::vec4 col(srgb(r.color.x), srgb(r.color.y), srgb(r.color.z), 1.0f);
      // Points have no faces: shade them by their normal (when the layout has one) from a fixed
      // direction, so surfaces of one albedo stay apart. Cubes are shaded by face instead.
      float shade = glm::length(r.normal) > 0.1f ? 0.45f + 0.55f * std::abs(glm::dot(glm::normalize(r.normal), kPointLight)) : 1.0f;
      points.push_back({glm::vec4(c, 1.0f), glm::vec4(glm::vec3(col) * shade, 1.0f)});
      cubes.push_back({glm::vec4(c - 0.5f, 1.0f), col});
      plo = glm::min(plo, c - 0.5f);
      phi = glm::max(phi, c + 0.5f);
    }
    view3d_->setPoints(std::move(points));
    view3d_->setCubes(std::move(cubes));
    if (!pts.empty()) lo = glm::floor(plo), hi = glm::ceil(phi);
    std::snprintf(buf, sizeof buf, "%zu records", pts.size());
    info3d_ = buf;
    if (pts.empty()) msg3d_ = "no records";
  }
  view3d_->setBox(lo, hi);
  orbit3d_.target = 0.5f * (lo + hi);
  orbit3d_.radius = std::max(0.5f * glm::length(hi - lo), 1e-3f);
  if (orbitScene_ != scene_.get()) {
    orbitScene_ = scene_.get();
    orbit3d_.lookAlong(cursor_->camera().forward);
  }
}

bool Viewer::update3D() {
  if (!capError_.empty() || !has3DView(cap_.desc) || viewMode_ == ViewMode::Slice) return false;
  if (!view3d_) view3d_ = std::make_unique<View3D>(*shaders_);
  long key[7] = {capKey_[0], capKey_[1], capKey_[2], level_, display_.channel, long(display_.exposure * 1000),
                 long(reinterpret_cast<intptr_t>(scene_.get()))};
  bool rebuilt = false;
  if (!std::equal(key, key + 7, content3dKey_)) {
    std::copy(key, key + 7, content3dKey_);
    build3DContent();
    rebuilt = true;
  }
  if (viewMode_ == ViewMode::Cubes && view3d_->cubesOverLimit()) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%zu cubes would be drawn, over the limit of %zu: pick a coarser level or the 3D view",
                  view3d_->cubeCandidates(), View3D::kCubeLimit);
    msg3d_ = buf;
  } else if (msg3d_.find("over the limit") != std::string::npos) {
    msg3d_.clear();
  }
  // While dragging, render a quarter of the pixels: the ray march costs per pixel (level 0 of a
  // 128^3 grid took 140-250 ms at 384^2 on llvmpipe); the full size follows on release.
  // Cubes cost per cube in the vertex shader (one thread on llvmpipe: 0.5-0.7 s for 100k), so a
  // drag shows the ray-marched view of the same texels and the cubes come back on release.
  const bool dragging = dragging3d_ || scriptDragging_;
  const int size = dragging ? View3D::kSize / 2 : View3D::kSize;
  const ViewMode mode = dragging && viewMode_ == ViewMode::Cubes ? ViewMode::Volume : viewMode_;
  double rkey[6] = {double(mode), orbit3d_.yaw, orbit3d_.pitch, orbit3d_.distance, double(orbit3d_.radius), double(size)};
  if (rebuilt || !std::equal(rkey, rkey + 6, render3dKey_)) {
    std::copy(rkey, rkey + 6, render3dKey_);
    try {
      render3dMs_.push_back(view3d_->render(mode, orbit3d_, size));
    } catch (const ShaderError& e) {
      shaderError_ = e.what();
      if (scripted_) throw;
    }
    frameHeavy_ = true;
  }
  return true;
}

void Viewer::draw3DView() {
  if (!update3D()) return;
  ImVec2 avail = ImGui::GetContentRegionAvail();
  avail.y -= 70;
  float side = std::max(64.0f, std::min(avail.x, avail.y));
  float used = float(view3d_->lastSize()) / float(View3D::kSize);  // the rendered corner of the texture
  ImGui::Image(reinterpret_cast<ImTextureID>(intptr_t(view3d_->texture())), ImVec2(side, side), ImVec2(0, used),
               ImVec2(used, 0));
  ImGuiIO& io = ImGui::GetIO();
  if (ImGui::IsItemHovered()) {
    if (ImGui::IsMouseClicked(ImGuiMouseButton_Left)) dragging3d_ = true;
    if (io.MouseWheel != 0.0f) orbit3d_.distance = std::clamp(orbit3d_.distance * std::pow(0.9f, io.MouseWheel), 0.6f, 8.0f);
  }
  if (dragging3d_) {
    if (!ImGui::IsMouseDown(ImGuiMouseButton_Left)) dragging3d_ = false;
    else if (io.MouseDelta.x != 0.0f || io.MouseDelta.y != 0.0f) orbit3d_.rotate(-io.MouseDelta.x * 0.4f, io.MouseDelta.y * 0.4f);
  }
  if (!msg3d_.empty()) ImGui::TextColored(ImVec4(0.95f, 0.75f, 0.3f, 1), "%s", msg3d_.c_str());
  ImGui::TextWrapped("%s", info3d_.c_str());
  ImGui::TextDisabled("%s view %dx%d, last render %.1f ms; drag to rotate, wheel to zoom", viewModeName(viewMode_),
                      view3d_->lastSize(), view3d_->lastSize(), render3dMs_.empty() ? 0.0 : render3dMs_.back());
  if (!status_.empty()) ImGui::TextDisabled("%s", status_.c_str());
}

void Viewer::drawRightPanel() {
  auto flags = [&](const char* name) {
    return wantTab_ == name ? ImGuiTabItemFlags_SetSelected : ImGuiTabItemFlags_None;
  };
  if (ImGui::BeginTabBar("tabs")) {
    if (ImGui::BeginTabItem("Inspect", nullptr, flags("inspect"))) {
      drawInspector();
      ImGui::EndTabItem();
    }
    if (probeStage() >= 0 && ImGui::BeginTabItem("Probe", nullptr, flags("probe"))) {
      drawProbe();
      ImGui::EndTabItem();
    }
    if (ImGui::BeginTabItem("Timing", nullptr, flags("timing"))) {
      drawTiming();
      ImGui::EndTabItem();
    }
    if (!lesson_.steps.empty() && ImGui::BeginTabItem("Lesson", nullptr, flags("lesson"))) {
      drawLesson();
      ImGui::EndTabItem();
    }
    if (ImGui::BeginTabItem("Camera/Export", nullptr, flags("export"))) {
      drawExport();
      ImGui::EndTabItem();
    }
    ImGui::EndTabBar();
  }
  wantTab_.clear();
  if (!shaderError_.empty()) {
    ImGui::Separator();
    ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "shader error (last good program kept):");
    ImGui::TextWrapped("%s", shaderError_.c_str());
  }
}

void Viewer::drawStatsTable(const char* id, const nlohmann::json& stats) {
  if (!stats.is_object() || stats.empty()) return;
  auto text = [](const nlohmann::json& v) {
    char buf[48];
    if (v.is_number()) {
      std::snprintf(buf, sizeof buf, "%.6g", v.get<double>());
      return std::string(buf);
    }
    if (v.is_array()) {
      std::string s;
      for (const auto& e : v) {
        if (e.is_number()) std::snprintf(buf, sizeof buf, "%.4g", e.get<double>());
        else std::snprintf(buf, sizeof buf, "%s", e.dump().c_str());
        s += (s.empty() ? "" : ", ") + std::string(buf);
      }
      return s;
    }
    return v.is_string() ? v.get<std::string>() : v.dump();
  };
  if (ImGui::BeginTable(id, 2, ImGuiTableFlags_Borders | ImGuiTableFlags_SizingStretchProp)) {
    for (auto it = stats.begin(); it != stats.end(); ++it) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(it.key().c_str());
      ImGui::TableNextColumn();
      ImGui::TextWrapped("%s", text(it.value()).c_str());
    }
    ImGui::EndTable();
  }
}

void Viewer::drawInspector() {
  const Technique& t = cursor_->technique();
  ImGui::TextWrapped("%s", t.stage(selected_).summary());
  const StageRecord& rec = cursor_->record(selected_);
  if (!rec.stats.empty() && ImGui::CollapsingHeader("stage statistics", ImGuiTreeNodeFlags_DefaultOpen)) {
    nlohmann::json j(rec.stats);
    drawStatsTable("stagestats", j);
  }
  ImGui::Separator();
  if (!capError_.empty()) return;
  const OutputDesc& d = cap_.desc;
  if (d.kind != OutputKind::Buffer && !cap_.levels.empty()) {
    int levels = int(cap_.levels.size());
    if (levels > 1) ImGui::SliderInt("level", &level_, 0, levels - 1);
    const LevelData& L = cap_.levels[std::clamp(level_, 0, levels - 1)];
    ImGui::Text("size %d x %d x %d, %d channels", L.size.x, L.size.y, L.size.z, L.channels);
    if (L.size.z > 1) {
      ImGui::TextUnformatted("slice axis");
      for (int a = 0; a < 3; ++a) {
        ImGui::SameLine();
        ImGui::RadioButton(a == 0 ? "x" : a == 1 ? "y" : "z", &slice_.axis, a);
      }
      int extent = slice_.axis == 0 ? L.size.x : slice_.axis == 1 ? L.size.y : L.size.z;
      if (slice_.index < 0) slice_.index = extent / 2;
      slice_.index = std::clamp(slice_.index, 0, extent - 1);
      ImGui::SliderInt("slice", &slice_.index, 0, extent - 1);
    }
    const char* channels[] = {"all (semantic)", "r / 0", "g / 1", "b / 2", "a / 3"};
    int ch = display_.channel + 1;
    if (ImGui::Combo("channel", &ch, channels, std::min(L.channels, 4) + 1)) display_.channel = ch - 1;
    ImGui::SliderFloat("exposure", &display_.exposure, 0.05f, 16.0f, "%.2f", ImGuiSliderFlags_Logarithmic);
    const nlohmann::json& stats = capStats_;
    if (stats.contains("levels") && stats["levels"].size() > size_t(level_)) {
      ImGui::Separator();
      ImGui::Text("level %d statistics", level_);
      drawStatsTable("levelstats", stats["levels"][level_]);
    }
  } else if (d.kind == OutputKind::Buffer) {
    ImGui::Text("%u records, stride %u bytes", cap_.recordCount, d.layout.stride);
    const nlohmann::json& recs = capRecords_;
    if (recs.is_array() && !recs.empty() && recs[0].is_object()) {
      int cols = int(recs[0].size()) + 1;
      if (ImGui::BeginTable("records", cols, ImGuiTableFlags_Borders | ImGuiTableFlags_ScrollY | ImGuiTableFlags_ScrollX |
                                                  ImGuiTableFlags_SizingFixedFit,
                            ImVec2(0, 300))) {
        ImGui::TableSetupColumn("#");
        for (auto it = recs[0].begin(); it != recs[0].end(); ++it) ImGui::TableSetupColumn(it.key().c_str());
        ImGui::TableHeadersRow();
        for (size_t r = 0; r < recs.size(); ++r) {
          ImGui::TableNextRow();
          ImGui::TableNextColumn();
          ImGui::Text("%zu", r);
          for (auto it = recs[r].begin(); it != recs[r].end(); ++it) {
            ImGui::TableNextColumn();
            ImGui::TextUnformatted(it.value().dump().c_str());
          }
        }
        ImGui::EndTable();
      }
    }
  }
}

void Viewer::drawProbe() {
  int p = probeStage();
  const ParamSet& ps = cursor_->params();
  ImGui::Text("probe pixel: (%.0f, %.0f) of %dx%d", ps.value("probe.x") * cursor_->view().width - 0.5,
              ps.value("probe.y") * cursor_->view().height - 0.5, cursor_->view().width, cursor_->view().height);
  ImGui::TextDisabled("click a pixel of a camera image (final, G-buffer, ...) to probe it");
  // The samples come from the probe stage's ConeSamples output, whoever declares it.
  const Technique& t = cursor_->technique();
  if (cursor_->record(p).state == StageState::NotRun) {
    ImGui::TextWrapped("stage %s has not run yet", t.stage(p).id());
    return;
  }
  static std::vector<ConeSeries> cones;
  static long key = -1;
  if (key != generation_) {
    key = generation_;
    cones.clear();
    for (const auto& o : t.decl(p).outputs)
      if (o.semantic == Semantic::ConeSamples) {
        try {
          cones = decodeConeSamples(captureOutput(cursor_->board(), o));
        } catch (const Error&) {
        }
        break;
      }
  }
  size_t total = 0;
  for (const auto& c : cones) total += c.distance.size();
  ImGui::Text("%zu cones, %zu samples", cones.size(), total);
  std::string mono = checkOpacityMonotonic(cones);
  if (!mono.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", mono.c_str());
  ImGui::BeginChild("cones");
  for (const auto& c : cones) {
    if (c.distance.empty()) continue;
    // The aperture follows from any sample: diameter = 2 * distance * tan(aperture / 2).
    const float aperture = c.distance.back() > 0.0f
                               ? 2.0f * std::atan(0.5f * c.diameter.back() / c.distance.back()) * 57.29578f
                               : 0.0f;
    char title[96];
    std::snprintf(title, sizeof title, "cone %d: %.0f deg, %zu samples, to distance %.3f m", c.cone, aperture,
                  c.distance.size(), c.distance.back());
    if (!ImGui::TreeNodeEx(title, ImGuiTreeNodeFlags_DefaultOpen)) continue;
    int n = int(c.distance.size());
    ImGui::PlotLines("lod", c.lod.data(), n, 0, "mip level per sample", 0.0f, FLT_MAX, ImVec2(0, 40));
    ImGui::PlotLines("opacity", c.opacity.data(), n, 0, "accumulated opacity", 0.0f, 1.0f, ImVec2(0, 40));
    ImGui::PlotLines("radiance", c.luminance.data(), n, 0, "accumulated luminance", 0.0f, FLT_MAX, ImVec2(0, 40));
    ImGui::TextDisabled("final opacity %.3f, luminance %.4f", c.opacity.back(), c.luminance.back());
    ImGui::TreePop();
  }
  ImGui::EndChild();
}

void Viewer::drawTiming() {
  const Technique& t = cursor_->technique();
  double cpu = 0, gpu = 0;
  // The state is in the timeline; here the room goes to each stage's recent GPU times.
  if (ImGui::BeginTable("timing", 4, ImGuiTableFlags_Borders | ImGuiTableFlags_SizingStretchProp)) {
    ImGui::TableSetupColumn("stage", ImGuiTableColumnFlags_WidthStretch, 1.15f);
    ImGui::TableSetupColumn("cpu ms", ImGuiTableColumnFlags_WidthStretch, 0.6f);
    ImGui::TableSetupColumn("gpu ms", ImGuiTableColumnFlags_WidthStretch, 0.6f);
    ImGui::TableSetupColumn("gpu ms, last runs", ImGuiTableColumnFlags_WidthStretch, 1.65f);
    ImGui::TableHeadersRow();
    for (int i = 0; i < t.stageCount(); ++i) {
      const StageRecord& r = cursor_->record(i);
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(t.stage(i).id());
      ImGui::TableNextColumn();
      ImGui::Text("%.1f", r.cpuMs);
      ImGui::TableNextColumn();
      ImGui::Text("%.1f", r.gpuMs);
      ImGui::TableNextColumn();
      const auto& h = timeHistory_.at(i);
      if (!h.empty()) {
        std::vector<float> g;
        for (const auto& e : h) g.push_back(e.second);
        std::vector<float> sorted = g;
        std::sort(sorted.begin(), sorted.end());
        char overlay[48];
        std::snprintf(overlay, sizeof overlay, "median %.1f (%zu)", sorted[sorted.size() / 2], g.size());
        ImGui::PushID(i);
        ImGui::PlotLines("##history", g.data(), int(g.size()), 0, overlay, 0.0f, FLT_MAX,
                         ImVec2(std::max(ImGui::GetContentRegionAvail().x, 40.0f), 18.0f * uiScale_));
        ImGui::PopID();
      }
      cpu += r.cpuMs;
      gpu += r.gpuMs;
    }
    ImGui::EndTable();
  }
  ImGui::Text("total cpu %.1f ms, gpu %.1f ms", cpu, gpu);
  if (!idleFrameMs_.empty()) {
    size_t n = std::min<size_t>(idleFrameMs_.size(), 120);
    std::vector<float> recent(idleFrameMs_.end() - n, idleFrameMs_.end());
    ImGui::PlotLines("UI ms", recent.data(), int(n), 0, nullptr, 0.0f, FLT_MAX, ImVec2(0, 40));
  }
  ImGui::Separator();
  const Blackboard& b = cursor_->board();
  ImGui::Text("resources: %s", fmtBytes(b.totalBytes()).c_str());
  if (ImGui::BeginTable("memory", 3, ImGuiTableFlags_Borders | ImGuiTableFlags_SizingFixedFit | ImGuiTableFlags_ScrollY,
                        ImVec2(0, 260))) {
    ImGui::TableSetupColumn("resource");
    ImGui::TableSetupColumn("shape");
    ImGui::TableSetupColumn("bytes");
    ImGui::TableHeadersRow();
    for (const auto& [name, tex] : b.textures()) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(name.c_str());
      ImGui::TableNextColumn();
      glm::ivec3 s = tex->levelSize(0);
      ImGui::Text("%dx%dx%d %s x%d", s.x, s.y, s.z, formatName(tex->desc().format), tex->levels());
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(fmtBytes(tex->byteSize()).c_str());
    }
    for (const auto& [name, buf] : b.buffers()) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(name.c_str());
      ImGui::TableNextColumn();
      ImGui::TextUnformatted("buffer");
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(fmtBytes(buf->size()).c_str());
    }
    ImGui::EndTable();
  }
}

void Viewer::drawLesson() {
  ImGui::TextWrapped("%s", lesson_.title.c_str());
  ImGui::Text("step %d of %zu", lessonStep_ + 1, lesson_.steps.size());
  if (ImGui::Button("< Previous step")) applyLessonStep(lessonStep_ - 1);
  ImGui::SameLine();
  if (ImGui::Button("Next step >")) applyLessonStep(lessonStep_ + 1);
  ImGui::Separator();
  ImGui::BeginChild("narrative");
  // Markdown is hard-wrapped: join a paragraph's lines and let ImGui wrap; headings stand alone.
  auto markdown = [](const std::string& text) {
    std::istringstream in(text);
    std::string line, para;
    auto flush = [&] {
      if (!para.empty()) ImGui::TextWrapped("%s", para.c_str());
      para.clear();
    };
    while (std::getline(in, line)) {
      if (line.rfind("#", 0) == 0) {
        flush();
        size_t k = line.find_first_not_of('#');
        ImGui::TextColored(ImVec4(0.6f, 0.8f, 1.0f, 1), "%s", line.substr(std::min(k + 1, line.size())).c_str());
      } else if (line.find_first_not_of(" \t") == std::string::npos) {
        flush();
        ImGui::Spacing();
      } else {
        para += (para.empty() ? "" : " ") + line;
      }
    }
    flush();
  };
  if (lessonStep_ >= 0) {
    markdown(lesson_.steps[lessonStep_].narrative);
    if (lessonStep_ + 1 == int(lesson_.steps.size()) && !lesson_.epilogue.empty()) {
      ImGui::Separator();
      markdown(lesson_.epilogue);
    }
  }
  ImGui::EndChild();
}

void Viewer::drawExport() {
  const Technique& t = cursor_->technique();
  ImGui::TextUnformatted("Camera");
  for (size_t i = 0; i < scene_->cameras.size(); ++i) {
    std::string label = std::to_string(i) + ": " + scene_->cameras[i].name;
    if (ImGui::Selectable(label.c_str(), cameraIndex_ == int(i))) setCameraIndex(int(i));
  }
  if (ImGui::Button("Frame the scene")) frameScene();
  ImGui::SameLine();
  if (ImGui::Button("Orbit -15")) orbit(-15, 0);
  ImGui::SameLine();
  if (ImGui::Button("Orbit +15")) orbit(15, 0);
  ImGui::Separator();
  ImGui::TextUnformatted("Export");
  static char dir[256] = "viewer-out";
  ImGui::InputText("folder", dir, sizeof dir);
  if (ImGui::Button("Save view PNG")) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    std::string path = std::string(dir) + "/view.png";
    try {
      writePng(viewportImage(), path);
      status_ = "saved " + path;
    } catch (const Error& e) {
      status_ = e.what();
    }
  }
  ImGui::SameLine();
  if (ImGui::Button("Save output PNG/EXR") && capError_.empty()) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    try {
      auto e = writeOutputFiles(cap_, dir, std::string(t.stage(selected_).id()) + "." + cap_.desc.name);
      status_ = "saved " + e["files"].dump();
    } catch (const Error& e) {
      status_ = e.what();
    }
  }
  if (ImGui::Button("Screenshot")) {
    pendingScreenshot_ = std::string(dir) + "/screenshot.png";
    screenshotDelay_ = 1;
  }
  if (ImGui::Button("Copy `voxlab run` command")) {
    copied_ = commandLine();
    glfwSetClipboardString(window_->handle(), copied_.c_str());
  }
  if (!copied_.empty()) ImGui::TextWrapped("%s", copied_.c_str());
  ImGui::Separator();
  ImGui::SetNextItemWidth(120.0f * uiScale_);
  float scale = wantUiScale_;
  if (ImGui::SliderFloat("UI scale (Ctrl+= / Ctrl+-)", &scale, 0.75f, 3.0f, "%.2f")) wantUiScale_ = scale;
  if (ImGui::Button("Reload shaders (F5)")) reloadShaders();
  ImGui::SameLine();
  ImGui::Checkbox("watch shader files", &watchShaders_);
  ImGui::TextDisabled("%d programs", shaders_->programCount());
}

// --- Scripts ---------------------------------------------------------------------------------------

void Viewer::scriptFail(const ScriptAction& a, const std::string& msg) const {
  throw Error(opt_.script + ":" + std::to_string(a.line) + ": " + a.verb + ": " + msg);
}

void Viewer::stepScript() {
  if (scriptBusy()) return;
  if (pc_ >= script_.size()) {
    quit_ = true;
    return;
  }
  const ScriptAction a = script_[pc_++];  // a copy: walk-stages inserts actions into script_
  frameHeavy_ = true;  // script I/O (saving, comparing) is not UI time
  try {
    execute(a);
  } catch (const Error& e) {
    std::string m = e.what();
    if (m.rfind(opt_.script + ":", 0) == 0) throw;
    scriptFail(a, m);
  }
}

void Viewer::execute(const ScriptAction& a) {
  const Technique& t = cursor_->technique();
  auto arg = [&](size_t i) -> const std::string& { return a.args.at(i); };
  auto intArg = [&](size_t i) {
    try {
      size_t used = 0;
      int v = std::stoi(arg(i), &used);
      if (used != arg(i).size()) throw std::invalid_argument("x");
      return v;
    } catch (const std::exception&) {
      scriptFail(a, "'" + arg(i) + "' is not an integer");
    }
  };
  auto floatArg = [&](size_t i) {
    try {
      return std::stof(arg(i));
    } catch (const std::exception&) {
      scriptFail(a, "'" + arg(i) + "' is not a number");
    }
  };
  const std::string& v = a.verb;
  if (v == "technique") {
    if (arg(0) != t.id()) switchTechnique(arg(0));
  } else if (v == "scene") {
    if (!loadSceneNamed(arg(0))) std::printf("scene error: %s\n", sceneError_.c_str());
  } else if (v == "expect-scene-error") {
    std::string text;
    for (const auto& w : a.args) text += (text.empty() ? "" : " ") + w;
    if (sceneError_.empty() || sceneError_.find(text) == std::string::npos)
      scriptFail(a, "last scene error is '" + sceneError_ + "', expected it to contain '" + text + "'");
  } else if (v == "stage") {
    selectStage(t.stageIndex(arg(0)));
  } else if (v == "output") {
    selectOutput(arg(0));
  } else if (v == "level") {
    level_ = intArg(0);
  } else if (v == "slice") {
    std::string ax = arg(0);
    if (ax != "x" && ax != "y" && ax != "z") scriptFail(a, "axis must be x, y or z");
    slice_.axis = ax[0] - 'x';
    slice_.index = intArg(1);
  } else if (v == "channel") {
    display_.channel = std::clamp(intArg(0), -1, 3);
  } else if (v == "exposure") {
    display_.exposure = floatArg(0);
  } else if (v == "set") {
    std::string s = arg(0);
    size_t eq = s.find('=');
    if (eq == std::string::npos) scriptFail(a, "expected NAME=VALUE");
    cursor_->setParamText(s.substr(0, eq), s.substr(eq + 1));
    paramsChanged();
  } else if (v == "reset-params") {
    cursor_->setParams(t.defaultParams());
    paramsChanged();
  } else if (v == "camera") {
    setCameraIndex(intArg(0));
  } else if (v == "orbit") {
    orbit(floatArg(0), floatArg(1));
  } else if (v == "frame-scene") {
    frameScene();
  } else if (v == "size") {
    Args::parseSize(arg(0), opt_.width, opt_.height);
    cursor_->setViewSize(opt_.width, opt_.height);
    paramsChanged();
  } else if (v == "run") {
    lastRunRequest_ = std::max(lastRunRequest_, selected_);
    requestRun(selected_);
  } else if (v == "runall") {
    lastRunRequest_ = t.stageCount() - 1;
    requestRun(lastRunRequest_);
  } else if (v == "next") {
    selectStage(selected_ + 1);
    lastRunRequest_ = std::max(lastRunRequest_, selected_);
    requestRun(selected_);
  } else if (v == "prev") {
    selectStage(selected_ - 1);
  } else if (v == "probe") {
    probePixel(intArg(0), intArg(1));
  } else if (v == "lesson") {
    lesson_ = loadLesson(arg(0));
    applyLessonStep(0);
  } else if (v == "lesson-next" || v == "lesson-prev") {
    if (lesson_.steps.empty()) scriptFail(a, "no lesson is open");
    int next = lessonStep_ + (v == "lesson-next" ? 1 : -1);
    if (next < 0 || next >= int(lesson_.steps.size()))
      scriptFail(a, "no step " + std::to_string(next + 1) + "; the lesson has " + std::to_string(lesson_.steps.size()));
    applyLessonStep(next);
    std::printf("lesson step %d/%zu: %s/%s\n", next + 1, lesson_.steps.size(), lesson_.steps[next].stage.c_str(),
                lesson_.steps[next].output.c_str());
  } else if (v == "lesson-end") {
    if (lesson_.steps.empty()) scriptFail(a, "no lesson is open");
    if (lessonStep_ + 1 < int(lesson_.steps.size())) {
      applyLessonStep(lessonStep_ + 1);
      std::printf("lesson step %d/%zu: %s/%s\n", lessonStep_ + 1, lesson_.steps.size(),
                  lesson_.steps[lessonStep_].stage.c_str(), lesson_.steps[lessonStep_].output.c_str());
      --pc_;  // repeat this action after the step has run
    }
  } else if (v == "save-view") {
    refreshCapture();
    if (!capError_.empty()) scriptFail(a, capError_);
    if (viewMode_ != ViewMode::Slice) update3D();
    else if (isCameraImage(selected_, cap_)) updateOverlay();
    fs::path p(arg(0));
    std::error_code ec;
    if (p.has_parent_path()) fs::create_directories(p.parent_path(), ec);
    writePng(viewportImage(), arg(0));
    std::printf("saved view %s\n", arg(0).c_str());
  } else if (v == "screenshot") {
    pendingScreenshot_ = arg(0);
    screenshotDelay_ = 2;  // let ImGui settle one frame after the last change
  } else if (v == "save-output" || v == "compare-output") {
    refreshCapture();
    if (!capError_.empty()) scriptFail(a, capError_);
    std::string prefix = std::string(t.stage(selected_).id()) + "." + cap_.desc.name;
    if (v == "save-output") {
      std::error_code ec;
      fs::create_directories(arg(0), ec);
      auto e = writeOutputFiles(cap_, arg(0), prefix);
      std::printf("saved %s: %s\n", prefix.c_str(), e["files"].dump().c_str());
      return;
    }
    double tol = a.args.size() > 2 ? floatArg(2) : 0.0;
    if (cap_.desc.kind == OutputKind::Buffer) {
      std::string x = readTextFile(arg(0) + "/" + prefix + ".bin"), y = readTextFile(arg(1) + "/" + prefix + ".bin");
      uint32_t stride = std::max<uint32_t>(cap_.desc.layout.stride, 1);
      if (x.size() != y.size())
        scriptFail(a, prefix + ": " + std::to_string(x.size() / stride) + " records vs " + std::to_string(y.size() / stride));
      // Appended records have no fixed order: compare the sorted record sets.
      auto recs = [&](const std::string& s) {
        std::vector<std::string> r;
        for (size_t i = 0; i + stride <= s.size(); i += stride) r.push_back(s.substr(i, stride));
        std::sort(r.begin(), r.end());
        return r;
      };
      if (recs(x) != recs(y)) scriptFail(a, prefix + ": record sets differ");
      std::printf("compare-output %s: %zu records identical\n", prefix.c_str(), x.size() / stride);
      return;
    }
    size_t levels = cap_.levels.size();
    for (size_t l = 0; l < levels; ++l) {
      std::string name = prefix + (levels > 1 ? "@" + std::to_string(l) : "") + ".exr";
      LevelData p = readLevelExr(arg(0) + "/" + name), q = readLevelExr(arg(1) + "/" + name);
      if (p.size != q.size || p.channels != q.channels) scriptFail(a, name + ": sizes or channel counts differ");
      double maxDiff = 0;
      size_t above = 0;
      for (size_t i = 0; i < p.values.size(); ++i) {
        double dd = std::abs(double(p.values[i]) - double(q.values[i]));
        if (!(dd <= tol)) ++above;
        if (dd > maxDiff || std::isnan(dd)) maxDiff = dd;
      }
      std::printf("compare-output %s: %zu values, max abs diff %g (tolerance %g)\n", name.c_str(), p.values.size(), maxDiff, tol);
      if (above) scriptFail(a, name + ": " + std::to_string(above) + " values differ by more than " + arg(2 < a.args.size() ? 2 : 0));
    }
  } else if (v == "expect-images-differ" || v == "expect-images-equal") {
    int w1, h1, w2, h2;
    auto p = readImageBytes(arg(0), w1, h1), q = readImageBytes(arg(1), w2, h2);
    size_t diff = 0;
    if (w1 == w2 && h1 == h2 && p.size() == q.size())
      for (size_t i = 0; i < p.size(); ++i) diff += p[i] != q[i];
    else
      diff = std::max(p.size(), q.size());
    std::printf("%s vs %s: %zu bytes differ\n", arg(0).c_str(), arg(1).c_str(), diff);
    if (v == "expect-images-differ" && diff == 0) scriptFail(a, "the images are identical");
    if (v == "expect-images-equal" && diff != 0) scriptFail(a, std::to_string(diff) + " bytes differ");
  } else if (v == "expect-samples-monotonic") {
    int p = probeStage();
    if (p < 0) scriptFail(a, "the technique has no cone-samples output");
    std::vector<ConeSeries> cones;
    for (const auto& o : t.decl(p).outputs)
      if (o.semantic == Semantic::ConeSamples) cones = decodeConeSamples(captureOutput(cursor_->board(), o));
    size_t total = 0;
    for (const auto& c : cones) total += c.distance.size();
    if (total == 0) scriptFail(a, "no cone samples were recorded (stage " + std::string(t.stage(p).id()) + ", " + std::to_string(cones.size()) + " cones)");
    std::string m = checkOpacityMonotonic(cones);
    if (!m.empty()) scriptFail(a, m);
    std::printf("probe: %zu cones, %zu samples, accumulated opacity non-decreasing along every cone\n", cones.size(), total);
  } else if (v == "expect-state") {
    int i = t.stageIndex(arg(0));
    std::string want = arg(1) == "not-run" ? "not run" : arg(1);
    std::string got = stageStateName(cursor_->record(i).state);
    if (got != want) scriptFail(a, "stage " + arg(0) + " is " + got + ", expected " + want);
  } else if (v == "expect-param") {
    std::string got = cursor_->params().desc(arg(0)).format(cursor_->params().value(arg(0)));
    if (got != arg(1)) scriptFail(a, arg(0) + " is " + got + ", expected " + arg(1));
  } else if (v == "copy-command") {
    copied_ = commandLine();
    glfwSetClipboardString(window_->handle(), copied_.c_str());
    std::printf("command: %s\n", copied_.c_str());
  } else if (v == "reload") {
    reloadShaders();
    if (!shaderError_.empty()) std::printf("shader reload failed: %s\n", shaderError_.c_str());
  } else if (v == "wait") {
    waitFrames_ = intArg(0);
  } else if (v == "tab") {
    static const char* tabs[] = {"inspect", "probe", "timing", "lesson", "export"};
    if (std::find_if(std::begin(tabs), std::end(tabs), [&](const char* n) { return arg(0) == n; }) == std::end(tabs))
      scriptFail(a, "unknown tab '" + arg(0) + "'; valid: inspect, probe, timing, lesson, export");
    wantTab_ = arg(0);
  } else if (v == "view-mode") {
    if (arg(0) == "slice") viewMode_ = ViewMode::Slice;
    else if (arg(0) == "3d") viewMode_ = ViewMode::Volume;
    else if (arg(0) == "cubes") viewMode_ = ViewMode::Cubes;
    else scriptFail(a, "unknown mode '" + arg(0) + "'; valid: slice, 3d, cubes");
    if (viewMode_ != ViewMode::Slice) {
      refreshCapture();
      if (capError_.empty() && !has3DView(cap_.desc))
        scriptFail(a, "output " + cap_.desc.name + " (" + kindName(cap_.desc.kind) + ") has no 3D view");
    }
  } else if (v == "auto-rerun") {
    if (arg(0) != "on" && arg(0) != "off") scriptFail(a, "expected on or off, not '" + arg(0) + "'");
    autoRerun_ = arg(0) == "on";
  } else if (v == "ui-scale") {
    float s = floatArg(0);
    if (!(s >= 0.75f && s <= 3.0f)) scriptFail(a, "scale must be in 0.75..3, not " + arg(0));
    wantUiScale_ = s;
    waitFrames_ = 2;
  } else if (v == "view-dragging") {
    if (arg(0) != "on" && arg(0) != "off") scriptFail(a, "expected on or off, not '" + arg(0) + "'");
    scriptDragging_ = arg(0) == "on";
  } else if (v == "view-orbit") {
    orbit3d_.rotate(floatArg(0), floatArg(1));
  } else if (v == "expect-view-nonempty") {
    refreshCapture();
    if (!capError_.empty()) scriptFail(a, capError_);
    if (!update3D()) scriptFail(a, "no 3D view is shown (view-mode 3d|cubes on a volume or a buffer with positions)");
    if (!msg3d_.empty() && msg3d_.find("over the limit") != std::string::npos) scriptFail(a, msg3d_);
    size_t n = view3d_->nonBackgroundPixels(), want = size_t(std::max(intArg(0), 0));
    std::printf("view %s of %s: %zu of %d pixels show content (need > %zu); %s; render %.1f ms\n",
                viewModeName(viewMode_), cap_.desc.name.c_str(), n, View3D::kSize * View3D::kSize, want, info3d_.c_str(),
                render3dMs_.empty() ? 0.0 : render3dMs_.back());
    if (n <= want) scriptFail(a, std::to_string(n) + " content pixels, expected more than " + arg(0));
  } else if (v == "iterate") {
    if (cursor_->iterations(selected_) <= 1) scriptFail(a, std::string("stage ") + t.stage(selected_).id() + " is not iterative");
    stepIteration();
  } else if (v == "expect-iterations") {
    const StageRecord& r = cursor_->record(t.stageIndex(arg(0)));
    int want = intArg(1);
    if (r.iterationsRun != want || (r.state != StageState::Partial && r.state != StageState::Done))
      scriptFail(a, arg(0) + " is " + stageStateName(r.state) + " after " + std::to_string(r.iterationsRun) + " of " +
                        std::to_string(r.iterationsTotal) + " iterations, expected " + arg(1));
    std::printf("%s: %d of %d iterations (%s)\n", arg(0).c_str(), r.iterationsRun, r.iterationsTotal, stageStateName(r.state));
  } else if (v == "walk-stages") {
    auto more = walkStagesActions(a);
    script_.insert(script_.begin() + long(pc_), more.begin(), more.end());
  } else if (v == "fly") {
    moveCamera(flyCamera(liveCamera(), floatArg(0), floatArg(1), floatArg(2)));
  } else if (v == "look") {
    moveCamera(lookCamera(liveCamera(), floatArg(0), floatArg(1)));
  } else if (v == "overlay") {
    if (arg(1) != "on" && arg(1) != "off") scriptFail(a, "expected on or off, not '" + arg(1) + "'");
    bool on = arg(1) == "on";
    if (arg(0) == "bounds") overlayOpt_.bounds = on;
    else if (arg(0) == "voxels") overlayOpt_.voxels = on;
    else if (arg(0) == "xray") overlayOpt_.xray = on;
    else scriptFail(a, "unknown overlay '" + arg(0) + "'; valid: bounds, voxels, xray");
  } else if (v == "overlay-volume") {
    auto vols = overlayVolumes();
    if (std::find(vols.begin(), vols.end(), arg(0)) == vols.end())
      scriptFail(a, "no volume '" + arg(0) + "' has run; valid: " + joinNames(vols));
    overlayVolume_ = arg(0);
    overlayLevel_ = intArg(1);
  } else if (v == "expect-overlay-pixels") {
    refreshCapture();
    if (!capError_.empty()) scriptFail(a, capError_);
    if (!isCameraImage(selected_, cap_)) scriptFail(a, "output " + cap_.desc.name + " is not a camera image; overlays apply to those");
    updateOverlay();
    if (overlayKey_.empty()) scriptFail(a, "no overlay is on (overlay bounds|voxels on)");
    size_t n = overlay_->coveredPixels(), want = size_t(std::max(intArg(0), 0));
    std::printf("overlay on %s: %zu pixels covered (need > %zu), %zu voxel cubes, %.1f ms; %s\n", cap_.desc.name.c_str(), n,
                want, overlay_->cubeCount(), overlayMs_, overlayMsg_.c_str());
    if (n <= want) scriptFail(a, std::to_string(n) + " pixels covered, expected more than " + arg(0));
  } else if (v == "frame-stats") {
    printFrameStats();
  } else if (v == "quit") {
    quit_ = true;
  }
}

std::vector<ScriptAction> Viewer::walkStagesActions(const ScriptAction& a) const {
  const Technique& t = cursor_->technique();
  const std::string out = a.args.at(0), run = a.args.at(1);
  // Per-output tolerances of the snapshot suite: what was measured to vary between runs.
  nlohmann::json tol = nlohmann::json::parse(readTextFile(a.args.at(2)));
  auto toleranceOf = [&](const std::string& address) {
    double d = tol.at("default").at("max_abs").get<double>();
    if (tol.contains("outputs") && tol["outputs"].contains(address)) d = tol["outputs"][address].value("max_abs", d);
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", d);
    return std::string(buf);
  };
  std::vector<ScriptAction> acts;
  auto add = [&](std::string verb, std::vector<std::string> args) {
    ScriptAction s;
    s.verb = std::move(verb);
    s.args = std::move(args);
    s.line = a.line;
    acts.push_back(std::move(s));
  };
  std::string previous;
  for (int i = 0; i < t.stageCount(); ++i) {
    const std::string id = t.stage(i).id();
    add("stage", {id});
    const int n = cursor_->iterations(i);
    if (n > 1)
      for (int k = 1; k <= n; ++k) {
        add("iterate", {});
        add("expect-iterations", {id, std::to_string(k)});
      }
    add("run", {});
    char shot[32];
    std::snprintf(shot, sizeof shot, "/%02d-", i + 1);
    std::string png = out + shot + id + ".png";
    add("screenshot", {png});
    if (!previous.empty()) add("expect-images-differ", {previous, png});
    previous = png;
    for (const auto& o : t.decl(i).outputs) {
      add("output", {o.name});
      add("save-output", {out + "/view"});
      add("compare-output", {out + "/view", run, toleranceOf(t.id() + "/" + id + "/" + o.name)});
    }
  }
  return acts;
}

void Viewer::printFrameStats() const {
  if (idleFrameMs_.empty()) {
    std::printf("frame-stats: no idle frames\n");
    return;
  }
  std::vector<double> s = idleFrameMs_;
  std::sort(s.begin(), s.end());
  double sum = 0;
  for (double x : s) sum += x;
  int w, h;
  window_->framebufferSize(w, h);
  std::printf("frame-stats: %zu idle UI frames at %dx%d: mean %.1f ms, median %.1f ms, p95 %.1f ms, max %.1f ms\n",
              s.size(), w, h, sum / s.size(), s[s.size() / 2], s[std::min(s.size() - 1, size_t(s.size() * 0.95))],
              s.back());
  if (!render3dMs_.empty()) {
    std::vector<double> r = render3dMs_;
    std::sort(r.begin(), r.end());
    double total = 0;
    for (double x : r) total += x;
    std::printf("frame-stats: %zu 3D view renders at %dx%d: mean %.1f ms, median %.1f ms, max %.1f ms\n", r.size(),
                View3D::kSize, View3D::kSize, total / r.size(), r[r.size() / 2], r.back());
  }
  std::fflush(stdout);
}

}  // namespace

int runViewer(const ViewerOptions& options) {
  Viewer v(options);
  return v.loop();
}

}  // namespace voxlab
