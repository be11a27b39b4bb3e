// The viewer's window, frame loop and state changes; the panels are in panel_*.cpp, each registering
// its script verbs (script_verbs.h); viewer_state.h lists them.
#include "inspect/viewer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <utility>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include "core/error.h"
#include "core/paths.h"
#include "gpu/shader_library.h"
#include "gpu/gl_debug.h"
#include "inspect/viewer_state.h"
#include "techniques/common/light_stage.h"

namespace voxlab {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }
}  // namespace

void DisplayTexture::upload(int w, int h, const uint8_t* rgba) {
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

DisplayTexture::~DisplayTexture() {
  if (id) glDeleteTextures(1, &id);
}

// --- Details tabs --------------------------------------------------------------------------------

namespace {
std::vector<DetailsTab>& tabRegistry() {
  static std::vector<DetailsTab> tabs;
  return tabs;
}
}  // namespace

const std::vector<DetailsTab>& detailsTabs() { return tabRegistry(); }

bool registerDetailsTab(const DetailsTab& tab) {
  auto& tabs = tabRegistry();
  tabs.push_back(tab);
  std::stable_sort(tabs.begin(), tabs.end(), [](const DetailsTab& a, const DetailsTab& b) { return a.order < b.order; });
  return true;
}

// --- Construction ------------------------------------------------------------------------------

Viewer::Viewer(const ViewerOptions& o) : opt(o) {
  // Validate input that needs no window first, so bad options fail with one line.
  createTechnique(o.technique);
  if (!o.lesson.empty()) lesson = loadLesson(o.lesson);
  if (!o.script.empty()) {
    if (!fileExists(o.script)) throw Error("script file '" + o.script + "' does not exist");
    script.actions = parseScript(readTextFile(o.script), o.script);
    script.active = true;
  }
  SceneAnimation loadedAnimation;
  auto loaded = std::make_shared<Scene>(loadScene(resolveScenePath(o.scene), loadedAnimation));

  window = std::make_unique<GlfwWindow>(o.windowWidth, o.windowHeight, "voxlab");
  shaders = std::make_unique<ShaderLibrary>();
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // layout is fixed; no imgui.ini next to the binary
  ImGui::StyleColorsDark();
  // Installed before ImGui's, which chains to it: every press is queued, however short the tap.
  glfwSetWindowUserPointer(window->handle(), this);
  glfwSetKeyCallback(window->handle(), &Viewer::onKeyEvent);
  ImGui_ImplGlfw_InitForOpenGL(window->handle(), true);
  // Dropped files are queued and loaded at the start of the next frame (dropFile).
  glfwSetDropCallback(window->handle(), [](GLFWwindow* w, int count, const char** paths) {
    auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(w));
    for (int i = 0; i < count; ++i) self->droppedFiles.emplace_back(paths[i]);
  });
  ImGui_ImplOpenGL3_Init("#version 450 core");
  script.glFailuresAtStart = glFailureCount();
  applyUiScale(o.uiScale);
  if (o.present) setPresenting(true);

  scene = loaded;
  sceneAnimation = std::move(loadedAnimation);
  frames.sceneTimes = {0.0, double(sceneAnimation.duration)};
  sceneName = o.scene;
  std::snprintf(scenePath, sizeof scenePath, "%s", o.scene.c_str());
  switchTechnique(o.technique);
  if (!lesson.steps.empty()) {
    applyLessonStep(0);
  } else if (!script.active) {
    // A person opening the viewer sees the technique run, stage by stage, to its final image;
    // scripts start from nothing run and drive every step themselves.
    const int last = cursor->stageCount() - 1;
    selectStage(last);
    runs.lastRequest = last;
    requestRun(last);
  }
}

Viewer::~Viewer() {
  view3d.renderer.reset();
  overlay.renderer.reset();
  cursor.reset();
  shaders.reset();
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
}

// --- State changes -----------------------------------------------------------------------------

void Viewer::switchTechnique(const std::string& id) {
  auto t = createTechnique(id);
  cursor = std::make_unique<StepCursor>(std::move(t), *shaders);
  cursor->setScene(scene);
  cursor->setViewSize(opt.width, opt.height);
  cameraIndex = 0;
  selected = 0;
  outputIndex = 0;
  view.level = 0;
  runs.target = runs.lastRequest = runs.iterateStage = -1;
  pendingCamera.reset();
  timeHistory.assign(cursor->stageCount(), {});
  // The timeline keeps the animations the new technique declares too, and starts over.
  auto& animated = frames.animations;
  animated.erase(std::remove_if(animated.begin(), animated.end(),
                                [&](const ParamAnimation& a) { return !cursor->params().has(a.name); }),
                 animated.end());
  frames.frame = frames.running = frames.pauseAt = -1;
  frames.playing = false;
  frames.reran.clear();
  frames.stageMs.clear();
  overlay.volume.clear();
  overlay.level = -1;
  ++generation;
}

bool Viewer::loadSceneNamed(const std::string& name) {
  try {
    SceneAnimation loadedAnimation;
    auto loaded = std::make_shared<Scene>(loadScene(resolveScenePath(name), loadedAnimation));
    scene = loaded;
    sceneAnimation = std::move(loadedAnimation);
    // The timeline starts over on the new scene, over its whole animation.
    frames.sceneTimes = {0.0, double(sceneAnimation.duration)};
    frames.frame = frames.running = frames.pauseAt = -1;
    frames.playing = false;
    frames.reran.clear();
    frames.stageMs.clear();
    sceneName = name;
    cursor->setScene(scene);
    // Parameters that default to the scene's value (the light) start from the new scene's.
    for (const auto& [pname, desc] : cursor->params().descs())
      if (desc.sceneDefault) cursor->setParam(pname, desc.defaultValue);
    cursor->setViewSize(opt.width, opt.height);
    cameraIndex = 0;
    runs.target = runs.iterateStage = -1;
    pendingCamera.reset();
    sceneError.clear();
    ++generation;
    if (runs.autoRerun && runs.lastRequest >= 0) requestRun(runs.lastRequest);
    return true;
  } catch (const Error& e) {
    sceneError = e.what();  // keep the current scene
    status = "scene not loaded (the current one is kept): " + sceneError;
    return false;
  }
}

void Viewer::selectStage(int i) {
  i = std::clamp(i, 0, cursor->stageCount() - 1);
  if (i != selected) {
    // The final stage opens on the technique's final output; any other stage on its first output.
    outputIndex = 0;
    const Technique& t = cursor->technique();
    if (t.finalStage() == t.stage(i).id()) {
      const auto& outs = t.decl(i).outputs;
      for (size_t k = 0; k < outs.size(); ++k)
        if (outs[k].name == t.finalOutput()) outputIndex = int(k);
    }
    view.level = 0;
    pointer.pickTexel = glm::ivec3(-1);
  }
  selected = i;
}

void Viewer::selectOutput(const std::string& name) {
  const auto& outs = cursor->technique().decl(selected).outputs;
  for (size_t k = 0; k < outs.size(); ++k)
    if (outs[k].name == name) {
      outputIndex = int(k);
      return;
    }
  cursor->technique().findOutput(cursor->technique().stage(selected).id(), name);  // throws listing names
}

void Viewer::setParam(const std::string& name, double value) {
  try {
    ParamSet candidate = cursor->params();
    candidate.set(name, value);  // throws naming the valid range
    applyParams(candidate);
  } catch (const Error& e) {
    status = e.what();
  }
}

bool Viewer::applyParams(const ParamSet& candidate) {
  if (!glLimits) glLimits = ResourceLimits::query();
  const std::string refusal = checkResourceBudget(cursor->technique(), candidate, cursor->view(), *glLimits);
  if (!refusal.empty()) {
    budgetRefusal = refusal;
    status = "not applied: " + refusal;
    return false;
  }
  budgetRefusal.clear();
  if (status.rfind("not applied: ", 0) == 0) status.clear();
  cursor->setParams(candidate);  // marks every stage that declares a changed one (and its readers) stale
  paramsChanged();
  return true;
}

void Viewer::setCameraIndex(int i) {
  cursor->useSceneCamera(i);
  pendingCamera.reset();
  cameraIndex = i;
  paramsChanged();
}

void Viewer::moveCamera(const Camera& c) {
  pendingCamera = c;
  cameraIndex = -1;
}

void Viewer::applyPendingCamera() {
  if (!pendingCamera || runs.target >= 0 || runs.iterateStage >= 0) return;
  cursor->setCamera(*pendingCamera);
  pendingCamera.reset();
  paramsChanged();
}

void Viewer::orbit(float yawDeg, float pitchDeg) {
  moveCamera(orbitCamera(liveCamera(), scene->bounds.center(), yawDeg, pitchDeg));
}

bool Viewer::turnLight(float azimuthDeg, float elevationDeg) {
  if (!cursor->params().has(kLightAzimuth) || !cursor->params().has(kLightElevation)) {
    status = "technique " + cursor->technique().id() + " declares no light.0 parameters (no light stage)";
    return false;
  }
  Light now = applyLightParams(scene->lights.empty() ? defaultSun() : scene->lights[0], cursor->params());
  float az = 0, el = 0;
  sunAngles(now.direction, az, el);
  az = std::fmod(az + azimuthDeg, 360.0f);
  if (az < 0.0f) az += 360.0f;
  el = std::clamp(el + elevationDeg, -90.0f, 90.0f);
  cursor->setParam(kLightAzimuth, az);
  cursor->setParam(kLightElevation, el);
  paramsChanged();
  return true;
}

bool Viewer::dropFile(const std::string& path) {
  bool ok = loadSceneNamed(path);
  status = ok ? "loaded dropped file " + path : "dropped file not loaded (kept the current scene): " + sceneError;
  return ok;
}

void Viewer::handleFly() {
  ImGuiIO& io = ImGui::GetIO();
  double now = glfwGetTime();
  float dt = float(std::clamp(now - pointer.lastFlyTime, 0.0, 0.1));  // a slow frame moves no further than a fast one
  pointer.lastFlyTime = now;
  Camera c = liveCamera();
  bool moved = false;
  if (io.MouseDelta.x != 0.0f || io.MouseDelta.y != 0.0f) {
    c = lookCamera(c, -io.MouseDelta.x * 0.25f, -io.MouseDelta.y * 0.25f);
    moved = true;
  }
  // Speed: a third of the scene's diagonal per second, four times that with Shift.
  float speed = 0.35f * glm::length(scene->bounds.extent()) * (io.KeyShift ? 4.0f : 1.0f) * dt;
  auto axis = [](int plus, int minus) { return float(ImGui::IsKeyDown(plus)) - float(ImGui::IsKeyDown(minus)); };
  float f = axis(GLFW_KEY_W, GLFW_KEY_S), r = axis(GLFW_KEY_D, GLFW_KEY_A), u = axis(GLFW_KEY_E, GLFW_KEY_Q);
  if (f != 0.0f || r != 0.0f || u != 0.0f) {
    c = flyCamera(c, r * speed, u * speed, f * speed);
    moved = true;
  }
  if (moved) moveCamera(c);
}

void Viewer::frameScene() {
  moveCamera(frameBounds(scene->bounds, liveCamera().yfov));
}

void Viewer::stepIteration(int count) {
  const StageRecord& r = cursor->record(selected);
  runs.iterateStage = selected;
  runs.iterateTo = count > 0 ? count : (r.state == StageState::Partial ? r.iterationsRun : 0) + 1;
}

bool Viewer::isCameraImage(int stage, const CapturedOutput& c) const {
  if (c.desc.kind != OutputKind::Image2D || c.levels.empty()) return false;
  if (!cursor->technique().dependsOnView(stage)) return false;
  return c.levels[0].size.x == cursor->view().width && c.levels[0].size.y == cursor->view().height;
}

void Viewer::onKeyEvent(GLFWwindow* window, int key, int, int action, int) {
  auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(window));
  if (self && action == GLFW_PRESS) self->keyPresses.push_back(key);
}

void Viewer::reloadShaders(bool fromWatch) {
  auto errors = shaders->reloadChanged();
  const bool rebuilt = shaders->lastReloadCount() > 0;
  if (fromWatch && errors.empty() && !rebuilt) return;
  auto firstLine = [](const std::string& text) { return text.substr(0, text.find('\n')); };
  if (errors.empty() && !rebuilt && !shaderError.empty()) {
    // Nothing changed since a reload failed (the file watcher's, or an earlier F5): the shader is
    // still broken, so its file:line stays in view and in the status line.
    status = "shader still broken (no file changed since): " + firstLine(shaderError);
    return;
  }
  if (errors.empty()) {
    shaderError.clear();
    cursor->invalidateAll();
    status = "shaders reloaded; every stage is stale";
    if (runs.autoRerun && runs.lastRequest >= 0) requestRun(runs.lastRequest);
  } else {
    shaderError = joinNames(errors, "\n");  // the last good programs stay in use
    status = "shader reload failed: " + firstLine(shaderError);
  }
}

std::string Viewer::commandLine() const {
  const Technique& t = cursor->technique();
  std::string until = selected == t.stageCount() - 1 ? "" : t.stage(selected).id();
  // A scene camera by its index; an orbit or fly camera as --look-from/--look-at (with camera 0's field
  // of view, which orbit and fly keep).
  return reproduceCommand(t.id(), sceneName, cursor->params(), t.defaultParams(), cursor->view().width,
                          cursor->view().height, std::max(cameraIndex, 0), until, "out",
                          cameraIndex < 0 ? &liveCamera() : nullptr);
}

// --- Per frame -----------------------------------------------------------------------------------

bool Viewer::runPendingStage() {
  // One stage (or one iteration) per frame, so the window stays live while a technique runs.
  const int target = runs.iterateStage >= 0 ? runs.iterateStage : runs.target;
  if (target < 0) return false;
  // The first stage that is not Done: before the iterated stage, or up to the run target.
  int next = -1;
  for (int i = 0; i < target + (runs.iterateStage >= 0 ? 0 : 1) && next < 0; ++i)
    if (cursor->record(i).state != StageState::Done) next = i;
  if (next < 0 && runs.iterateStage < 0) {
    runs.lastRequest = std::max(runs.lastRequest, runs.target);
    runs.target = -1;
    return false;
  }
  const int ran = next >= 0 ? next : target;
  try {
    if (next >= 0 && cursor->iterations(next) > 1) {
      cursor->runIteration(next);  // iterative stages one iteration per frame: the timeline shows progress
    } else if (next >= 0) {
      cursor->runThrough(next);  // earlier stages are Done, so this runs exactly one stage
    } else {
      int k = cursor->runIteration(target);
      if (k + 1 >= runs.iterateTo || cursor->record(target).state == StageState::Done) runs.iterateStage = -1;
      status = std::string(cursor->technique().stage(target).id()) + ": iteration " + std::to_string(k + 1) + " of " +
                std::to_string(cursor->record(target).iterationsTotal);
    }
  } catch (const ShaderError& e) {
    shaderError = e.what();
    runs.target = runs.iterateStage = -1;
    if (script.active) throw;
  } catch (const Error& e) {
    // A run refused before it allocated (the resource budget, e.g. a lesson's parameters) or a
    // stage's own error: the viewer keeps what it has and says so; a script fails on it, except
    // during a soak, whose random parameters may be refused as a user's are (the soak goes on and
    // checks that the viewer still draws).
    status = e.what();
    runs.target = runs.iterateStage = -1;
    if (script.active && !soak.active) throw;
    if (soak.active) std::printf("soak: the run stopped with: %s (the viewer keeps its state)\n", status.c_str());
    ++generation;
    return true;
  }
  const StageRecord& r = cursor->record(ran);
  if (r.state == StageState::Done) {
    auto& h = timeHistory.at(ran);
    h.emplace_back(float(r.cpuMs), float(r.gpuMs));
    if (h.size() > 32) h.pop_front();
  }
  ++generation;
  return true;
}

void Viewer::refreshCapture() {
  const Technique& t = cursor->technique();
  const auto& outs = t.decl(selected).outputs;
  if (outs.empty()) {
    capError = "this stage declares no outputs";
    cap = CapturedOutput();
    return;
  }
  outputIndex = std::clamp(outputIndex, 0, int(outs.size()) - 1);
  long key[4] = {long(cursor.get() != nullptr ? generation : 0), selected, outputIndex, 0};
  if (std::equal(key, key + 4, capKey)) return;
  std::copy(key, key + 4, capKey);
  frameHeavy = true;
  const StageRecord& r = cursor->record(selected);
  cap = CapturedOutput();
  cap.desc = outs[outputIndex];
  capStats = capRecords = nlohmann::json();
  capError.clear();
  if (r.state == StageState::NotRun) {
    capError = "not run yet: press Run to here (R)";
    return;
  }
  try {
    cap = captureOutput(cursor->board(), outs[outputIndex]);
  } catch (const Error& e) {
    capError = e.what();
    return;
  }
  capStats = outputStatistics(cap);
  capRecords = cap.desc.kind == OutputKind::Buffer ? recordsJson(cap, 32) : nlohmann::json();
}

const Visualiser* Viewer::shownVisualiser() const {
  if (!capError.empty()) return nullptr;
  return &visualiserFor(cap.desc);
}

VisualiserContext Viewer::visualiserContext() {
  return VisualiserContext{cap, capStats, capRecords, view, contextVolumeLookup(*cursor, selected),
                           contextOutputLookup(*cursor, selected)};
}

void Viewer::handleKeys() {
  ImGuiIO& io = ImGui::GetIO();
  if (io.WantCaptureKeyboard || pointer.flying) return;  // while flying, W/A/S/D/Q/E move the camera
  // In presenter mode with a lesson the arrow and page keys step the lesson (panel_presenter.cpp).
  const bool lessonKeys = handlePresenterKeys();
  if (ImGui::IsKeyPressed(GLFW_KEY_I) && cursor->iterations(selected) > 1) stepIteration();
  if (!lessonKeys && ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_RightArrow))) {
    selectStage(selected + 1);
    runs.lastRequest = std::max(runs.lastRequest, selected);
    requestRun(selected);
  }
  if (!lessonKeys && ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_LeftArrow))) selectStage(selected - 1);
  if (ImGui::IsKeyPressed(GLFW_KEY_R)) {
    runs.lastRequest = std::max(runs.lastRequest, selected);
    requestRun(selected);
  }
  if (ImGui::IsKeyPressed(GLFW_KEY_A)) {
    runs.lastRequest = cursor->stageCount() - 1;
    requestRun(runs.lastRequest);
  }
  if (ImGui::IsKeyPressed(GLFW_KEY_F5)) reloadShaders();
  if (io.KeyCtrl && (ImGui::IsKeyPressed(GLFW_KEY_EQUAL) || ImGui::IsKeyPressed(GLFW_KEY_KP_ADD))) wantUiScale = uiScale + 0.25f;
  if (io.KeyCtrl && (ImGui::IsKeyPressed(GLFW_KEY_MINUS) || ImGui::IsKeyPressed(GLFW_KEY_KP_SUBTRACT)))
    wantUiScale = uiScale - 0.25f;
  // Watch the shader files: about once a second, rebuild the programs whose files changed.
  if (watchShaders && glfwGetTime() - lastShaderCheck > 1.0) {
    lastShaderCheck = glfwGetTime();
    reloadShaders(true);
  }
  if (!lessonKeys && ImGui::IsKeyPressed(GLFW_KEY_PAGE_DOWN) && !lesson.steps.empty()) applyLessonStep(lessonStep + 1);
  if (!lessonKeys && ImGui::IsKeyPressed(GLFW_KEY_PAGE_UP) && !lesson.steps.empty()) applyLessonStep(lessonStep - 1);
}

void Viewer::applyUiScale(float scale) {
  scale = std::clamp(scale, 0.75f, 3.0f);
  ImGuiIO& io = ImGui::GetIO();
  io.Fonts->Clear();
  ImFontConfig font;
  font.SizePixels = std::round(13.0f * scale);  // the default font is drawn for 13 px
  io.Fonts->AddFontDefault(&font);
  addPresenterFonts(scale);  // the presenter's narrative type, sized with the UI
  ImGui_ImplOpenGL3_DestroyFontsTexture();
  ImGui_ImplOpenGL3_CreateFontsTexture();
  ImGuiStyle style;
  ImGui::StyleColorsDark(&style);
  style.ScaleAllSizes(scale);
  ImGui::GetStyle() = style;
  uiScale = wantUiScale = scale;
}

void Viewer::takeScreenshot(const std::string& path) {
  int w, h;
  window->framebufferSize(w, h);
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

int Viewer::loop() {
  while (!window->shouldClose() && !quit) {
    auto t0 = Clock::now();
    frameHeavy = false;
    window->pollEvents();
    for (std::string path : std::exchange(droppedFiles, {})) dropFile(path);
    if (script.active) stepScript();
    if (quit) break;
    if (runPendingStage()) frameHeavy = true;
    updateFrames();
    applyPendingCamera();
    if (wantUiScale != uiScale) {
      applyUiScale(wantUiScale);
      frameHeavy = true;
    }

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    handleKeys();
    refreshCapture();
    drawUi();
    ImGui::Render();
    int w, h;
    window->framebufferSize(w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, w, h);
    glClearColor(0.08f, 0.08f, 0.09f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    if (!pendingScreenshot.empty() && --screenshotDelay <= 0) {
      takeScreenshot(pendingScreenshot);
      std::printf("screenshot %s\n", pendingScreenshot.c_str());
      pendingScreenshot.clear();
      frameHeavy = true;
    }
    window->swapBuffers();
    glFinish();  // count the frame's GPU work (llvmpipe) in its time
    double ms = msSince(t0);
    if (!frameHeavy) idleFrameMs.push_back(ms);
    if (script.waitFrames > 0) --script.waitFrames;
  }
  if (script.active) printFrameStats();
  return 0;
}

// --- UI --------------------------------------------------------------------------------------------

void Viewer::drawUi() {
  if (presenter.on) {
    drawPresenter();
    return;
  }
  ImGuiIO& io = ImGui::GetIO();
  // Side panels grow with the UI scale but leave the view at least 40 % of the window.
  const float kLeftWidth = std::min(330.0f * uiScale, 0.28f * io.DisplaySize.x);
  const float kRightWidth = std::min(380.0f * uiScale, 0.32f * io.DisplaySize.x);
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

void Viewer::drawRightPanel() {
  if (ImGui::BeginTabBar("tabs")) {
    for (const DetailsTab& tab : detailsTabs()) {
      if (tab.visible && !tab.visible(*this)) continue;
      ImGuiTabItemFlags flags = wantTab == tab.id ? ImGuiTabItemFlags_SetSelected : ImGuiTabItemFlags_None;
      if (ImGui::BeginTabItem(tab.label, nullptr, flags)) {
        tab.draw(*this);
        ImGui::EndTabItem();
      }
    }
    ImGui::EndTabBar();
  }
  wantTab.clear();
  if (!shaderError.empty()) {
    ImGui::Separator();
    ImGui::TextColored(kErrorColour, "shader error (last good program kept):");
    ImGui::TextWrapped("%s", shaderError.c_str());
  }
}

int runViewer(const ViewerOptions& options) {
  Viewer v(options);
  return v.loop();
}

}  // namespace voxlab
