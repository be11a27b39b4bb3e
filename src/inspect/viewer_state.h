// The viewer's state and the actions on it, shared by its panels. viewer.cpp owns the window, the
// frame loop and the state changes; each panel is one file that draws from this state and calls
// its actions:
//   panel_timeline.cpp    technique / scene pickers, stage timeline, run buttons (left)
//   panel_parameters.cpp  parameter widgets from the ParamDescs (left)
//   panel_view.cpp        the view: the output's 2D view through its visualiser, picking, probing
//   panel_view3d.cpp      the 3D view of the output's visualiser
//   panel_overlay.cpp     scene overlays over camera images
//   panel_compare.cpp     compare an image with another output, a snapshot or a reference EXR
//   panel_inspector.cpp, panel_probe.cpp, panel_timing.cpp, panel_lesson.cpp, panel_export.cpp:
//                         the Details tabs, each registered with VOXLAB_REGISTER_DETAILS_TAB
//   panel_presenter.cpp   presenter mode: the view fills the window beside the lesson's narrative
//                         in large type; side panels appear at the window's edges
//   panel_gl_log.cpp      the GL log tab: every GL debug message of the session
//   script_runner.cpp     runs a script (tests drive the same actions as the mouse): each verb is
//                         registered beside its feature with VOXLAB_REGISTER_SCRIPT_VERBS
//                         (script_verbs.h); the image-file checks are script_checks.cpp
//   script_soak.cpp       the soak verb: random valid actions across every technique, leak checks
// A new Details tab (a presenter panel, say) is one more file with one registration; a new script
// verb is one more entry in its feature's registration.
#pragma once
#include <chrono>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <imgui.h>
#include <nlohmann/json.hpp>

#include "capture/capture.h"
#include "graph/resource_budget.h"
#include "gpu/gl.h"
#include "gpu/gl_debug.h"
#include "graph/step_cursor.h"
#include "inspect/inspect_logic.h"
#include "inspect/scene_overlay.h"
#include "inspect/view3d.h"
#include "inspect/viewer.h"
#include "inspect/visualiser.h"
#include "lesson/lesson.h"
#include "platform/glfw_window.h"
#include "reference/image_metrics.h"
#include "run/frames.h"
#include "scene/scene.h"

namespace voxlab {

class ShaderLibrary;

// A GL texture holding one RGBA8 image for ImGui::Image.
struct DisplayTexture {
  GLuint id = 0;
  int width = 0, height = 0;
  void upload(int w, int h, const uint8_t* rgba);
  ImTextureID imgui() const { return reinterpret_cast<ImTextureID>(intptr_t(id)); }
  DisplayTexture() = default;
  DisplayTexture(const DisplayTexture&) = delete;
  DisplayTexture& operator=(const DisplayTexture&) = delete;
  ~DisplayTexture();
};

// What the compare view puts next to the shown image (panel_compare.cpp).
struct CompareState {
  enum class Source { Output, Snapshot, File };
  enum class Mode { SideBySide, Split, Difference };
  bool on = false;
  Source source = Source::Output;
  Mode mode = Mode::Split;
  std::string other;            // Source::Output: "stage/output"
  char file[512] = {0};         // Source::File: an EXR (or PNG) path
  std::optional<CapturedOutput> snapshot;  // Source::Snapshot: a kept copy of an output
  std::string snapshotLabel;    // what was different when it was kept ("cone.count=2")
  float split = 0.5f;           // Mode::Split: fraction of the width showing the shown image
  // Result, recomputed when either side changes.
  std::string key, error, otherLabel;
  std::optional<reference::ImageMetrics> metrics;
  float errorScale = 0.0f;
  DisplayTexture otherTex, diffTex;
  DisplayImage otherImage;      // what otherTex shows (RGB, top row first): Save view PNG puts it beside the image
  bool setByLesson = false;     // a lesson step ("beside") turned the view on: the next step turns it off
};

// What the stage timeline has queued (panel_timeline.cpp); one stage runs per frame.
struct RunQueue {
  int target = -1;        // stage to run through (-1 = idle)
  int iterateStage = -1;  // stage to run iterations of, after the stages before it (-1 = none)
  int iterateTo = 0;      // ... until this many of its iterations have run
  int lastRequest = -1;   // the furthest stage a run was asked for (auto re-run re-runs up to it)
  bool autoRerun = true;  // re-run stale stages after a change
};

// Outputs on demand (viewer.cpp): the runs compute the final image's dependencies and what is
// shown (inspect_logic.h viewerDemand), not every output.
struct DemandState {
  std::vector<std::pair<std::string, std::string>> outputs;  // (stage id, output) last given to the cursor
  // A run under this demand stopped on an error: missing outputs are not queued again until the
  // demand changes or a run completes.
  bool refused = false;
};

// The shown output's 2D image as the view panel draws it (panel_view.cpp), rebuilt when the data or
// the view settings change.
struct View2DState {
  long key[8] = {0};
  DisplayTexture texture;
  SliceImage image;
};

// The mouse over the view's 2D image (panel_view.cpp): hovering, picking, and the drags that orbit
// the camera, turn the light or fly.
struct PointerState {
  bool hover = false;
  glm::ivec3 hoverTexel{0}, pickTexel{-1};
  bool dragging = false, orbiting = false, turningLight = false;
  ImVec2 dragStart{0, 0};
  bool flying = false;  // right drag on a camera image
  double lastFlyTime = 0.0;
};

// A probe record output of a probing stage that has run, captured (panel_probe.cpp).
struct ProbeRecords {
  int stage = -1;
  const OutputDesc* desc = nullptr;
  CapturedOutput out;
  nlohmann::json records;
  std::string error;
};

// The Probe tab's records, refreshed per generation, and its step sliders (panel_probe.cpp).
struct ProbePanelState {
  std::vector<ProbeRecords> cache;
  long cacheKey = -1;
  std::map<std::string, int> recordStep;  // per probe record "stage/output": the step its record view shows
  // The space of the last click or probe verb (none yet: the screen, where the chain is): the
  // Probe tab opens the records of the stages probing there and folds the others.
  ProbeSpace lastSpace = ProbeSpace::Screen;
  std::string scrollTo;  // "stage/output": a record the tab scrolls to once (its step slider was moved by a script)
  int clicks = 0, clicksShown = -1;  // probes set, and the count the tab last opened its records for
  int marksShown = 0;  // probe marks (rings in presenter mode) drawn over the view in the last frame
};

// Scene overlays over camera images (panel_overlay.cpp).
struct OverlayState {
  std::unique_ptr<SceneOverlay> renderer;
  SceneOverlay::Options options{false, false, false, 0.6f};
  std::string volume;  // "stage/output"; "" = the latest volume before the selected stage
  int level = -1;      // -1 = the finest level with at most 32 texels per axis
  int levelCount = 1;  // levels of the overlaid volume (for the slider)
  std::string key, contentKey, message;
  double ms = 0.0;
  glm::vec3 eye{0.0f};  // the camera position the overlay was last drawn from
};

// The 3D view of the shown output (panel_view3d.cpp).
struct View3DState {
  ViewMode mode = ViewMode::Slice;
  std::unique_ptr<View3D> renderer;
  OrbitCamera orbit;
  const Scene* orbitScene = nullptr;  // the orbit starts along the scene camera once per scene
  long contentKey[7] = {-1, -1, -1, -1, -1, -1, -1};
  double renderKey[6] = {-1, 0, 0, 0, 0, 0};
  std::string info, message;
  std::vector<double> renderMs;
  bool dragging = false;
  bool scriptDragging = false;  // view-dragging on: render as while the mouse drags
};

// The script being replayed (script_runner.cpp, --script).
struct ScriptState {
  bool active = false;  // the viewer runs a script (and quits at its end)
  std::vector<ScriptAction> actions;
  size_t next = 0;              // the action to run next
  int waitFrames = 0;           // frames to draw before the next action
  size_t glFailuresAtStart = 0;  // glFailureCount() when the script started
};

// The script's soak run (script_soak.cpp).
struct SoakState {
  bool active = false;
  unsigned long long seed = 0;
  std::mt19937_64 rng;
  double seconds = 0.0, maxRssGrowthMiB = 0.0;
  int maxObjectGrowth = 0, maxProgramGrowth = 0, line = 0, actions = 0, frameAtAction = 0;
  int actionLimit = 0;                         // > 0: exactly this many random actions (a replay)
  std::chrono::steady_clock::time_point start;
  bool baselineTaken = false;
  size_t rssBaseline = 0, rssEnd = 0;          // resident bytes at the two settled points
  GLObjectCounts objectsBaseline, objectsEnd;  // live GL objects at the two settled points
  std::string lastAction;
};

// Presenter mode (panel_presenter.cpp, `voxlab view --present`, keys P / F11).
struct PresenterState {
  bool on = false;
  float restoreScale = 1.0f;          // the UI scale to return to when presenter mode ends
  std::optional<ImVec2> scriptMouse;  // script `mouse X Y`: the pointer for the edge reveal
  bool leftShown = false, rightShown = false;  // side panels revealed by the pointer at an edge
  ImFont* narrativeFont = nullptr;    // the narrative's type (DejaVu Sans when installed)
  ImFont* headingFont = nullptr;
  ImVec2 imageMin{0, 0}, imageMax{0, 0};  // where the view's image was last drawn (window pixels)
  float narrativePx = 0.0f;           // the size the narrative was last fitted at
  // A step's narrative that does not fit at the smallest size a hall can read (32 px at 1080
  // lines) is shown in pages: 'page' of 'pages' (from the last drawing); next / back turn pages
  // before they change the step.
  int page = 0, pages = 1;
};

// The current lesson step's sweep (panel_lesson_sweep.cpp): a child `voxlab sweep` runs it into a
// cache folder named by the request, so the viewer stays responsive and a step seen before plots
// at once; the Lesson tab plots its error and time with the value the view shows ringed.
struct LessonSweepPlot {
  std::string key;      // the sweep's command line; a new one starts another sweep
  std::string dir;      // the cache folder: <temp>/voxlab-sweeps/<hash of key>
  std::string status;   // "running", "" when the report is loaded, else what went wrong
  std::string swept;    // the parameter's name
  int pid = 0;          // the child while it runs
  nlohmann::json report;
  LessonSweepPlot() = default;
  LessonSweepPlot(const LessonSweepPlot&) = delete;
  LessonSweepPlot& operator=(const LessonSweepPlot&) = delete;
  ~LessonSweepPlot();   // ends the child it started, if it still runs
  void stop();
};

// The frames timeline (panel_frames.cpp): the technique played as frames while parameters move and
// an animated scene plays its own animation, as `voxlab run --frames N [--time-range FROM:TO]
// --animate ...` runs them (run/frames.h: the same frame values and the same stale-stage rule), one
// frame's stages after the other's through the run queue. The stage list highlights the stages the
// shown frame re-ran; the Frames tab plots each frame's stage times.
struct FramesTimeline {
  std::vector<ParamAnimation> animations;
  // Seconds of the scene's animation the frames span (a new scene: 0 to its duration); unused on a
  // still scene.
  std::pair<double, double> sceneTimes{0.0, 0.0};
  int count = 16;
  int frame = -1;        // the frame whose values are applied (-1: none yet)
  int running = -1;      // the frame whose stages are still queued (-1: none)
  bool playing = false, looping = false;
  int pauseAt = -1;      // while playing: pause once this frame has run (-1: at the end)
  // A script waits for the playing to stop (frames-play, frames-wait); otherwise only for the
  // frame being run, so a script that steps through a lesson does not play every frame of it.
  bool scriptWaits = false;
  std::vector<int> queued;  // the stages the running frame re-runs
  std::vector<int> reran;   // the stages the shown frame re-ran
  std::map<int, std::vector<float>> stageMs;  // per frame that ran: CPU ms per stage (0: not re-run)
  char animateText[160] = {0};
  std::string error;     // the last animation text refused
};

class Viewer {
 public:
  explicit Viewer(const ViewerOptions& o);
  ~Viewer();
  int loop();

  // --- state changes (shared by the UI, the keyboard, lessons and scripts) ---
  void switchTechnique(const std::string& id);
  bool loadSceneNamed(const std::string& name);  // false + sceneError on failure
  void selectStage(int i);
  void selectOutput(const std::string& name);
  void requestRun(int stage) { runs.target = std::max(runs.target, std::min(stage, cursor->stageCount() - 1)); }
  void runSelected() {
    runs.lastRequest = std::max(runs.lastRequest, selected);
    requestRun(selected);
  }
  void runAll() {
    runs.lastRequest = cursor->stageCount() - 1;
    requestRun(runs.lastRequest);
  }
  void paramsChanged() {
    if (runs.autoRerun) requestRun(std::max(selected, runs.lastRequest));
  }
  void setParam(const std::string& name, double value);  // status line on a bad value
  // Every parameter change goes through here (the widgets, Defaults, scripts): a change whose
  // resources (graph/resource_budget.h) would not fit the GL limits or gpu.memory-budget is not
  // applied; its one-line refusal becomes budgetRefusal and the status line, and the parameters,
  // stage states and results stay as they were. True when applied.
  bool applyParams(const ParamSet& candidate);
  std::string budgetRefusal;  // the last refused change's line ("" after one that fitted)
  std::optional<ResourceLimits> glLimits;  // of the window's context, queried once
  void setCameraIndex(int i);
  // Orbit and fly move the live camera at once; the technique's camera follows whenever no stage is
  // queued, so overlays track the mouse while a slow render catches up.
  const Camera& liveCamera() const { return pendingCamera ? *pendingCamera : cursor->camera(); }
  void moveCamera(const Camera& c);
  void applyPendingCamera();
  void orbit(float yawDeg, float pitchDeg);
  // Turns the light (the light.0.* parameters of techniques/common/light_stage.h) by these angles
  // from where it points now; Shift + left drag on a camera image and the script verb turn-light.
  // False + status when the technique declares no light.0 parameters.
  bool turnLight(float azimuthDeg, float elevationDeg);
  // A file dropped on the window (GLFW drop callback, queued in droppedFiles) or the script verb
  // drop: loaded as loadSceneNamed does, keeping the current scene when it fails.
  bool dropFile(const std::string& path);
  std::vector<std::string> droppedFiles;
  // Key presses since the last frame, in order, from a GLFW key callback: a tap shorter than a
  // frame (what presenter remotes send) is a press here, where Dear ImGui 1.86's per-frame key
  // state can miss it. Presenter mode's keys are read from this queue (handlePresenterKeys).
  std::vector<int> keyPresses;
  static void onKeyEvent(GLFWwindow* window, int key, int scancode, int action, int mods);
  void handleFly();  // right mouse over a camera image: mouse looks, W/A/S/D/Q/E move
  void frameScene();
  // Queues iterations of the selected stage until 'count' of them have run (after the stages
  // before it); by default one more than now.
  void stepIteration(int count = -1);
  void applyLessonStep(int i);
  // --- frames (panel_frames.cpp) ---
  // Applies frame k's parameter values and scene time (clamped to the frames) and queues the stages
  // they make stale, through the final stage. False + status when nothing animates or the values
  // are refused.
  bool showFrame(int k);
  // The scene times the frames span, unset on a still scene (then only parameters animate).
  std::optional<std::pair<double, double>> frameSceneTimes() const;
  // The timeline has something to play: an animated parameter or an animated scene.
  bool framesAnimate() const { return !frames.animations.empty() || sceneAnimation.animated(); }
  void updateFrames();  // per loop: a frame whose stages have run is recorded; playing moves on
  void drawFrames();    // the Frames tab
  bool frameReran(int stage) const;  // the shown frame re-ran this stage
  // Rebuilds programs whose files changed. fromWatch: the periodic file check, which stays quiet
  // when nothing changed.
  void reloadShaders(bool fromWatch = false);
  std::string commandLine() const;
  // An image at the view's size from a stage whose results depend on the camera
  // (Technique::dependsOnView): screen probes and scene overlays apply to these.
  bool isCameraImage(int stage, const CapturedOutput& c) const;

  // --- probes (panel_probe.cpp) ---
  // Stages that declare a probe in 'space' (and, for volume and light probes, for 'resource').
  std::vector<std::pair<int, const ProbeDesc*>> probesFor(ProbeSpace space, const std::string& resource) const;
  bool hasProbes() const;
  // The probe spaces a click on the shown output reaches (none: a click only picks).
  std::vector<ProbeSpace> probeSpacesOfShown() const;
  // A click on element 'texel' (image pixel rows from the top for images) of the shown output:
  // sets the probe parameters of every stage that declares a probe in that output's space and
  // queues what went stale. Returns the number of stages probed.
  int probeShownAt(const glm::ivec3& texel, int level);
  void probePixel(int x, int y);  // screen space: pixel of the camera images (from the top left)
  // Whether the lesson step being shown sets parameter 'name' (a probe it points somewhere).
  bool lessonStepSets(const std::string& name) const;
  // Every probe record output of a probing stage that has run, captured (refreshed per generation).
  const std::vector<ProbeRecords>& probeRecords();

  // --- per frame ---
  // Outputs on demand: the outputs shown now (the view's, the compare view's other image, the
  // overlaid volume), as (stage id, output) pairs.
  std::vector<std::pair<std::string, std::string>> shownOutputs() const;
  // Gives the cursor the demand of what is shown (when it changed) and queues the run of a
  // demanded output that is missing from a stage the runs have reached.
  void updateDemand();
  // Whether a queued run reaches 'stage' (the view says "computing" rather than showing old data).
  bool runQueuedThrough(int stage) const { return runs.target >= stage || runs.iterateStage == stage; }
  bool runPendingStage();  // runs at most one stage; true when one ran
  void refreshCapture();
  void drawUi();
  void drawLeftPanel();    // panel_timeline.cpp (+ drawParameters)
  void drawParameters();   // panel_parameters.cpp
  void drawView();         // panel_view.cpp
  void drawRightPanel();   // the Details tabs (detailsTabs())
  void drawTiming();       // panel_timing.cpp
  void drawLesson();       // panel_lesson.cpp
  void drawExport();       // panel_export.cpp
  void drawProbe();        // panel_probe.cpp
  VisualiserContext visualiserContext();  // of the shown capture
  const Visualiser* shownVisualiser() const;  // nullptr when there is no capture
  bool has3DView() const;
  bool update3D();  // builds the 3D content and renders it when anything shown changed; false = no 3D view
  void draw3DView();
  // Scene overlays over camera images: voxels of a volume level and the volume's bounds.
  void drawOverlayControls();
  void updateOverlay();  // re-renders the overlay when anything it shows changed
  std::vector<std::string> overlayVolumes() const;  // "stage/output" of every volume that has run
  std::vector<std::string> imageOutputs() const;    // "stage/output" of every image that has run
  // Compare (panel_compare.cpp).
  void drawCompareControls();
  void updateCompare();  // recomputes the other image, the difference and the metrics when stale
  bool drawCompareImage(ImVec2 origin, ImVec2 size);  // draws the compared view; false when compare is off
  std::optional<CapturedOutput> compareOther(std::string& label, std::string& error);
  void handleKeys();
  void takeScreenshot(const std::string& path);
  // Rebuilds the font at the scale's size and scales the style (outside a frame); Ctrl+= / Ctrl+-
  // and the Camera/Export tab change it.
  void applyUiScale(float scale);
  // --- presenter mode (panel_presenter.cpp) ---
  void setPresenting(bool on);
  float presenterUiScale() const;  // follows the window: 1 at 1280x720, 1.5 at 1920x1080
  void addPresenterFonts(float scale);  // into the font atlas (applyUiScale)
  // Presenter keys (P / F11 toggle, Escape leaves; with a lesson: Page Down / Right / Space next,
  // Page Up / Left / Backspace previous, Home / End, 1..9 and 0 = step 10). True when handled.
  bool presenterKey(int glfwKey);
  // Polls the presenter keys; true when the arrow and page keys belong to the lesson this frame.
  bool handlePresenterKeys();
  void drawPresenter();  // the whole window in presenter mode (drawUi calls it)
  void drawNarrative(ImVec2 size);
  // The laser pointer: a ring and crosshair over a probed pixel or cell, sized for the audience.
  void drawLaserPointer(ImDrawList* dl, ImVec2 at, ImVec2 imageSize) const;

  // What the view panel shows: the 3D view, or the image with its overlay blended in.
  DisplayImage viewportImage() const;

  // --- script (script_runner.cpp) ---
  bool scriptBusy() const {
    return runs.target >= 0 || runs.iterateStage >= 0 || frames.running >= 0 || (frames.playing && frames.scriptWaits) ||
           pendingCamera || !pendingScreenshot.empty() || script.waitFrames > 0;
  }
  void stepScript();
  void execute(const ScriptAction& a);
  [[noreturn]] void scriptFail(const ScriptAction& a, const std::string& msg) const;
  // Expands walk-stages into the actions that walk every stage and output of the technique.
  std::vector<ScriptAction> walkStagesActions(const ScriptAction& a) const;
  void printFrameStats() const;
  // One random action of the soak (script_soak.cpp).
  std::vector<ScriptAction> soakRandomActions(int line);
  SoakState soak;

  // --- state ---
  ViewerOptions opt;
  std::unique_ptr<GlfwWindow> window;
  std::unique_ptr<ShaderLibrary> shaders;
  std::unique_ptr<StepCursor> cursor;
  // The viewer loaded the scene and alone holds it non-const: the Frames tab poses an animated
  // scene in place (run/frames.h poseCursorScene), with the animation read in the same load.
  std::shared_ptr<Scene> scene;
  SceneAnimation sceneAnimation;
  std::string sceneName;
  std::string sceneError, shaderError, status;
  char scenePath[512] = {0};
  float uiScale = 1.0f, wantUiScale = 1.0f;

  int selected = 0;          // selected stage
  int outputIndex = 0;       // output of the selected stage
  ViewSettings view;         // level, slice, channel, exposure of the shown output
  int cameraIndex = 0;       // scene camera in use (-1 after an orbit or fly)
  std::optional<Camera> pendingCamera;
  RunQueue runs;
  DemandState demand;
  std::vector<std::deque<std::pair<float, float>>> timeHistory;  // per stage: (cpu, gpu) ms of recent runs
  bool watchShaders = true;  // rebuild programs when their files change on disk
  double lastShaderCheck = 0.0;
  long generation = 0;       // bumps whenever a stage runs or the technique/scene changes

  // Capture of the selected output (refreshed when selection or generation changes).
  CapturedOutput cap;
  nlohmann::json capStats, capRecords;  // of cap, computed once per capture (not per frame)
  std::string capError;
  long capKey[4] = {-1, -1, -1, -1};
  View2DState image2d;
  PointerState pointer;

  ProbePanelState probes;
  OverlayState overlay;
  CompareState compare;
  PresenterState presenter;

  FramesTimeline frames;
  Lesson lesson;
  int lessonStep = -1;
  LessonSweepPlot lessonSweep;
  // Writes the shown output's figure (inspect/figure.h, as `voxlab figure`) to 'path'; returns it.
  std::string saveFigure(const std::string& path);
  void drawLessonSweep(const LessonStep& step);
  // The parameter value the view shows, formatted as the sweep's values are ("" when the
  // technique has no such parameter).
  std::string currentParamText(const std::string& name) const;

  ScriptState script;
  std::string pendingScreenshot;
  int screenshotDelay = 0;
  bool quit = false;

  std::vector<double> idleFrameMs;  // frames where no stage ran and no capture was refreshed
  bool frameHeavy = false;
  std::string copied;
  std::string wantTab;  // tab to bring to front on the next frame ("" = leave as is)
  char exportDir[256] = "viewer-out";

  View3DState view3d;
};

// --- Details tabs ------------------------------------------------------------------------------------

struct DetailsTab {
  const char* id;      // script `tab ID`
  const char* label;   // shown on the tab
  int order;           // left to right
  bool (*visible)(const Viewer&);  // nullptr = always
  void (*draw)(Viewer&);
};
const std::vector<DetailsTab>& detailsTabs();  // sorted by order
bool registerDetailsTab(const DetailsTab& tab);
#define VOXLAB_REGISTER_DETAILS_TAB(name, ...) \
  static const bool voxlabDetailsTab_##name = ::voxlab::registerDetailsTab(::voxlab::DetailsTab{__VA_ARGS__})

// Small helpers the panels share (viewer.cpp); formatBytes comes from graph/resource_budget.h.
inline const ImVec4 kWarningColour{0.95f, 0.75f, 0.3f, 1};
inline const ImVec4 kErrorColour{1, 0.4f, 0.4f, 1};
inline const ImVec4 kFrameRerunColour{0.4f, 0.8f, 1.0f, 1};  // a stage the shown frame re-ran

}  // namespace voxlab
