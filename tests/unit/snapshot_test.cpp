// Snapshot suite: every declared output of every technique, compared with its golden.
//
// For each technique the run settings come from tests/golden/<technique>/settings.json (scene,
// size, parameter overrides; defaults below when absent; {"runs": [...]} for several scenes, the
// later runs' tests named <technique>_<stage>_<output>_<scene>). Goldens live in
// tests/golden/<technique>/<scene>/:
//   images and volumes: <stage>.<output>[@level].exr (values, as `voxlab run` writes them);
//   buffers:            <stage>.<output>.records (raw records; sorted for the exact tier).
// Tolerances are data (tests/golden/tolerances.json): "exact" outputs must match bit for bit
// (buffers as sorted multisets, since atomics append in no fixed order); "tolerance" outputs may
// differ by max_abs in at most max_fraction of their values. A failure writes the actual file and
// a difference image under <build>/snapshot-failures/ and names them.
// Goldens are (re)written only with VOXLAB_UPDATE_GOLDENS=1 (scripts/update-goldens.sh).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "core/args.h"
#include "capture/output_handler.h"
#include "core/paths.h"
#include "graph/technique.h"
#include "scene/scene.h"
#include "test_support.h"

namespace voxlab::snapshot {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct Settings {
  std::string name;   // "" for the scene runs, else the name of one of "configurations"
  std::string scene;  // "" for the main run and configurations, else the scene's stem (later runs)
  RunRequest request;
  std::string goldenSuffix() const { return name.empty() ? "" : "." + name; }  // of <scene> in golden paths
  std::string testPrefix(const std::string& technique) const { return technique + (name.empty() ? "" : "_" + name); }
  std::string failureName(const std::string& technique) const {
    return testPrefix(technique) + (scene.empty() ? "" : "." + scene);
  }
  ParamSet params() const {
    ParamSet p = createTechnique(request.technique)->defaultParams();
    for (const auto& set : request.sets) {
      size_t eq = set.find('=');
      p.setText(set.substr(0, eq), set.substr(eq + 1));
    }
    return p;
  }
};

// What 'j' (one object of settings.json) overrides: "scene", "size", "set" (replacing the list).
void applyOverrides(Settings& s, const json& j) {
  s.request.scene = j.value("scene", s.request.scene);
  if (j.contains("size")) Args::parseSize(j["size"].get<std::string>(), s.request.width, s.request.height);
  if (j.contains("set")) s.request.sets = j["set"].get<std::vector<std::string>>();
}

// One snapshot run: the defaults (Cornell box, 128x128, voxel.resolution=64 where declared)
// with what 'j' overrides.
Settings settingsFrom(const std::string& technique, const json& j) {
  Settings s;
  s.request.technique = technique;
  s.request.width = s.request.height = 128;
  auto params = createTechnique(technique)->defaultParams();
  if (params.has("voxel.resolution")) s.request.sets.push_back("voxel.resolution=64");
  applyOverrides(s, j);
  return s;
}

// The snapshot runs of a technique: tests/golden/<technique>/settings.json holds one settings
// object, or {"runs": [object, ...]} for several scenes; without the file, one run at the
// defaults. The first run is the technique's main one (its tests carry no scene suffix; later
// runs' tests end in the scene's name). Then each entry of the optional "configurations" list:
// the main run with its own "name" and what it overrides, e.g. vct-grid's anisotropic mips at
// reduced size; its tests are named <technique>_<name>_..., its goldens live in
// tests/golden/<technique>/<scene>.<name>/.
std::vector<Settings> runsFor(const std::string& technique) {
  std::string path = projectPath("tests/golden/" + technique + "/settings.json");
  json j = fileExists(path) ? json::parse(readTextFile(path)) : json::object();
  std::vector<Settings> runs;
  if (j.contains("runs")) {
    for (const json& r : j["runs"]) runs.push_back(settingsFrom(technique, r));
  } else {
    runs.push_back(settingsFrom(technique, j));
  }
  for (size_t i = 1; i < runs.size(); ++i) runs[i].scene = fs::path(resolveScenePath(runs[i].request.scene)).stem().string();
  const Settings main = runs.front();
  for (const json& c : j.value("configurations", json::array())) {
    Settings t = main;
    t.name = c.at("name").get<std::string>();
    applyOverrides(t, c);
    runs.push_back(t);
  }
  return runs;
}

// The entry "<address> on <scene>" (e.g. "vct-grid/inject/radiance-injected on sponza") overrides
// "<address>", which overrides "default".
GoldenTolerance toleranceFor(const std::string& address, const std::string& scene, CaptureTier tier) {
  static json data = json::parse(readTextFile(projectPath("tests/golden/tolerances.json")));
  GoldenTolerance t;
  if (tier == CaptureTier::Exact) {
    // Only colour fields of record lists may be loosened, and only per output and scene.
    for (const std::string& key : {address, address + " on " + scene})
      if (data.contains("outputs") && data["outputs"].contains(key))
      {
        t.recordColourSteps = data["outputs"][key].value("record_colour_steps", t.recordColourSteps);
        t.recordColourFraction = data["outputs"][key].value("record_colour_fraction", t.recordColourFraction);
      }
    return t;
  }
  const json& d = data.at("default");
  t.maxAbs = d.at("max_abs").get<double>();
  t.maxFraction = d.at("max_fraction").get<double>();
  for (const std::string& key : {address, address + " on " + scene}) {
    if (!data.contains("outputs") || !data["outputs"].contains(key)) continue;
    const json& o = data["outputs"][key];
    t.maxAbs = o.value("max_abs", t.maxAbs);
    t.maxFraction = o.value("max_fraction", t.maxFraction);
  }
  return t;
}

bool updating() {
  const char* e = std::getenv("VOXLAB_UPDATE_GOLDENS");
  return e && std::string(e) == "1";
}

std::string failureDir() {
  std::string d = fs::current_path().string() + "/snapshot-failures";
  fs::create_directories(d);
  return d;
}

class SnapshotTest : public ::testing::Test {
 public:
  SnapshotTest(Settings settings, std::string stage, std::string output)
      : settings_(std::move(settings)), technique_(settings_.request.technique), stage_(std::move(stage)),
        output_(std::move(output)) {}

  void TestBody() override {
    HeadlessSession& s = testing_support::session(settings_.request);
    // <technique>[_<configuration>][.<scene> for later runs]: names of failure files
    const std::string failureName = settings_.failureName(technique_);
    CapturedOutput c = testing_support::capture(s, stage_, output_);
    std::string address = technique_ + "/" + stage_ + "/" + output_;
    // The output's visualiser (looked up by kind and semantic) knows its golden files and how to
    // compare them; the tier is the declared one or the visualiser's default.
    GoldenRequest q;
    q.tier = captureTier(c.desc);
    if (q.tier == CaptureTier::None) GTEST_SKIP() << address << " is not compared (tier none)";
    if (isPlaceholderUnder(c.desc, settings_.params())) {
      // Declared a placeholder under these parameters: it must be one empty texel, no golden.
      for (const LevelData& level : c.levels) {
        EXPECT_EQ(level.texelCount(), 1u) << address << " is a placeholder unless " << c.desc.placeholderUnless;
        for (float v : level.values) EXPECT_EQ(v, 0.0f) << address << " is a placeholder but not empty";
      }
      return;
    }
    q.goldenDir = projectPath("tests/golden/" + technique_ + "/" + s.cursor().scene().name + settings_.goldenSuffix());
    q.prefix = stage_ + "." + output_;
    q.failureDir = failureDir();
    q.failurePrefix = failureName + "." + q.prefix;
    q.tolerance = toleranceFor(address, s.cursor().scene().name, q.tier);
    q.update = updating();
    GoldenResult r = outputHandler(c.desc).compareGolden(c, q);
    EXPECT_TRUE(r.ok) << r.message;
  }

 private:
  Settings settings_;
  std::string technique_, stage_, output_;
};

// An iterative stage stepped one iteration at a time (as the viewer's "Step iteration" does) must
// pass through Partial, end Done, leave its readers Stale, and produce exactly what one full run
// of the stage produces from the same inputs. Exact: the same programs on the same data.
class IterationTest : public ::testing::Test {
 public:
  IterationTest(Settings settings, std::string stage) : settings_(std::move(settings)), stage_(std::move(stage)) {}
  void TestBody() override {
    HeadlessSession& s = testing_support::session(settings_.request);
    StepCursor& c = s.cursor();
    const Technique& t = c.technique();
    const int stage = t.stageIndex(stage_);
    const int n = c.iterations(stage);
    ASSERT_GT(n, 1);
    std::vector<CapturedOutput> full;
    for (const auto& o : t.decl(stage).outputs) full.push_back(captureOutput(c.board(), o));

    c.invalidate(stage);
    for (int k = 0; k < n; ++k) {
      EXPECT_EQ(c.runIteration(stage), k);
      EXPECT_EQ(c.record(stage).iterationsRun, k + 1);
      EXPECT_EQ(c.record(stage).state, k + 1 < n ? StageState::Partial : StageState::Done) << "after iteration " << k;
    }
    for (int j = stage + 1; j < t.stageCount(); ++j)
      for (const auto& res : t.decl(j).reads)
        if (res != kViewResource && t.writerOf(res, j) == stage)
          EXPECT_EQ(c.record(j).state, StageState::Stale) << t.stage(j).id() << " reads " << res;
    const auto& outs = t.decl(stage).outputs;
    for (size_t i = 0; i < outs.size(); ++i) {
      CapturedOutput stepped = captureOutput(c.board(), outs[i]);
      ASSERT_EQ(stepped.levels.size(), full[i].levels.size()) << outs[i].name;
      for (size_t l = 0; l < stepped.levels.size(); ++l)
        EXPECT_EQ(stepped.levels[l].values, full[i].levels[l].values) << outs[i].name << " level " << l;
      EXPECT_EQ(stepped.records, full[i].records) << outs[i].name;
    }
    c.runAll();  // leave the shared session as the snapshot tests expect it
  }

 private:
  Settings settings_;
  std::string stage_;
};

}  // namespace

void registerSnapshotTests() {
  for (const auto& entry : techniqueRegistry()) {
    auto t = createTechnique(entry.id);
    for (const Settings& settings : runsFor(entry.id)) {
      const std::string prefix = settings.testPrefix(entry.id);
      for (int i = 0; i < t->stageCount(); ++i)
        for (const auto& o : t->decl(i).outputs) {
          std::string stage = t->stage(i).id(), output = o.name;
          std::string name = prefix + "/" + stage + "/" + output;
          if (!settings.scene.empty()) name += "/" + settings.scene;
          std::replace(name.begin(), name.end(), '-', '_');
          std::replace(name.begin(), name.end(), '/', '_');
          ::testing::RegisterTest("Snapshot", name.c_str(), nullptr, nullptr, __FILE__, __LINE__,
                                  [=]() -> ::testing::Test* { return new SnapshotTest(settings, stage, output); });
        }
      if (!settings.scene.empty()) continue;  // iterations: the main run and the configurations
      ParamSet params = settings.params();
      for (int i = 0; i < t->stageCount(); ++i)
        if (t->stage(i).iterations(params) > 1) {
          std::string stage = t->stage(i).id();
          std::string name = prefix + "_" + stage;
          std::replace(name.begin(), name.end(), '-', '_');
          ::testing::RegisterTest("Iterations", name.c_str(), nullptr, nullptr, __FILE__, __LINE__,
                                  [=]() -> ::testing::Test* { return new IterationTest(settings, stage); });
        }
    }
  }
}

}  // namespace voxlab::snapshot
