// Snapshot suite: every declared output of every technique, compared with its golden.
//
// For each technique the run settings come from tests/golden/<technique>/settings.json (scene,
// size, parameter overrides; defaults below when absent). Goldens live in
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
#include "core/paths.h"
#include "graph/technique.h"
#include "test_support.h"

namespace voxlab::snapshot {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct Settings {
  std::string name;  // "" for the main configuration, else the name of one in "configurations"
  RunRequest request;
  std::string goldenSuffix() const { return name.empty() ? "" : "." + name; }  // of <scene> in golden paths
  std::string testPrefix(const std::string& technique) const { return technique + (name.empty() ? "" : "_" + name); }
  ParamSet params() const {
    ParamSet p = createTechnique(request.technique)->defaultParams();
    for (const auto& set : request.sets) {
      size_t eq = set.find('=');
      p.setText(set.substr(0, eq), set.substr(eq + 1));
    }
    return p;
  }
};

// The main configuration (top-level "scene", "size", "set"), then each entry of the optional
// "configurations" list (its own "name", and "scene", "size", "set" replacing the main ones), e.g.
// vct-grid's anisotropic mips at reduced size. Goldens of a named configuration live in
// tests/golden/<technique>/<scene>.<name>/.
std::vector<Settings> configurationsFor(const std::string& technique) {
  Settings s;
  s.request.technique = technique;
  s.request.width = s.request.height = 128;
  std::string path = projectPath("tests/golden/" + technique + "/settings.json");
  auto params = createTechnique(technique)->defaultParams();
  if (params.has("voxel.resolution")) s.request.sets.push_back("voxel.resolution=64");
  std::vector<Settings> out;
  json j = fileExists(path) ? json::parse(readTextFile(path)) : json::object();
  auto apply = [](Settings& t, const json& o) {
    t.request.scene = o.value("scene", t.request.scene);
    if (o.contains("size")) Args::parseSize(o["size"].get<std::string>(), t.request.width, t.request.height);
    if (o.contains("set")) t.request.sets = o["set"].get<std::vector<std::string>>();
  };
  apply(s, j);
  out.push_back(s);
  for (const json& c : j.value("configurations", json::array())) {
    Settings t = s;
    t.name = c.at("name").get<std::string>();
    apply(t, c);
    out.push_back(t);
  }
  return out;
}

// Whether the output is only a placeholder under these parameters (OutputDesc::placeholderUnless,
// a choice parameter).
bool isPlaceholder(const OutputDesc& desc, const ParamSet& params) {
  if (desc.placeholderUnless.empty()) return false;
  size_t eq = desc.placeholderUnless.find('=');
  return params.getChoice(desc.placeholderUnless.substr(0, eq)) != desc.placeholderUnless.substr(eq + 1);
}

struct Tolerance {
  double maxAbs = 0.0;
  double maxFraction = 0.0;
};

Tolerance toleranceFor(const std::string& address, CaptureTier tier) {
  static json data = json::parse(readTextFile(projectPath("tests/golden/tolerances.json")));
  Tolerance t;
  if (tier == CaptureTier::Exact) return t;
  const json& d = data.at("default");
  t.maxAbs = d.at("max_abs").get<double>();
  t.maxFraction = d.at("max_fraction").get<double>();
  if (data.contains("outputs") && data["outputs"].contains(address)) {
    const json& o = data["outputs"][address];
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

std::vector<uint8_t> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void writeBytes(const std::string& path, const std::vector<uint8_t>& b) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
}

// Records sorted as byte strings: the canonical form of an append-order-free list.
std::vector<uint8_t> sortedRecords(const CapturedOutput& c) {
  size_t stride = c.desc.layout.stride;
  std::vector<std::vector<uint8_t>> recs(c.recordCount);
  for (uint32_t i = 0; i < c.recordCount; ++i)
    recs[i].assign(c.records.begin() + i * stride, c.records.begin() + (i + 1) * stride);
  std::sort(recs.begin(), recs.end());
  std::vector<uint8_t> out;
  for (auto& r : recs) out.insert(out.end(), r.begin(), r.end());
  return out;
}

class SnapshotTest : public ::testing::Test {
 public:
  SnapshotTest(Settings settings, std::string stage, std::string output)
      : settings_(std::move(settings)), technique_(settings_.request.technique), stage_(std::move(stage)),
        output_(std::move(output)) {}

  void TestBody() override {
    HeadlessSession& s = testing_support::session(settings_.request);
    CapturedOutput c = testing_support::capture(s, stage_, output_);
    std::string address = technique_ + "/" + stage_ + "/" + output_;
    std::string dir = projectPath("tests/golden/" + technique_ + "/" + s.cursor().scene().name + settings_.goldenSuffix());
    std::string prefix = stage_ + "." + output_;
    Tolerance tol = toleranceFor(address, c.desc.tier);
    if (c.desc.tier == CaptureTier::None) GTEST_SKIP() << address << " is not compared (tier none)";
    if (isPlaceholder(c.desc, settings_.params())) {
      // Declared a placeholder under these parameters: it must be one empty texel, no golden.
      for (const LevelData& level : c.levels) {
        EXPECT_EQ(level.texelCount(), 1u) << address << " is a placeholder unless " << c.desc.placeholderUnless;
        for (float v : level.values) EXPECT_EQ(v, 0.0f) << address << " is a placeholder but not empty";
      }
      return;
    }
    if (c.desc.kind == OutputKind::Buffer)
      compareBuffer(c, dir, prefix, tol);
    else
      compareLevels(c, dir, prefix, tol);
  }

 private:
  void compareBuffer(const CapturedOutput& c, const std::string& dir, const std::string& prefix, const Tolerance& tol) {
    std::string golden = dir + "/" + prefix + ".records";
    std::vector<uint8_t> actual = c.desc.tier == CaptureTier::Exact ? sortedRecords(c) : c.records;
    if (updating()) {
      fs::create_directories(dir);
      writeBytes(golden, actual);
      return;
    }
    ASSERT_TRUE(fileExists(golden)) << "missing golden " << golden << " (run scripts/update-goldens.sh and review)";
    std::vector<uint8_t> expected = readBytes(golden);
    std::string actualPath = failureDir() + "/" + technique_ + "." + prefix + ".records";
    size_t stride = c.desc.layout.stride;
    if (expected.size() != actual.size()) {
      writeBytes(actualPath, actual);
      FAIL() << technique_ << "/" << prefix << ": " << actual.size() / stride << " records, golden has "
             << expected.size() / stride << " (actual written to " << actualPath << ")";
    }
    if (c.desc.tier == CaptureTier::Exact) {
      if (expected != actual) {
        writeBytes(actualPath, actual);
        size_t differing = 0;
        for (size_t i = 0; i < actual.size(); i += stride)
          if (std::memcmp(&actual[i], &expected[i], stride) != 0) ++differing;
        FAIL() << technique_ << "/" << prefix << ": " << differing << " of " << actual.size() / stride
               << " sorted records differ (actual written to " << actualPath << ")";
      }
      return;
    }
    // Tolerance tier: every 4-byte field read as float.
    size_t n = actual.size() / 4, over = 0;
    double worst = 0;
    for (size_t i = 0; i < n; ++i) {
      float a, e;
      std::memcpy(&a, &actual[i * 4], 4);
      std::memcpy(&e, &expected[i * 4], 4);
      double d = std::abs(double(a) - double(e));
      worst = std::max(worst, d);
      if (d > tol.maxAbs) ++over;
    }
    if (double(over) > tol.maxFraction * double(n)) {
      writeBytes(actualPath, actual);
      FAIL() << technique_ << "/" << prefix << ": " << over << " of " << n << " values differ by more than "
             << tol.maxAbs << " (worst " << worst << "; allowed fraction " << tol.maxFraction << "; actual written to "
             << actualPath << ")";
    }
  }

  void compareLevels(const CapturedOutput& c, const std::string& dir, const std::string& prefix, const Tolerance& tol) {
    for (size_t l = 0; l < c.levels.size(); ++l) {
      std::string name = prefix + (c.levels.size() > 1 ? "@" + std::to_string(l) : "") + ".exr";
      std::string golden = dir + "/" + name;
      const LevelData& a = c.levels[l];
      if (updating()) {
        fs::create_directories(dir);
        writeLevelExr(a, golden, semanticName(c.desc.semantic));
        continue;
      }
      ASSERT_TRUE(fileExists(golden)) << "missing golden " << golden << " (run scripts/update-goldens.sh and review)";
      LevelData e = readLevelExr(golden);
      ASSERT_EQ(a.size, e.size) << name << ": size differs from the golden";
      ASSERT_EQ(a.channels, e.channels) << name << ": channel count differs from the golden";
      size_t over = 0;
      double worst = 0;
      LevelData diff = a;
      for (size_t i = 0; i < a.values.size(); ++i) {
        double d = std::abs(double(a.values[i]) - double(e.values[i]));
        if (std::isnan(d)) d = INFINITY;
        diff.values[i] = float(d);
        worst = std::max(worst, d);
        if (d > tol.maxAbs) ++over;
      }
      if (double(over) > tol.maxFraction * double(a.values.size())) {
        std::string base = failureDir() + "/" + technique_ + "." + name;
        writeLevelExr(a, base + ".actual.exr", semanticName(c.desc.semantic));
        writeLevelExr(diff, base + ".diff.exr", "scalar");
        FAIL() << technique_ << "/" << name << ": " << over << " of " << a.values.size() << " values differ by more than "
               << tol.maxAbs << " (worst " << worst << ", allowed fraction " << tol.maxFraction << "); actual: "
               << base << ".actual.exr, difference: " << base << ".diff.exr, golden: " << golden;
      }
    }
  }

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
    for (const Settings& settings : configurationsFor(entry.id)) {
      const std::string prefix = settings.testPrefix(entry.id);
      for (int i = 0; i < t->stageCount(); ++i)
        for (const auto& o : t->decl(i).outputs) {
          std::string stage = t->stage(i).id(), output = o.name;
          std::string name = prefix + "/" + stage + "/" + output;
          std::replace(name.begin(), name.end(), '-', '_');
          std::replace(name.begin(), name.end(), '/', '_');
          ::testing::RegisterTest("Snapshot", name.c_str(), nullptr, nullptr, __FILE__, __LINE__,
                                  [=]() -> ::testing::Test* { return new SnapshotTest(settings, stage, output); });
        }
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
