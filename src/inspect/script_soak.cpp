// The viewer soak (script verb `soak`, tests/viewer/soak.txt): random but valid UI actions across
// every registered technique, reproducible from a seed, with checks after each action and a leak
// check at the end. Everything comes from the registries and declarations (techniques, stages,
// outputs, ParamDescs, lessons/); nothing here names a technique.
//
//   soak SECONDS SEED MAX_RSS_GROWTH_MIB MAX_OBJECT_GROWTH MAX_PROGRAM_GROWTH [ACTIONS]
//
// First a warm-up tour runs every technique once at its defaults (programs compiled, CPU buffers
// at their sizes, the driver's caches filled), then the viewer is settled (default scene, first
// technique, default parameters, run to the end, slice view, no overlays) and the resident set
// size and the live GL objects (gpu/gl_debug.h: liveGLObjects) are taken as the baseline. Then
// random actions for SECONDS (or exactly ACTIONS of them): switch technique, run all, select and
// run a stage, set a parameter to a valid value near its default, reset the parameters, probe a
// pixel, show another output, toggle 3D views and overlays, orbit, reload shaders, load a good or
// a broken scene, open a lesson and step it. Each is printed with its number before it runs; after
// each: no GL message of severity high or medium and the UI drew a frame since. At the end the
// viewer is settled the same way and measured again: what grew beyond the bounds was kept by
// actions that should have released it. Programs have a bound of their own: the shader library
// keeps one per set of defines a session has used (a parameter that is a program define builds a
// new one), a cache bounded by the combinations used, where other objects should come back. Both
// measurements are taken in the same state, so the result does not depend on which technique the
// random actions happened to end in, nor on how fast the machine was. The sequence depends only on the seed, and the end prints the `soak`
// line (with ACTIONS) that replays it exactly.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <random>
#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "core/error.h"
#include "core/paths.h"
#include "gpu/gl_debug.h"
#include "inspect/script_verbs.h"
#include "inspect/viewer_state.h"

namespace voxlab {

namespace fs = std::filesystem;

namespace {

size_t residentBytes() {
  long pages = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return size_t(resident) * size_t(sysconf(_SC_PAGESIZE));
}

// Resident bytes of the live heap: freed memory that the allocator still holds (glibc keeps the
// high-water mark of each arena, and llvmpipe's threads allocate from several) is handed back
// first, so that two measurements compare what is in use, not the largest it ever was.
size_t settledResidentBytes() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
  return residentBytes();
}

ScriptAction action(std::string verb, std::vector<std::string> args, int line) {
  ScriptAction a;
  a.verb = std::move(verb);
  a.args = std::move(args);
  a.line = line;
  return a;
}

}  // namespace

std::vector<ScriptAction> Viewer::soakRandomActions(int line) {
  std::mt19937_64& rng = soak.rng;
  auto pick = [&](size_t n) { return size_t(std::uniform_int_distribution<size_t>(0, n - 1)(rng)); };
  auto unit = [&]() { return std::uniform_real_distribution<double>(0.0, 1.0)(rng); };
  const Technique& t = cursor->technique();
  std::vector<ScriptAction> acts;
  auto add = [&](std::string verb, std::vector<std::string> args) { acts.push_back(action(std::move(verb), std::move(args), line)); };
  // Weights of the action kinds (out of their sum).
  enum Kind { Switch, RunAll, RunStage, SetParam, Reset, Probe, Output, View3D, Overlay, Orbit, Reload, Scene, Lesson, kKinds };
  static const int kWeight[kKinds] = {2, 3, 3, 5, 1, 2, 2, 2, 1, 1, 1, 1, 2};
  int total = 0;
  for (int w : kWeight) total += w;
  int r = int(pick(size_t(total)));
  int kind = 0;
  while (r >= kWeight[kind]) r -= kWeight[kind++];
  switch (kind) {
    case Switch: {
      const auto& reg = techniqueRegistry();
      add("technique", {reg[pick(reg.size())].id});
      break;
    }
    case RunAll: add("runall", {}); break;
    case RunStage:
      add("stage", {t.stage(int(pick(size_t(t.stageCount())))).id()});
      add("run", {});
      break;
    case SetParam: {
      // A valid value near the default: numbers within a quarter of the way to either end of the
      // range (so a run stays about as expensive as the default one), any choice or flag.
      std::vector<const ParamDesc*> descs;
      for (const auto& [name, d] : cursor->params().descs())
        if (name != memoryBudgetParam().name) descs.push_back(&d);
      if (descs.empty()) break;
      const ParamDesc& d = *descs[pick(descs.size())];
      double v = d.defaultValue;
      const bool scene = ParamDesc::isSceneValue(v);
      const double lo = scene ? d.minValue : v - 0.25 * (v - d.minValue);
      const double hi = scene ? d.maxValue : v + 0.25 * (d.maxValue - v);
      switch (d.type) {
        case ParamType::Bool: v = double(pick(2)); break;
        case ParamType::Choice: v = double(pick(d.choices.size())); break;
        case ParamType::Float: v = lo + unit() * (hi - lo); break;
        case ParamType::Int:
          if (d.powerOfTwo) {
            v = scene ? d.minValue : (pick(2) ? d.defaultValue : std::max(d.minValue, d.defaultValue / 2));
          } else {
            v = std::round(lo + unit() * (hi - lo));
          }
          v = std::clamp(v, d.minValue, d.maxValue);
          break;
      }
      add("set", {d.name + "=" + d.format(v)});
      break;
    }
    case Reset: add("reset-params", {}); break;
    case Probe:
      if (probesFor(ProbeSpace::Screen, "").empty()) break;  // no stage of this technique probes pixels
      add("probe", {std::to_string(pick(size_t(std::max(opt.width, 1)))), std::to_string(pick(size_t(std::max(opt.height, 1))))});
      break;
    case Output: {
      const auto& outs = t.decl(selected).outputs;
      if (!outs.empty()) add("output", {outs[pick(outs.size())].name});
      break;
    }
    case View3D:
      if (view3d.mode != ViewMode::Slice) {
        add("view-mode", {"slice"});
      } else {
        refreshCapture();
        if (capError.empty() && has3DView()) add("view-mode", {pick(2) ? "3d" : "cubes"});
      }
      break;
    case Overlay: add("overlay", {pick(2) ? "bounds" : "voxels", pick(2) ? "on" : "off"}); break;
    case Orbit:
      add("orbit", {std::to_string(int(pick(61)) - 30), std::to_string(int(pick(31)) - 15)});
      break;
    case Reload: add("reload", {}); break;
    case Scene: {
      const std::string choices[] = {"cornell-box", projectPath("tests/data/bad/not-json.gltf"),
                                     projectPath("tests/data/scenes/furnace-box.gltf")};
      add("scene", {choices[pick(3)]});
      break;
    }
    case Lesson:
      if (!lesson.steps.empty() && lessonStep + 1 < int(lesson.steps.size()) && pick(3) != 0) {
        add("lesson-next", {});
      } else {
        std::vector<std::string> files;
        for (const auto& f : fs::directory_iterator(projectPath("lessons")))
          if (f.path().extension() == ".md" && f.path().filename() != "README.md") files.push_back(f.path().string());
        std::sort(files.begin(), files.end());
        if (!files.empty()) add("lesson", {files[pick(files.size())]});
      }
      break;
  }
  return acts;
}

namespace {

// The actions run next, before the rest of the script.
void insertActions(Viewer& viewer, const std::vector<ScriptAction>& more) {
  viewer.script.actions.insert(viewer.script.actions.begin() + long(viewer.script.next), more.begin(), more.end());
}

// The settled state both measurements are taken in: the default scene, the first technique at its
// default parameters, run to its last stage, the slice view without overlays; then the step 'then'.
// Whatever the random actions made on the way (scenes, techniques, parameter variants, 3D views) is
// either released by then or is a cache that the bounds allow for.
std::vector<ScriptAction> settledActions(const ScriptCall& call, const std::string& then) {
  const int line = call.action().line;
  return {action("scene", {"cornell-box"}, line),     action("technique", {techniqueRegistry().front().id}, line),
          action("reset-params", {}, line),           action("view-mode", {"slice"}, line),
          action("overlay", {"bounds", "off"}, line), action("overlay", {"voxels", "off"}, line),
          action("runall", {}, line),                 action(then, {}, line)};
}

double elapsedSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// soak: the warm-up tour of every technique, then the settled state and the baseline.
void soakStart(Viewer& viewer, const ScriptCall& call) {
  SoakState& soak = viewer.soak;
  if (soak.active) call.fail("a soak is already running");
  soak = SoakState();
  soak.active = true;
  try {
    soak.seconds = std::stod(call.arg(0));
    soak.seed = std::stoull(call.arg(1));
    soak.maxRssGrowthMiB = std::stod(call.arg(2));
    soak.maxObjectGrowth = std::stoi(call.arg(3));
    soak.maxProgramGrowth = std::stoi(call.arg(4));
    if (call.count() > 5) soak.actionLimit = std::stoi(call.arg(5));
  } catch (const std::exception&) {
    call.badArgument("SECONDS, SEED, MAX_RSS_GROWTH_MIB, MAX_OBJECT_GROWTH, MAX_PROGRAM_GROWTH and ACTIONS must be numbers");
  }
  soak.rng.seed(soak.seed);
  soak.line = call.action().line;
  if (soak.actionLimit > 0)
    std::printf("soak: seed %llu, %d random actions over %zu techniques\n", (unsigned long long)soak.seed,
                soak.actionLimit, techniqueRegistry().size());
  else
    std::printf("soak: seed %llu, %.0f s of random actions over %zu techniques\n", (unsigned long long)soak.seed,
                soak.seconds, techniqueRegistry().size());
  std::fflush(stdout);
  // The warm-up: every technique once at its defaults (programs compiled, CPU buffers at their
  // sizes, the driver's caches filled), then the settled state and the baseline.
  std::vector<ScriptAction> tour;
  for (const auto& tech : techniqueRegistry()) {
    tour.push_back(action("technique", {tech.id}, call.action().line));
    tour.push_back(action("runall", {}, call.action().line));
    tour.push_back(action("soak-check", {}, call.action().line));
  }
  for (const auto& x : settledActions(call, "soak-baseline")) tour.push_back(x);
  insertActions(viewer, tour);
}

// soak-baseline: the resident memory and the live GL objects in the settled state.
void soakBaseline(Viewer& viewer, const ScriptCall& call) {
  SoakState& soak = viewer.soak;
  soak.rssBaseline = settledResidentBytes();
  soak.objectsBaseline = liveGLObjects();
  soak.baselineTaken = true;
  std::printf("soak: warm-up done; settled: RSS %.1f MiB, GL objects %d (%s)\n", double(soak.rssBaseline) / 1048576.0,
              soak.objectsBaseline.total(), soak.objectsBaseline.describe().c_str());
  std::fflush(stdout);
  soak.start = std::chrono::steady_clock::now();
  insertActions(viewer, {action("soak-step", {}, call.action().line)});
}

// soak-step: one random action and its check, until the time or the action count is up.
void soakStep(Viewer& viewer, const ScriptCall& call) {
  SoakState& soak = viewer.soak;
  const double elapsed = elapsedSince(soak.start);
  const bool done = soak.actionLimit > 0 ? soak.actions >= soak.actionLimit : elapsed >= soak.seconds;
  if (done) {
    std::printf("soak: %d random actions in %.1f s (replay: soak 0 %llu %g %d %d %d)\n", soak.actions, elapsed,
                (unsigned long long)soak.seed, soak.maxRssGrowthMiB, soak.maxObjectGrowth, soak.maxProgramGrowth,
                soak.actions);
    std::fflush(stdout);
    insertActions(viewer, settledActions(call, "soak-finish"));
    return;
  }
  std::vector<ScriptAction> acts;
  while (acts.empty()) acts = viewer.soakRandomActions(call.action().line);
  ++soak.actions;
  std::string text;
  for (const auto& x : acts) {
    text += (text.empty() ? "" : "; ") + x.verb;
    for (const auto& w : x.args) text += " " + w;
  }
  std::printf("soak action %d (seed %llu): %s\n", soak.actions, (unsigned long long)soak.seed, text.c_str());
  std::fflush(stdout);
  soak.lastAction = text;
  acts.push_back(action("soak-check", {}, call.action().line));
  acts.push_back(action("soak-step", {}, call.action().line));
  insertActions(viewer, acts);
  soak.frameAtAction = ImGui::GetFrameCount();
}

// soak-check: no GL failure and a frame drawn since the action.
void soakCheck(Viewer& viewer, const ScriptCall& call) {
  SoakState& soak = viewer.soak;
  const std::string where = soak.baselineTaken ? "after soak action " + std::to_string(soak.actions) + " (seed " +
                                                     std::to_string(soak.seed) + ": " + soak.lastAction + ")"
                                               : "in the soak's warm-up (technique " + viewer.cursor->technique().id() + ")";
  if (glFailureCount() != viewer.script.glFailuresAtStart) {
    std::string last;
    for (const auto& e : glDebugLog())
      if (isGLFailure(e.message)) last = e.message.describe();
    call.fail(where + ": GL failure: " + last);
  }
  if (soak.baselineTaken && !(ImGui::GetFrameCount() > soak.frameAtAction))
    call.fail(where + ": the UI drew no frame");
  if (soak.baselineTaken && soak.actions % 10 == 0) {
    const GLObjectCounts objects = liveGLObjects();
    std::printf("soak at %.0f s: RSS %.1f MiB, GL objects %d (%s)\n", elapsedSince(soak.start),
                double(residentBytes()) / 1048576.0, objects.total(), objects.describe().c_str());
  }
}

// soak-finish: measured again in the settled state; the growth within the bounds.
void soakFinish(Viewer& viewer, const ScriptCall& call) {
  SoakState& soak = viewer.soak;
  soak.rssEnd = settledResidentBytes();
  soak.objectsEnd = liveGLObjects();
  const double growthMiB = (double(soak.rssEnd) - double(soak.rssBaseline)) / 1048576.0;
  const int programGrowth = soak.objectsEnd.programs - soak.objectsBaseline.programs;
  const int objectGrowth = soak.objectsEnd.total() - soak.objectsBaseline.total() - programGrowth;
  std::printf("soak: settled after %d actions: RSS %.1f MiB (growth %.1f MiB, bound %.1f), GL objects %d (%s; growth "
              "%d besides programs, bound %d; programs %d, bound %d)\n",
              soak.actions, double(soak.rssEnd) / 1048576.0, growthMiB, soak.maxRssGrowthMiB, soak.objectsEnd.total(),
              soak.objectsEnd.describe().c_str(), objectGrowth, soak.maxObjectGrowth, programGrowth,
              soak.maxProgramGrowth);
  soak.active = false;
  if (growthMiB > soak.maxRssGrowthMiB)
    call.fail("resident memory grew by " + std::to_string(growthMiB) + " MiB over the soak (seed " +
                      std::to_string(soak.seed) + "), more than " + std::to_string(soak.maxRssGrowthMiB));
  if (objectGrowth > soak.maxObjectGrowth)
    call.fail("live GL objects other than programs grew by " + std::to_string(objectGrowth) + " over the soak (seed " +
                      std::to_string(soak.seed) + "), more than " + std::to_string(soak.maxObjectGrowth));
  if (programGrowth > soak.maxProgramGrowth)
    call.fail("live GL programs grew by " + std::to_string(programGrowth) + " over the soak (seed " +
                      std::to_string(soak.seed) + "), more than " + std::to_string(soak.maxProgramGrowth));
}

}  // namespace

// soak, and the steps it inserts into the script (no usage: not for scripts to call).
VOXLAB_REGISTER_SCRIPT_VERBS(soak, 160,
  {"soak", 5, 6,
   "soak SECONDS SEED MAX_RSS_GROWTH_MIB MAX_OBJECT_GROWTH MAX_PROGRAM_GROWTH [ACTIONS] (a warm-up tour of every "
   "technique, then random valid actions from SEED for SECONDS, or exactly ACTIONS of them when given (a replay), GL "
   "and frame checks after each; settled at the default state before and after, the resident memory, the live GL "
   "objects other than programs and the programs may grow by at most the bounds)",
   soakStart},
  {"soak-baseline", 0, 0, nullptr, soakBaseline},
  {"soak-step", 0, 0, nullptr, soakStep},
  {"soak-check", 0, 0, nullptr, soakCheck},
  {"soak-finish", 0, 0, nullptr, soakFinish});

}  // namespace voxlab
