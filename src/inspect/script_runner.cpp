// Script verbs (voxlab view --script): the same actions a user performs with the mouse and the
// keyboard, plus expectations for the tests in tests/viewer. The verbs and their usage are in
// inspect_logic.cpp (parseScript); nothing here names a stage, a technique or a semantic.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "capture/image_files.h"
#include "core/args.h"
#include "core/error.h"
#include "core/paths.h"
#include "gpu/gl_debug.h"
#include "inspect/viewer_state.h"
#include "techniques/common/light_stage.h"

namespace voxlab {

namespace fs = std::filesystem;

namespace {

// Reads an 8-bit image (PNG) as bytes (channels as stored) for the script's image comparisons.
std::vector<uint8_t> readImageBytes(const std::string& path, int& w, int& h) {
  ImageFileData img = readImageFile(path);
  w = img.width;
  h = img.height;
  std::vector<uint8_t> px(img.pixels.size());
  for (size_t i = 0; i < px.size(); ++i) px[i] = uint8_t(std::lround(std::clamp(img.pixels[i], 0.0f, 1.0f) * 255.0f));
  return px;
}

}  // namespace

void Viewer::scriptFail(const ScriptAction& a, const std::string& msg) const {
  throw Error(opt.script + ":" + std::to_string(a.line) + ": " + a.verb + ": " + msg);
}

void Viewer::stepScript() {
  if (scriptBusy()) return;
  if (pc >= script.size()) {
    quit = true;
    return;
  }
  const ScriptAction a = script[pc++];  // a copy: walk-stages inserts actions into script
  frameHeavy = true;  // script I/O (saving, comparing) is not UI time
  try {
    execute(a);
  } catch (const Error& e) {
    std::string m = e.what();
    if (m.rfind(opt.script + ":", 0) == 0) throw;
    scriptFail(a, m);
  }
}

void Viewer::execute(const ScriptAction& a) {
  const Technique& t = cursor->technique();
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
  if (v.rfind("soak", 0) == 0) {
    executeSoak(a);
    return;
  }
  if (v == "technique") {
    if (arg(0) != t.id()) switchTechnique(arg(0));
  } else if (v == "scene") {
    if (!loadSceneNamed(arg(0))) std::printf("scene error: %s\n", sceneError.c_str());
  } else if (v == "drop") {
    if (!dropFile(arg(0))) std::printf("scene error: %s\n", sceneError.c_str());
  } else if (v == "turn-light") {
    if (!turnLight(floatArg(0), floatArg(1))) scriptFail(a, status);
    std::printf("light: azimuth %s, elevation %s\n", cursor->params().formatted().at(kLightAzimuth).c_str(),
                cursor->params().formatted().at(kLightElevation).c_str());
  } else if (v == "expect-scene") {
    if (scene->name != arg(0)) scriptFail(a, "scene is " + scene->name + ", expected " + arg(0));
  } else if (v == "expect-scene-error") {
    std::string text;
    for (const auto& w : a.args) text += (text.empty() ? "" : " ") + w;
    if (sceneError.empty() || sceneError.find(text) == std::string::npos)
      scriptFail(a, "last scene error is '" + sceneError + "', expected it to contain '" + text + "'");
  } else if (v == "stage") {
    selectStage(t.stageIndex(arg(0)));
  } else if (v == "output") {
    selectOutput(arg(0));
  } else if (v == "level") {
    view.level = intArg(0);
  } else if (v == "slice") {
    std::string ax = arg(0);
    if (ax != "x" && ax != "y" && ax != "z") scriptFail(a, "axis must be x, y or z");
    view.slice.axis = ax[0] - 'x';
    view.slice.index = intArg(1);
  } else if (v == "channel") {
    view.display.channel = std::clamp(intArg(0), -1, 3);
  } else if (v == "exposure") {
    view.display.exposure = floatArg(0);
  } else if (v == "set") {
    std::string s = arg(0);
    size_t eq = s.find('=');
    if (eq == std::string::npos) scriptFail(a, "expected NAME=VALUE");
    ParamSet candidate = cursor->params();
    candidate.setText(s.substr(0, eq), s.substr(eq + 1));
    if (!applyParams(candidate)) std::printf("%s\n", status.c_str());
  } else if (v == "reset-params") {
    applyParams(t.defaultParams());
  } else if (v == "expect-refusal") {
    std::string text;
    for (const auto& w : a.args) text += (text.empty() ? "" : " ") + w;
    if (budgetRefusal.empty() || budgetRefusal.find(text) == std::string::npos)
      scriptFail(a, "last parameter change refusal is '" + budgetRefusal + "', expected it to contain '" + text + "'");
    std::printf("refused: %s\n", budgetRefusal.c_str());
  } else if (v == "camera") {
    setCameraIndex(intArg(0));
  } else if (v == "orbit") {
    orbit(floatArg(0), floatArg(1));
  } else if (v == "frame-scene") {
    frameScene();
  } else if (v == "size") {
    Args::parseSize(arg(0), opt.width, opt.height);
    cursor->setViewSize(opt.width, opt.height);
    paramsChanged();
  } else if (v == "run") {
    lastRunRequest = std::max(lastRunRequest, selected);
    requestRun(selected);
  } else if (v == "runall") {
    lastRunRequest = t.stageCount() - 1;
    requestRun(lastRunRequest);
  } else if (v == "next") {
    selectStage(selected + 1);
    lastRunRequest = std::max(lastRunRequest, selected);
    requestRun(selected);
  } else if (v == "prev") {
    selectStage(selected - 1);
  } else if (v == "probe") {
    probePixel(intArg(0), intArg(1));
  } else if (v == "lesson") {
    lesson = loadLesson(arg(0));
    applyLessonStep(0);
  } else if (v == "lesson-next" || v == "lesson-prev") {
    if (lesson.steps.empty()) scriptFail(a, "no lesson is open");
    int next = lessonStep + (v == "lesson-next" ? 1 : -1);
    if (next < 0 || next >= int(lesson.steps.size()))
      scriptFail(a, "no step " + std::to_string(next + 1) + "; the lesson has " + std::to_string(lesson.steps.size()));
    applyLessonStep(next);
    std::printf("lesson step %d/%zu: %s/%s\n", next + 1, lesson.steps.size(), lesson.steps[next].stage.c_str(),
                lesson.steps[next].output.c_str());
  } else if (v == "lesson-end") {
    if (lesson.steps.empty()) scriptFail(a, "no lesson is open");
    if (lessonStep + 1 < int(lesson.steps.size())) {
      applyLessonStep(lessonStep + 1);
      std::printf("lesson step %d/%zu: %s/%s\n", lessonStep + 1, lesson.steps.size(),
                  lesson.steps[lessonStep].stage.c_str(), lesson.steps[lessonStep].output.c_str());
      --pc;  // repeat this action after the step has run
    }
  } else if (v == "save-view") {
    refreshCapture();
    if (!capError.empty()) scriptFail(a, capError);
    if (viewMode != ViewMode::Slice) update3D();
    else if (isCameraImage(selected, cap)) updateOverlay();
    fs::path p(arg(0));
    std::error_code ec;
    if (p.has_parent_path()) fs::create_directories(p.parent_path(), ec);
    writePng(viewportImage(), arg(0));
    std::printf("saved view %s\n", arg(0).c_str());
  } else if (v == "screenshot") {
    pendingScreenshot = arg(0);
    screenshotDelay = 2;  // let ImGui settle one frame after the last change
  } else if (v == "save-output" || v == "compare-output") {
    refreshCapture();
    if (!capError.empty()) scriptFail(a, capError);
    std::string prefix = std::string(t.stage(selected).id()) + "." + cap.desc.name;
    if (v == "save-output") {
      std::error_code ec;
      fs::create_directories(arg(0), ec);
      auto e = writeOutputFiles(cap, arg(0), prefix);
      std::printf("saved %s: %s\n", prefix.c_str(), e["files"].dump().c_str());
      return;
    }
    double tol = a.args.size() > 2 ? floatArg(2) : 0.0;
    if (cap.desc.kind == OutputKind::Buffer) {
      std::string x = readTextFile(arg(0) + "/" + prefix + ".bin"), y = readTextFile(arg(1) + "/" + prefix + ".bin");
      uint32_t stride = std::max<uint32_t>(cap.desc.layout.stride, 1);
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
    size_t levels = cap.levels.size();
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
    const ImageDifference d = imageDifference(p, w1, h1, q, w2, h2);
    std::printf("%s vs %s: %zu of %zu pixels differ (%.4f)\n", arg(0).c_str(), arg(1).c_str(), d.differing, d.pixels,
                d.fraction());
    if (v == "expect-images-differ") {
      const double atLeast = floatArg(2);
      if (!(atLeast >= 0.0 && atLeast < 1.0)) scriptFail(a, "MIN_FRACTION must be in 0..1, not " + arg(2));
      if (!(d.fraction() > atLeast))
        scriptFail(a, std::to_string(d.differing) + " of " + std::to_string(d.pixels) + " pixels differ (" +
                          std::to_string(d.fraction()) + "), expected more than " + arg(2));
    }
    if (v == "expect-images-equal" && d.differing != 0) scriptFail(a, std::to_string(d.differing) + " pixels differ");
  } else if (v == "expect-probe-records") {
    // Every probe record of every probing stage, checked by its visualiser (cone samples: the
    // accumulated opacity of every sample is the front-to-back composite of the one before and
    // the sample's own alpha).
    const size_t atLeast = size_t(std::max(intArg(0), 0));
    const auto& records = probeRecords();
    if (records.empty()) scriptFail(a, "technique " + t.id() + " declares no probe-record output on a probing stage");
    for (const auto& r : records) {
      const std::string name = std::string(t.stage(r.stage).id()) + "/" + r.desc->name;
      if (!r.error.empty()) scriptFail(a, name + ": " + r.error);
      const Visualiser& vis = visualiserFor(r.out.desc);
      RecordCheck c = vis.checkRecords(r.out);
      if (c.elements <= atLeast)
        scriptFail(a, name + ": " + c.summary + ", expected more than " + std::to_string(atLeast) + " (" + vis.name() + ")");
      if (!c.error.empty()) scriptFail(a, name + ": " + c.error);
      std::printf("probe: %s (%s): %s\n", name.c_str(), vis.name(), c.summary.c_str());
    }
  } else if (v == "record-step" || v == "expect-record-step") {
    // The step slider of a probe record's view (Visualiser::recordSteps): the same int the Probe
    // tab's slider moves, kept per record output.
    const ProbeRecords* rec = nullptr;
    std::vector<std::string> names;
    for (const auto& r : probeRecords()) {
      const std::string name = std::string(t.stage(r.stage).id()) + "/" + r.desc->name;
      if (r.error.empty() && visualiserFor(r.out.desc).recordSteps(r.out) > 0) names.push_back(name);
      if (name == arg(0)) rec = &r;
    }
    if (!rec) scriptFail(a, "no probe record '" + arg(0) + "'; with steps now: " + joinNames(names));
    if (!rec->error.empty()) scriptFail(a, arg(0) + ": " + rec->error);
    const Visualiser& vis = visualiserFor(rec->out.desc);
    const int n = int(vis.recordSteps(rec->out));
    if (n == 0) scriptFail(a, arg(0) + " (" + vis.name() + ") has no steps to show; with steps now: " + joinNames(names));
    int& k = recordStep[arg(0)];
    if (v == "record-step") {
      if (arg(1) == "first") k = 0;
      else if (arg(1) == "last") k = n - 1;
      else if (arg(1) == "next") k = k + 1;
      else if (arg(1) == "prev") k = k - 1;
      else k = intArg(1);
      if (k < 0 || k >= n) scriptFail(a, "step " + std::to_string(k) + " is outside 0.." + std::to_string(n - 1));
    }
    k = std::clamp(k, 0, n - 1);
    const std::string said = vis.describeRecordStep(rec->out, size_t(k));
    std::printf("%s step %d of %d: %s\n", arg(0).c_str(), k, n, said.c_str());
    if (v == "expect-record-step") {
      std::string text;
      for (size_t i = 1; i < a.args.size(); ++i) text += (text.empty() ? "" : " ") + a.args[i];
      if (said.find(text) == std::string::npos)
        scriptFail(a, arg(0) + " step " + std::to_string(k) + " shows '" + said + "', expected it to contain '" + text + "'");
    }
  } else if (v == "expect-state") {
    int i = t.stageIndex(arg(0));
    std::string want = arg(1) == "not-run" ? "not run" : arg(1);
    std::string got = stageStateName(cursor->record(i).state);
    if (got != want) scriptFail(a, "stage " + arg(0) + " is " + got + ", expected " + want);
  } else if (v == "expect-stat") {
    const auto& stats = cursor->record(t.stageIndex(arg(0))).stats;
    auto it = stats.find(arg(1));
    if (it == stats.end()) scriptFail(a, "stage " + arg(0) + " has no statistic '" + arg(1) + "' (it may not have run)");
    const double got = it->second, want = floatArg(3);
    const std::string& op = arg(2);
    bool ok = false;
    if (op == "=") ok = got == want;
    else if (op == "<") ok = got < want;
    else if (op == ">") ok = got > want;
    else if (op == "<=") ok = got <= want;
    else if (op == ">=") ok = got >= want;
    else scriptFail(a, "unknown comparison '" + op + "'; valid: = < > <= >=");
    if (!ok) scriptFail(a, arg(0) + " " + arg(1) + " is " + std::to_string(got) + ", expected " + op + " " + arg(3));
  } else if (v == "expect-param") {
    std::string got = cursor->params().desc(arg(0)).format(cursor->params().value(arg(0)));
    if (got != arg(1)) scriptFail(a, arg(0) + " is " + got + ", expected " + arg(1));
  } else if (v == "copy-command") {
    copied = commandLine();
    glfwSetClipboardString(window->handle(), copied.c_str());
    std::printf("command: %s\n", copied.c_str());
  } else if (v == "reload") {
    reloadShaders();
    if (!shaderError.empty()) std::printf("shader reload failed: %s\n", shaderError.c_str());
  } else if (v == "wait") {
    waitFrames = intArg(0);
  } else if (v == "tab") {
    std::vector<std::string> ids;
    for (const auto& tab : detailsTabs()) ids.push_back(tab.id);
    if (std::find(ids.begin(), ids.end(), arg(0)) == ids.end())
      scriptFail(a, "unknown tab '" + arg(0) + "'; valid: " + joinNames(ids));
    wantTab = arg(0);
  } else if (v == "view-mode") {
    if (arg(0) == "slice") viewMode = ViewMode::Slice;
    else if (arg(0) == "3d") viewMode = ViewMode::Volume;
    else if (arg(0) == "cubes") viewMode = ViewMode::Cubes;
    else scriptFail(a, "unknown mode '" + arg(0) + "'; valid: slice, 3d, cubes");
    if (viewMode != ViewMode::Slice) {
      refreshCapture();
      if (capError.empty() && !has3DView())
        scriptFail(a, "output " + cap.desc.name + " (" + kindName(cap.desc.kind) + ") has no 3D view");
    }
  } else if (v == "auto-rerun") {
    if (arg(0) != "on" && arg(0) != "off") scriptFail(a, "expected on or off, not '" + arg(0) + "'");
    autoRerun = arg(0) == "on";
  } else if (v == "ui-scale") {
    float s = floatArg(0);
    if (!(s >= 0.75f && s <= 3.0f)) scriptFail(a, "scale must be in 0.75..3, not " + arg(0));
    wantUiScale = s;
    waitFrames = 2;
  } else if (v == "view-dragging") {
    if (arg(0) != "on" && arg(0) != "off") scriptFail(a, "expected on or off, not '" + arg(0) + "'");
    scriptDragging = arg(0) == "on";
  } else if (v == "view-orbit") {
    orbit3d.rotate(floatArg(0), floatArg(1));
  } else if (v == "expect-view-nonempty") {
    refreshCapture();
    if (!capError.empty()) scriptFail(a, capError);
    if (!update3D()) scriptFail(a, "no 3D view is shown (view-mode 3d|cubes on a volume or a buffer with positions)");
    if (!msg3d.empty() && msg3d.find("over the limit") != std::string::npos) scriptFail(a, msg3d);
    const ViewContent c = view3d->content();
    const double minFraction = floatArg(0), minSpread = floatArg(1);
    if (!(minFraction >= 0.0 && minFraction < 1.0)) scriptFail(a, "MIN_FRACTION must be in 0..1, not " + arg(0));
    std::printf("view %s of %s: %zu of %zu pixels show content (%.4f, need > %s), luma spread %.1f (need > %s); %s; "
                "render %.1f ms\n",
                viewModeName(viewMode), cap.desc.name.c_str(), c.content, c.pixels, c.fraction(), arg(0).c_str(),
                c.lumaStdDev, arg(1).c_str(), info3d.c_str(), render3dMs.empty() ? 0.0 : render3dMs.back());
    if (!(c.fraction() > minFraction))
      scriptFail(a, std::to_string(c.fraction()) + " of the view shows content, expected more than " + arg(0));
    if (!(c.lumaStdDev > minSpread))
      scriptFail(a, "the content is flat: luma standard deviation " + std::to_string(c.lumaStdDev) +
                        " of 255, expected more than " + arg(1));
  } else if (v == "iterate") {
    if (cursor->iterations(selected) <= 1) scriptFail(a, std::string("stage ") + t.stage(selected).id() + " is not iterative");
    stepIteration();
  } else if (v == "expect-iterations") {
    const StageRecord& r = cursor->record(t.stageIndex(arg(0)));
    int want = intArg(1);
    if (r.iterationsRun != want || (r.state != StageState::Partial && r.state != StageState::Done))
      scriptFail(a, arg(0) + " is " + stageStateName(r.state) + " after " + std::to_string(r.iterationsRun) + " of " +
                        std::to_string(r.iterationsTotal) + " iterations, expected " + arg(1));
    std::printf("%s: %d of %d iterations (%s)\n", arg(0).c_str(), r.iterationsRun, r.iterationsTotal, stageStateName(r.state));
  } else if (v == "walk-stages") {
    auto more = walkStagesActions(a);
    script.insert(script.begin() + long(pc), more.begin(), more.end());
  } else if (v == "fly") {
    moveCamera(flyCamera(liveCamera(), floatArg(0), floatArg(1), floatArg(2)));
  } else if (v == "look") {
    moveCamera(lookCamera(liveCamera(), floatArg(0), floatArg(1)));
  } else if (v == "overlay") {
    if (arg(1) != "on" && arg(1) != "off") scriptFail(a, "expected on or off, not '" + arg(1) + "'");
    bool on = arg(1) == "on";
    if (arg(0) == "bounds") overlayOpt.bounds = on;
    else if (arg(0) == "voxels") overlayOpt.voxels = on;
    else if (arg(0) == "xray") overlayOpt.xray = on;
    else scriptFail(a, "unknown overlay '" + arg(0) + "'; valid: bounds, voxels, xray");
  } else if (v == "overlay-volume") {
    auto vols = overlayVolumes();
    if (std::find(vols.begin(), vols.end(), arg(0)) == vols.end())
      scriptFail(a, "no volume '" + arg(0) + "' has run; valid: " + joinNames(vols));
    overlayVolume = arg(0);
    overlayLevel = intArg(1);
  } else if (v == "expect-overlay-pixels") {
    refreshCapture();
    if (!capError.empty()) scriptFail(a, capError);
    if (!isCameraImage(selected, cap)) scriptFail(a, "output " + cap.desc.name + " is not a camera image; overlays apply to those");
    updateOverlay();
    if (overlayKey.empty()) scriptFail(a, "no overlay is on (overlay bounds|voxels on)");
    size_t n = overlay->coveredPixels(), want = size_t(std::max(intArg(0), 0));
    std::printf("overlay on %s: %zu pixels covered (need > %zu), %zu voxel cubes, %.1f ms; %s\n", cap.desc.name.c_str(), n,
                want, overlay->cubeCount(), overlayMs, overlayMsg.c_str());
    if (n <= want) scriptFail(a, std::to_string(n) + " pixels covered, expected more than " + arg(0));
  } else if (v == "expect-overlay-camera") {
    refreshCapture();
    if (!capError.empty()) scriptFail(a, capError);
    if (!isCameraImage(selected, cap)) scriptFail(a, "output " + cap.desc.name + " is not a camera image; overlays apply to those");
    updateOverlay();
    if (overlayKey.empty()) scriptFail(a, "no overlay is on (overlay bounds|voxels on)");
    const glm::vec3 want(floatArg(0), floatArg(1), floatArg(2));
    const glm::vec3 got = overlayEye - liveCamera().position;
    std::printf("overlay camera: the viewer's camera + (%g, %g, %g)\n", got.x, got.y, got.z);
    // Float rounding of P + K D against (P + K D) - P; measured 0 for lesson 08's path (K D = 1 m).
    if (glm::any(glm::greaterThan(glm::abs(got - want), glm::vec3(1e-4f))))
      scriptFail(a, "the overlay is drawn from the viewer's camera + (" + std::to_string(got.x) + ", " +
                        std::to_string(got.y) + ", " + std::to_string(got.z) + "), expected + (" + arg(0) + ", " +
                        arg(1) + ", " + arg(2) + ")");
  } else if (v == "click") {
    // A left click on pixel (X, Y) of the shown 2D view (from its top left), as the mouse does.
    refreshCapture();
    if (!capError.empty()) scriptFail(a, capError);
    VisualiserContext ctx = visualiserContext();
    glm::ivec3 element;
    const int x = intArg(0), y = intArg(1);
    SliceImage img = shownVisualiser()->image2D(ctx);
    bool found = false;
    if (!img.pick.empty()) {  // a pick map (point views): the element drawn at that pixel
      int id = x >= 0 && y >= 0 && x < img.width && y < img.height ? img.pick[size_t(y) * img.width + x] : -1;
      found = id >= 0;
      element = glm::ivec3(id, 0, 0);
    } else {
      found = shownVisualiser()->elementAt(ctx, x, y, element);
    }
    if (!found) scriptFail(a, "nothing of " + cap.desc.name + " is shown at (" + arg(0) + ", " + arg(1) + ")");
    pickTexel = element;
    int probed = probeSpacesOfShown().empty() ? 0 : probeShownAt(element, view.level);
    std::printf("click %s: %s; %d probe(s) set\n", cap.desc.name.c_str(), shownVisualiser()->describeElement(ctx, element).c_str(),
                probed);
  } else if (v == "expect-visualiser") {
    refreshCapture();
    if (!capError.empty()) scriptFail(a, capError);
    std::string got = shownVisualiser()->name();
    if (got != arg(0)) scriptFail(a, "output " + cap.desc.name + " is shown by visualiser '" + got + "', expected '" + arg(0) + "'");
    std::printf("output %s (%s, %s): visualiser %s\n", cap.desc.name.c_str(), kindName(cap.desc.kind),
                semanticName(cap.desc.semantic), got.c_str());
  } else if (v == "keep-snapshot") {
    refreshCapture();
    if (!capError.empty()) scriptFail(a, capError);
    compare.snapshot = cap;
    compare.snapshotLabel = std::string(t.stage(selected).id()) + "/" + cap.desc.name;
    for (const auto& [name, value] : cursor->params().formatted())
      if (t.defaultParams().formatted().at(name) != value) compare.snapshotLabel += " " + name + "=" + value;
  } else if (v == "compare-with") {
    const std::string& what = arg(0);
    compare.on = what != "off";
    if (what == "output") {
      if (a.args.size() < 2) scriptFail(a, "compare-with output STAGE/OUTPUT");
      auto outs = imageOutputs();
      if (std::find(outs.begin(), outs.end(), arg(1)) == outs.end())
        scriptFail(a, "no image output '" + arg(1) + "' has run; valid: " + joinNames(outs));
      compare.source = CompareState::Source::Output;
      compare.other = arg(1);
    } else if (what == "snapshot") {
      if (!compare.snapshot) scriptFail(a, "no snapshot kept (keep-snapshot)");
      compare.source = CompareState::Source::Snapshot;
    } else if (what == "file") {
      if (a.args.size() < 2) scriptFail(a, "compare-with file PATH");
      if (!fileExists(arg(1))) scriptFail(a, "file '" + arg(1) + "' does not exist");
      compare.source = CompareState::Source::File;
      std::snprintf(compare.file, sizeof compare.file, "%s", arg(1).c_str());
    } else if (what != "off") {
      scriptFail(a, "unknown source '" + what + "'; valid: output, snapshot, file, off");
    }
    compare.key.clear();
  } else if (v == "compare-mode") {
    if (arg(0) == "side") compare.mode = CompareState::Mode::SideBySide;
    else if (arg(0) == "split") compare.mode = CompareState::Mode::Split;
    else if (arg(0) == "difference") compare.mode = CompareState::Mode::Difference;
    else scriptFail(a, "unknown mode '" + arg(0) + "'; valid: side, split, difference");
    if (a.args.size() > 1) compare.split = std::clamp(floatArg(1), 0.0f, 1.0f);
  } else if (v == "print-compare") {
    refreshCapture();
    if (!capError.empty()) scriptFail(a, capError);
    if (!compare.on) scriptFail(a, "compare is off (compare-with ...)");
    if (cap.desc.kind != OutputKind::Image2D) scriptFail(a, "output " + cap.desc.name + " is not an image");
    compare.key.clear();
    const auto t0 = std::chrono::steady_clock::now();
    updateCompare();
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (!compare.error.empty()) scriptFail(a, compare.error);
    const auto& m = *compare.metrics;
    // %.9g: enough digits for the test to compare with `voxlab compare --json`.
    std::printf("compare %s vs %s: rmse %.9g psnr %.9g mae %.9g max_abs %.9g ssim %.9g (%.1f ms)\n", cap.desc.name.c_str(),
                compare.otherLabel.c_str(), m.rmse, m.psnr, m.mae, m.maxAbs, m.ssim, ms);
    if (!a.args.empty() && !(m.rmse > floatArg(0)))
      scriptFail(a, "rmse " + std::to_string(m.rmse) + " is not above " + arg(0));
  } else if (v == "present") {
    if (arg(0) != "on" && arg(0) != "off") scriptFail(a, "expected on or off, not '" + arg(0) + "'");
    setPresenting(arg(0) == "on");
    waitFrames = 2;  // the UI scale follows the window from the next frame
  } else if (v == "key") {
    static const std::pair<const char*, int> kKeys[] = {
        {"right", GLFW_KEY_RIGHT}, {"left", GLFW_KEY_LEFT},   {"pagedown", GLFW_KEY_PAGE_DOWN}, {"pageup", GLFW_KEY_PAGE_UP},
        {"space", GLFW_KEY_SPACE}, {"backspace", GLFW_KEY_BACKSPACE}, {"home", GLFW_KEY_HOME},  {"end", GLFW_KEY_END},
        {"p", GLFW_KEY_P},         {"f11", GLFW_KEY_F11},     {"escape", GLFW_KEY_ESCAPE}};
    int key = -1;
    for (const auto& [name, code] : kKeys)
      if (arg(0) == name) key = code;
    if (arg(0).size() == 1 && arg(0)[0] >= '0' && arg(0)[0] <= '9') key = GLFW_KEY_0 + (arg(0)[0] - '0');
    if (key < 0) scriptFail(a, "unknown key '" + arg(0) + "'; valid: right, left, pagedown, pageup, space, backspace, home, end, 0..9, p, f11, escape");
    const int before = lessonStep;
    if (!presenterKey(key)) scriptFail(a, "key " + arg(0) + " does nothing here (presenter mode is " +
                                              (presenter.on ? "on" : "off") + (lesson.steps.empty() ? ", no lesson is open)" : ")"));
    if (lessonStep != before)
      std::printf("key %s: lesson step %d/%zu: %s/%s\n", arg(0).c_str(), lessonStep + 1, lesson.steps.size(),
                  lesson.steps[lessonStep].stage.c_str(), lesson.steps[lessonStep].output.c_str());
    else
      std::printf("key %s: presenter mode %s, lesson step %d\n", arg(0).c_str(), presenter.on ? "on" : "off", lessonStep + 1);
    waitFrames = 2;
  } else if (v == "mouse") {
    presenter.scriptMouse = ImVec2(floatArg(0), floatArg(1));
    waitFrames = 2;  // a revealed panel is drawn from the next frame
  } else if (v == "expect-presenter-view") {
    if (!presenter.on) scriptFail(a, "presenter mode is off (present on)");
    int w, h;
    window->framebufferSize(w, h);
    const float area = (presenter.imageMax.x - presenter.imageMin.x) * (presenter.imageMax.y - presenter.imageMin.y);
    const float fraction = area / float(std::max(w * h, 1));
    std::printf("presenter view: image %.0fx%.0f at (%.0f, %.0f) in a %dx%d window: %.3f of it; narrative at %.1f px\n",
                presenter.imageMax.x - presenter.imageMin.x, presenter.imageMax.y - presenter.imageMin.y, presenter.imageMin.x,
                presenter.imageMin.y, w, h, fraction, presenter.narrativePx);
    if (!(fraction > floatArg(0))) scriptFail(a, "the view's image covers " + std::to_string(fraction) + " of the window, expected more than " + arg(0));
  } else if (v == "expect-region-ink" || v == "expect-regions-differ" || v == "expect-regions-equal") {
    const bool ink = v == "expect-region-ink";
    int w1, h1, w2 = 0, h2 = 0;
    auto p = readImageBytes(arg(0), w1, h1);
    std::vector<uint8_t> q;
    if (!ink) {
      q = readImageBytes(arg(1), w2, h2);
      if (w1 != w2 || h1 != h2 || p.size() != q.size()) scriptFail(a, "the images differ in size");
    }
    const size_t c = p.size() / std::max(size_t(w1) * h1, size_t(1));
    const size_t r = ink ? 1 : 2;
    const int x0 = int(std::floor(floatArg(r) * w1)), y0 = int(std::floor(floatArg(r + 1) * h1));
    const int x1 = int(std::ceil(floatArg(r + 2) * w1)), y1 = int(std::ceil(floatArg(r + 3) * h1));
    if (!(0 <= x0 && x0 < x1 && x1 <= w1 && 0 <= y0 && y0 < y1 && y1 <= h1))
      scriptFail(a, "the region must lie in 0..1 with X0 < X1 and Y0 < Y1");
    auto at = [&](const std::vector<uint8_t>& img, int x, int y) { return &img[(size_t(y) * w1 + x) * c]; };
    size_t count = 0, total = size_t(x1 - x0) * (y1 - y0);
    if (ink) {
      // Text on a background: pixels further than 48 of 255 in any channel from the most common
      // colour (anti-aliased glyph edges below that are not counted).
      std::map<uint32_t, size_t> freq;
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          const uint8_t* px = at(p, x, y);
          ++freq[uint32_t(px[0]) << 16 | uint32_t(px[std::min<size_t>(1, c - 1)]) << 8 | px[std::min<size_t>(2, c - 1)]];
        }
      uint32_t bg = std::max_element(freq.begin(), freq.end(), [](auto& l, auto& rr) { return l.second < rr.second; })->first;
      const int bgc[3] = {int(bg >> 16), int((bg >> 8) & 255), int(bg & 255)};
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          const uint8_t* px = at(p, x, y);
          for (size_t k = 0; k < std::min<size_t>(c, 3); ++k)
            if (std::abs(int(px[k]) - bgc[k]) > 48) {
              ++count;
              break;
            }
        }
      const double fraction = double(count) / double(total);
      std::printf("%s region (%d, %d)-(%d, %d): %.4f of the pixels differ from the most common colour (need > %s)\n",
                  arg(0).c_str(), x0, y0, x1, y1, fraction, arg(5).c_str());
      if (!(fraction > floatArg(5))) scriptFail(a, "only " + std::to_string(fraction) + " of the region's pixels stand out");
      return;
    }
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x)
        if (!std::equal(at(p, x, y), at(p, x, y) + c, at(q, x, y))) ++count;
    std::printf("%s vs %s region (%d, %d)-(%d, %d): %zu of %zu pixels differ\n", arg(0).c_str(), arg(1).c_str(), x0, y0, x1,
                y1, count, total);
    if (v == "expect-regions-differ" && count == 0) scriptFail(a, "the region is identical in both images");
    if (v == "expect-regions-equal" && count != 0) scriptFail(a, std::to_string(count) + " pixels of the region differ");
  } else if (v == "gl-debug-message") {
    // An application message into the context's debug output (severity low: logged, not a
    // failure), as a GL tool or a driver would send one; the GL log tab lists it.
    std::string text;
    for (const auto& w : a.args) text += (text.empty() ? "" : " ") + w;
    glDebugMessageInsert(GL_DEBUG_SOURCE_APPLICATION, GL_DEBUG_TYPE_OTHER, 1, GL_DEBUG_SEVERITY_LOW, -1, text.c_str());
  } else if (v == "expect-gl-log") {
    std::string text;
    for (const auto& w : a.args) text += (text.empty() ? "" : " ") + w;
    const auto log = glDebugLog();
    const GLDebugLogEntry* found = nullptr;
    for (const auto& e : log)
      if (e.message.describe().find(text) != std::string::npos) found = &e;
    if (!found) scriptFail(a, "no GL debug message contains '" + text + "' (" + std::to_string(log.size()) + " in the log)");
    std::printf("gl log: x%d %s\n", found->count, found->message.describe().c_str());
  } else if (v == "expect-no-gl-failures") {
    if (glFailureCount() != scriptGLFailures) {
      std::string last;
      for (const auto& e : glDebugLog())
        if (isGLFailure(e.message)) last = e.message.describe();
      scriptFail(a, std::to_string(glFailureCount() - scriptGLFailures) + " GL failure(s) since the script started; last: " + last);
    }
  } else if (v == "frame-stats") {
    printFrameStats();
  } else if (v == "quit") {
    quit = true;
  }
}

}  // namespace voxlab
