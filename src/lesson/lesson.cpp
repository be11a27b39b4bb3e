#include "lesson/lesson.h"

#include <sstream>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/paths.h"
#include "graph/reference_mode.h"
#include "graph/technique.h"
#include "run/reference_error.h"
#include "scene/scene.h"

namespace voxlab {
namespace {

using nlohmann::json;

std::string trim(const std::string& s) {
  size_t a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return "";
  size_t b = s.find_last_not_of(" \t\r\n");
  return s.substr(a, b - a + 1);
}

std::string jsonText(const json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  if (v.is_number_integer()) return std::to_string(v.get<long long>());
  if (v.is_number()) {
    std::ostringstream o;
    o << v.get<double>();
    return o.str();
  }
  throw Error("a parameter value must be a string, number or boolean, got " + v.dump());
}

// Validates one step against the registry; 'where' is "file:line".
void validateStep(LessonStep& step, const std::string& where, bool checkScenes) {
  auto fail = [&](const std::string& what) { throw Error(where + ": " + what); };
  std::unique_ptr<Technique> t;
  try {
    t = createTechnique(step.technique);
  } catch (const Error& e) {
    fail(e.what());
  }
  int index = -1;
  try {
    index = t->stageIndex(step.stage);
  } catch (const Error& e) {
    fail(e.what());
  }
  const auto& outs = t->decl(index).outputs;
  if (step.output.empty()) {
    if (!outs.empty()) step.output = outs.front().name;
  } else {
    try {
      t->findOutput(step.stage, step.output);
    } catch (const Error& e) {
      fail(e.what());
    }
  }
  if (step.level < 0) fail("level must be 0 or more, got " + std::to_string(step.level));
  if (!step.overlay.empty()) {
    try {
      OutputAddress a = OutputAddress::parse(step.technique + "/" + step.overlay);
      auto [stage, desc] = t->findOutput(a.stage, a.output);
      (void)stage;
      if (desc->kind != OutputKind::Volume3D)
        fail("overlay " + step.overlay + " is a " + kindName(desc->kind) + "; overlays show volumes (volume3d outputs)");
    } catch (const Error& e) {
      fail(std::string("overlay: ") + e.what());
    }
  }
  if (step.camera < 0) fail("camera must be 0 or more, got " + std::to_string(step.camera));
  ParamSet params = t->defaultParams();
  for (const auto& [name, value] : step.sets) {
    try {
      params.setText(name, value);
    } catch (const Error& e) {
      fail(e.what());
    }
  }
  if (step.iterations != 0) {
    int n = t->stage(index).iterations(params);
    if (n <= 1) fail("iterations: stage " + step.stage + " is not iterative");
    if (step.iterations < 1 || step.iterations > n)
      fail("iterations must be 1.." + std::to_string(n) + " for " + step.stage + ", got " + std::to_string(step.iterations));
  }
  if (step.frameCount != 0) {
    if (step.frameCount < kLessonMinFrames || step.frameCount > kLessonMaxFrames)
      fail("frames: 'count' must be " + std::to_string(kLessonMinFrames) + ".." + std::to_string(kLessonMaxFrames) +
           ", got " + std::to_string(step.frameCount));
    for (const std::string& text : step.frameAnimate) {
      try {
        step.frameAnimations.push_back(parseAnimation(params, text));
      } catch (const Error& e) {
        fail(std::string("frames: ") + e.what());
      }
    }
  }
  if (!step.sweep.empty()) {
    try {
      validateSweep(lessonSweepRequest(step), "sweep");
    } catch (const Error& e) {
      fail(e.what());
    }
  }
  if (checkScenes) {
    try {
      resolveScenePath(step.scene);
    } catch (const Error& e) {
      fail(e.what());
    }
  }
  if (step.besideReference) {
    auto [outStage, desc] = t->findOutput(step.stage, step.output);
    (void)outStage;
    std::string compared;
    for (const auto& o : outs)
      if (!o.referenceMode.empty()) compared += (compared.empty() ? "" : ", ") + o.name;
    if (desc->kind != OutputKind::Image2D || desc->referenceMode.empty())
      fail("beside: output " + step.output + " declares no reference mode to show beside it; outputs of " + step.stage +
           " that do: " + (compared.empty() ? std::string("none") : compared));
    if (step.camera != 0) fail("beside: the reference images are rendered from camera 0, the step shows camera " +
                               std::to_string(step.camera));
    try {
      step.referenceMode = referenceModeUnder(*desc, params);
    } catch (const Error& e) {
      fail(e.what());
    }
    step.referenceImage = referenceImagePath(step.scene, step.referenceMode);
    if (checkScenes && !fileExists(step.referenceImage))
      fail("beside: scene " + step.scene + " has no reference image for mode " + step.referenceMode + " (" +
           step.referenceImage + "; scripts/make-references.sh renders the suite's)");
  }
}

}  // namespace

Lesson parseLesson(const std::string& text, const std::string& path, bool checkScenes) {
  Lesson lesson;
  lesson.path = path;
  std::istringstream in(text);
  std::string line, narrative, block;
  int lineNo = 0, blockLine = 0;
  bool inStep = false, inOtherFence = false;
  std::string technique, scene, lessonScene = "cornell-box";
  while (std::getline(in, line)) {
    ++lineNo;
    std::string t = trim(line);
    if (inStep) {
      if (t.rfind("```", 0) == 0) {
        inStep = false;
        std::string where = path + ":" + std::to_string(blockLine);
        json j;
        try {
          j = json::parse(block);
        } catch (const json::parse_error& e) {
          // Turn the byte offset into a line of the file.
          size_t byte = std::min<size_t>(e.byte, block.size());
          int extra = 0;
          for (size_t k = 0; k + 1 < byte; ++k) extra += block[k] == '\n';
          throw Error(path + ":" + std::to_string(blockLine + 1 + extra) + ": voxlab-step is not valid JSON: " +
                      std::string(e.what()).substr(std::string(e.what()).find(']') + 2));
        }
        if (!j.is_object()) throw Error(where + ": a voxlab-step block must hold one JSON object");
        LessonStep step;
        step.line = blockLine;
        step.narrative = trim(narrative);
        narrative.clear();
        static const char* known[] = {"technique", "scene", "stage",      "output",  "level",
                                      "camera",    "set",   "iterations", "overlay", "bounds",
                                      "slice",     "axis",  "beside",     "sweep",   "sweep_set",
                                      "frames"};
        for (auto it = j.begin(); it != j.end(); ++it) {
          bool ok = false;
          for (const char* k : known) ok = ok || it.key() == k;
          if (!ok)
            throw Error(where + ": unknown key '" + it.key() +
                        "'; valid keys: technique, scene, stage, output, level, camera, set, iterations, overlay, "
                        "bounds, slice, axis, beside, sweep, sweep_set, frames");
        }
        auto str = [&](const char* key, std::string& out) {
          if (!j.contains(key)) return;
          if (!j[key].is_string()) throw Error(where + ": '" + key + "' must be a string");
          out = j[key].get<std::string>();
        };
        auto num = [&](const char* key, int& out) {
          if (!j.contains(key)) return;
          if (!j[key].is_number_integer()) throw Error(where + ": '" + key + "' must be an integer");
          out = j[key].get<int>();
        };
        str("technique", technique);
        // The scene is part of a step's absolute state: a step without "scene" shows the lesson's
        // scene (the first step's), never whatever an earlier step switched to.
        scene = lessonScene;
        str("scene", scene);
        if (lesson.steps.empty()) lessonScene = scene;
        if (technique.empty()) throw Error(where + ": the first voxlab-step needs a \"technique\"");
        if (!j.contains("stage")) throw Error(where + ": a voxlab-step needs a \"stage\"");
        step.technique = technique;
        step.scene = scene;
        str("stage", step.stage);
        str("output", step.output);
        num("level", step.level);
        num("camera", step.camera);
        num("iterations", step.iterations);
        num("slice", step.sliceIndex);
        if (j.contains("slice") && step.sliceIndex < 0) throw Error(where + ": 'slice' must be 0 or more");
        if (j.contains("axis")) {
          std::string axis;
          str("axis", axis);
          if (axis != "x" && axis != "y" && axis != "z") throw Error(where + ": 'axis' must be \"x\", \"y\" or \"z\"");
          step.sliceAxis = axis[0] - 'x';
        }
        str("overlay", step.overlay);
        if (j.contains("bounds")) {
          if (!j["bounds"].is_boolean()) throw Error(where + ": 'bounds' must be true or false");
          step.bounds = j["bounds"].get<bool>();
        }
        if (j.contains("beside")) {
          std::string beside;
          str("beside", beside);
          if (beside != "reference") throw Error(where + ": 'beside' must be \"reference\", got \"" + beside + "\"");
          step.besideReference = true;
        }
        auto assignments = [&](const char* key, std::vector<std::pair<std::string, std::string>>& out) {
          if (!j.contains(key)) return;
          if (!j[key].is_object()) throw Error(where + ": '" + key + "' must be an object of name: value");
          for (auto it = j[key].begin(); it != j[key].end(); ++it) {
            try {
              out.emplace_back(it.key(), jsonText(it.value()));
            } catch (const Error& e) {
              throw Error(where + ": " + it.key() + ": " + e.what());
            }
          }
        };
        assignments("set", step.sets);
        str("sweep", step.sweep);
        if (j.contains("sweep") && step.sweep.empty())
          throw Error(where + ": 'sweep' must be \"NAME=V1,V2,...\" or \"NAME=FROM:TO:STEPS\"");
        assignments("sweep_set", step.sweepSets);
        if (!step.sweepSets.empty() && step.sweep.empty())
          throw Error(where + ": 'sweep_set' needs a 'sweep' in the same step");
        if (j.contains("frames")) {
          const json& f = j["frames"];
          const std::string form = "'frames' must be {\"count\": N, \"animate\": [\"NAME=FROM:TO\", ...]}";
          if (!f.is_object()) throw Error(where + ": " + form);
          for (auto it = f.begin(); it != f.end(); ++it)
            if (it.key() != "count" && it.key() != "animate")
              throw Error(where + ": frames: unknown key '" + it.key() + "'; valid keys: count, animate");
          if (!f.contains("count") || !f["count"].is_number_integer())
            throw Error(where + ": frames: 'count' must be an integer; " + form);
          step.frameCount = f["count"].get<int>();
          if (step.frameCount == 0) step.frameCount = -1;  // validateStep names the valid range
          if (!f.contains("animate") || !f["animate"].is_array() || f["animate"].empty())
            throw Error(where + ": frames: 'animate' must be a non-empty list of \"NAME=FROM:TO\"; " + form);
          for (const json& a : f["animate"]) {
            if (!a.is_string()) throw Error(where + ": frames: every 'animate' entry must be a string \"NAME=FROM:TO\"");
            step.frameAnimate.push_back(a.get<std::string>());
          }
        }
        validateStep(step, where, checkScenes);
        lesson.steps.push_back(std::move(step));
      } else {
        block += line + "\n";
      }
      continue;
    }
    if (!inOtherFence && t.rfind("```voxlab-step", 0) == 0) {
      inStep = true;
      blockLine = lineNo;
      block.clear();
      continue;
    }
    if (t.rfind("```", 0) == 0) inOtherFence = !inOtherFence;
    if (!inOtherFence && lesson.title.empty() && t.rfind("# ", 0) == 0) lesson.title = trim(t.substr(2));
    narrative += line + "\n";
  }
  if (inStep) throw Error(path + ":" + std::to_string(blockLine) + ": voxlab-step block is never closed");
  if (lesson.steps.empty()) throw Error(path + ": the lesson has no ```voxlab-step blocks");
  lesson.epilogue = trim(narrative);
  if (lesson.title.empty()) lesson.title = path;
  return lesson;
}

SweepRequest lessonSweepRequest(const LessonStep& step) {
  SweepRequest request;
  request.technique = step.technique;
  request.scene = step.scene;
  request.width = request.height = kLessonSweepSize;
  request.params = {step.sweep};
  const std::string swept = step.sweep.substr(0, step.sweep.find('='));
  for (const auto& [name, value] : step.sets)
    if (name != swept && name.rfind(swept + ".", 0) != 0) request.sets.push_back(name + "=" + value);
  for (const auto& [name, value] : step.sweepSets) request.sets.push_back(name + "=" + value);
  return request;
}

Lesson loadLesson(const std::string& path, bool checkScenes) {
  if (!fileExists(path)) throw Error("lesson file '" + path + "' does not exist");
  return parseLesson(readTextFile(path), path, checkScenes);
}

}  // namespace voxlab
