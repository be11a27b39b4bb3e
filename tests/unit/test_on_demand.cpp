// Outputs on demand (StepCursor::demandOutputs): a run that asks only for the final image computes
// only what the final image depends on, found from the stages' declared reads; asking for
// everything afterwards computes the rest, and the final image is the same either way. Run for
// every registered technique, so a new technique or output is checked without being named here.
#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "graph/technique.h"
#include "inspect/inspect_logic.h"
#include "test_support.h"

namespace voxlab {
namespace {

// The resources the given outputs depend on, from the declarations alone (written here apart from
// StepCursor::plan, so that the two are checked against each other): the outputs' resources, then,
// from the last stage back, everything a stage reads when it writes one of them.
std::set<std::string> dependenciesOf(const Technique& t, const ParamSet& params,
                                     const std::vector<std::pair<std::string, std::string>>& outputs) {
  std::set<std::string> needed;
  for (const auto& [stage, output] : outputs) needed.insert(t.findOutput(stage, output).second->resourceName());
  for (int i = t.stageCount() - 1; i >= 0; --i) {
    const StageDecl& d = t.decl(i);
    bool writesNeeded = false;
    for (const auto& o : d.outputs) writesNeeded |= needed.count(o.resourceName()) != 0;
    for (const auto& w : d.writes) writesNeeded |= needed.count(w) != 0;
    if (!writesNeeded) continue;
    for (const auto& r : d.reads) {
      auto condition = d.readConditions.find(r);
      if (r != kViewResource && (condition == d.readConditions.end() || conditionHolds(condition->second, params, r)))
        needed.insert(r);
    }
  }
  return needed;
}

std::set<std::string> finalDependencies(const Technique& t, const ParamSet& params) {
  return dependenciesOf(t, params, {{t.finalStage(), t.finalOutput()}});
}

bool writesAny(const StageDecl& d, const std::set<std::string>& resources) {
  for (const auto& o : d.outputs)
    if (resources.count(o.resourceName())) return true;
  for (const auto& w : d.writes)
    if (resources.count(w)) return true;
  return false;
}

bool onBoard(Blackboard& board, const std::string& resource) {
  return board.hasTexture(resource) || board.hasBuffer(resource);
}

// A fresh run of technique on the Cornell box at 64x64, nothing computed yet.
HeadlessSession& smallCornellSession(const std::string& technique) {
  RunRequest request;
  request.technique = technique;
  request.scene = "cornell-box";
  request.width = request.height = 64;
  return testing_support::freshSession(request);
}

class OnDemand : public ::testing::TestWithParam<std::string> {};

TEST_P(OnDemand, FinalOnlyComputesOnlyWhatTheFinalImageUses) {
  HeadlessSession& s = smallCornellSession(GetParam());
  StepCursor& cursor = s.cursor();
  const Technique& t = cursor.technique();
  const std::set<std::string> needed = finalDependencies(t, cursor.params());

  s.demand(/*finalOnly=*/true);
  s.run();
  int skippedStages = 0, alongside = 0;
  for (int i = 0; i < t.stageCount(); ++i) {
    if (cursor.record(i).state == StageState::NotRun) ++skippedStages;
    for (const auto& o : t.decl(i).outputs) {
      const std::string address = t.id() + "/" + t.stage(i).id() + "/" + o.name;
      if (needed.count(o.resourceName())) {
        EXPECT_TRUE(cursor.outputComputed(i, o.name)) << address << " is needed by the final image but was not computed";
        continue;
      }
      // A placeholder (one empty texel under these parameters) is not a computed output, and an
      // output written alongside by a pass the final image needs is declared so (OutputDesc::alongside).
      if (isPlaceholderUnder(o, cursor.params()) || o.alongside) {
        ++alongside;
        continue;
      }
      EXPECT_FALSE(onBoard(cursor.board(), o.resourceName()))
          << address << " was computed (resource '" << o.resourceName()
          << "' allocated) by a --final-only run, but the final image does not depend on it";
      EXPECT_FALSE(cursor.outputComputed(i, o.name)) << address;
    }
  }
  const CapturedOutput finalOnly = testing_support::capture(s, t.finalStage(), t.finalOutput());

  // Everything asked for afterwards (the viewer opening every view): every output is there.
  cursor.demandEverything();
  s.run();
  for (int i = 0; i < t.stageCount(); ++i) {
    EXPECT_EQ(cursor.record(i).state, StageState::Done) << t.id() << "/" << t.stage(i).id();
    for (const auto& o : t.decl(i).outputs) {
      EXPECT_TRUE(cursor.outputComputed(i, o.name)) << t.id() << "/" << t.stage(i).id() << "/" << o.name;
      EXPECT_TRUE(onBoard(cursor.board(), o.resourceName())) << t.id() << "/" << t.stage(i).id() << "/" << o.name;
    }
  }
  const CapturedOutput everything = testing_support::capture(s, t.finalStage(), t.finalOutput());
  ASSERT_EQ(finalOnly.levels.size(), everything.levels.size());
  const auto& a = finalOnly.levels[0].values;
  const auto& b = everything.levels[0].values;
  ASSERT_EQ(a.size(), b.size());
  double maxDiff = 0;
  for (size_t k = 0; k < a.size(); ++k) maxDiff = std::max(maxDiff, double(std::abs(a[k] - b[k])));
  // The same stages on the same data: measured 0 for every technique (the runs are deterministic),
  // so any difference means the final image used something the final-only run left out.
  EXPECT_EQ(maxDiff, 0.0) << t.id() << ": the final image differs between a --final-only run and a whole run";
  RecordProperty("stages_skipped_final_only", skippedStages);
  RecordProperty("outputs_alongside_or_placeholder", alongside);
}

// The viewer's demand (inspect_logic.h viewerDemand): the final image, what is shown and the probe
// records. Shown here: the technique's first output declared onDemand that the final image does
// not use, and the first output of a stage the final image does not need (where it has them), as
// a user opening those two views. The run computes exactly what the demand depends on: every stage
// that writes something it needs runs, every other stage stays not run, and no output outside it
// is computed or allocated (save the other outputs of a stage that runs, unless declared onDemand,
// and placeholders).
class ViewerDemand : public ::testing::TestWithParam<std::string> {};

TEST_P(ViewerDemand, ComputesTheFinalImageAndTheShownOutputsOnly) {
  HeadlessSession& s = smallCornellSession(GetParam());
  StepCursor& cursor = s.cursor();
  const Technique& t = cursor.technique();
  const std::set<std::string> forFinal = finalDependencies(t, cursor.params());

  std::vector<std::pair<std::string, std::string>> shown;
  for (int i = 0; i < t.stageCount() && shown.empty(); ++i)
    for (const auto& o : t.decl(i).outputs)
      if (o.onDemand && !forFinal.count(o.resourceName())) {
        shown.push_back({t.stage(i).id(), o.name});
        break;
      }
  for (int i = 0; i < t.stageCount(); ++i)
    if (!t.decl(i).outputs.empty() && !writesAny(t.decl(i), forFinal)) {
      shown.push_back({t.stage(i).id(), t.decl(i).outputs[0].name});
      break;
    }
  const auto demand = viewerDemand(t, shown);
  const std::set<std::string> needed = dependenciesOf(t, cursor.params(), demand);
  for (const auto& r : forFinal) EXPECT_TRUE(needed.count(r)) << t.id() << ": the viewer's demand leaves out " << r;
  for (const auto& [stage, output] : shown)
    EXPECT_TRUE(std::find(demand.begin(), demand.end(), std::make_pair(stage, output)) != demand.end()) << stage << "/" << output;

  cursor.demandOutputs(demand);
  s.run();
  for (int i = 0; i < t.stageCount(); ++i) {
    const std::string stage = t.id() + "/" + t.stage(i).id();
    const bool ran = cursor.record(i).state != StageState::NotRun;
    EXPECT_EQ(ran, writesAny(t.decl(i), needed)) << stage << (ran ? " ran, but nothing demanded needs it"
                                                                   : " did not run, but a demanded output needs it");
    for (const auto& o : t.decl(i).outputs) {
      const std::string address = stage + "/" + o.name;
      if (needed.count(o.resourceName())) {
        EXPECT_TRUE(cursor.outputComputed(i, o.name)) << address << " is demanded or needed but was not computed";
        continue;
      }
      // A stage that runs writes its outputs, save those it computes on demand; placeholders are
      // not computed outputs.
      if (isPlaceholderUnder(o, cursor.params()) || o.alongside || (ran && !o.onDemand)) continue;
      EXPECT_FALSE(onBoard(cursor.board(), o.resourceName())) << address << " was allocated; nothing demanded needs it";
      EXPECT_FALSE(cursor.outputComputed(i, o.name)) << address;
    }
  }
  for (const auto& [stage, output] : shown)  // a shown output is on the board, to be captured
    EXPECT_TRUE(onBoard(cursor.board(), t.findOutput(stage, output).second->resourceName())) << stage << "/" << output;
  RecordProperty("shown", int(shown.size()));
}

std::vector<std::string> everyTechnique() { return techniqueIds(); }

auto techniqueTestName = [](const ::testing::TestParamInfo<std::string>& info) {
  std::string name = info.param;
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
};

INSTANTIATE_TEST_SUITE_P(EveryTechnique, OnDemand, ::testing::ValuesIn(everyTechnique()), techniqueTestName);
INSTANTIATE_TEST_SUITE_P(EveryTechnique, ViewerDemand, ::testing::ValuesIn(everyTechnique()), techniqueTestName);

// An output that does not exist is named in one line, before anything runs.
TEST(OnDemandCursor, UnknownOutputIsRefusedInOneLine) {
  RunRequest request;
  request.technique = "vct-grid";
  request.width = request.height = 32;
  HeadlessSession& s = testing_support::freshSession(request);
  try {
    s.cursor().demandOutputs({{"composite", "no-such-output"}});
    FAIL() << "an unknown output was accepted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no-such-output"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

// A demand that grows re-runs only the stage that left the newly wanted output out (and keeps
// what it already has): after a --final-only run of vct-grid, asking for the soft-shadow image
// re-runs the cone trace alone; the voxels, mips and G-buffer are not computed again.
TEST(OnDemandCursor, GrowingDemandRerunsOnlyTheStageThatLeftItOut) {
  RunRequest request;
  request.technique = "vct-grid";
  request.width = request.height = 32;
  request.sets = {"voxel.resolution=32"};
  HeadlessSession& s = testing_support::freshSession(request);
  StepCursor& cursor = s.cursor();
  const Technique& t = cursor.technique();
  s.demand(/*finalOnly=*/true);
  s.run();
  const int coneTrace = t.stageIndex("cone-trace");
  ASSERT_FALSE(cursor.outputComputed(coneTrace, "soft-shadow"));
  EXPECT_FALSE(cursor.board().hasTexture("soft-shadow"));
  std::vector<double> before;
  for (int i = 0; i < t.stageCount(); ++i) before.push_back(cursor.record(i).cpuMs);

  cursor.demandOutputs({{"cone-trace", "soft-shadow"}});
  s.run();
  EXPECT_TRUE(cursor.outputComputed(coneTrace, "soft-shadow"));
  EXPECT_TRUE(cursor.board().hasTexture("soft-shadow"));
  for (int i = 0; i < coneTrace; ++i)  // a stage that did not run again keeps its record's time
    EXPECT_EQ(cursor.record(i).cpuMs, before[size_t(i)]) << t.stage(i).id() << " ran again";
  EXPECT_NE(cursor.record(coneTrace).cpuMs, before[size_t(coneTrace)]) << "the cone trace did not run again";
  const CapturedOutput shadow = testing_support::capture(s, "cone-trace", "soft-shadow");
  double lit = 0;
  for (float v : shadow.levels[0].values) lit += v;
  EXPECT_GT(lit, 0.0) << "the soft-shadow image is empty";
}

// A composite term of weight 0 adds nothing, so it is no dependency of the final image: at the
// defaults (composite.specular = 0, Lambertian materials) a --final-only run of vct-grid does not
// trace the specular cone; with the weight above 0 it does, and the term brightens the image.
TEST(OnDemandCursor, ACompositeTermOfWeightZeroIsNotComputed) {
  auto finalOnly = [](const std::string& weight, bool& traced) {
    RunRequest request;
    request.technique = "vct-grid";
    request.width = request.height = 32;
    request.sets = {"voxel.resolution=32", "composite.specular=" + weight};
    HeadlessSession& s = testing_support::freshSession(request);
    s.demand(/*finalOnly=*/true);
    s.run();
    traced = s.cursor().outputComputed(s.cursor().technique().stageIndex("cone-trace"), "indirect-specular");
    EXPECT_EQ(traced, s.cursor().board().hasTexture("indirect-specular")) << weight;
    const CapturedOutput combined = testing_support::capture(s, "composite", "combined");
    double sum = 0;
    for (float v : combined.levels[0].values) sum += v;
    return sum;
  };
  bool tracedAtZero = true, tracedAbove = false;
  const double zero = finalOnly("0", tracedAtZero);
  const double above = finalOnly("0.5", tracedAbove);
  EXPECT_FALSE(tracedAtZero);
  EXPECT_TRUE(tracedAbove);
  EXPECT_GT(above, zero) << "the specular term added nothing";

  ParamSet params;
  params.declare(ParamDesc::real("w", 0.0, 0.0, 1.0, "a weight"));
  EXPECT_FALSE(conditionHolds("w>0", params, "test"));  // strict: the bound itself does not hold
  EXPECT_TRUE(conditionHolds("w>=0", params, "test"));
  params.set("w", 0.25);
  EXPECT_TRUE(conditionHolds("w>0", params, "test"));
  EXPECT_FALSE(conditionHolds("w>0.25", params, "test"));
  EXPECT_THROW(conditionHolds("w>", params, "test"), Error);
}

// vct-grid's averaged grid (radiance-injected) is read after the inject stage only by the occlusion
// fix under compare-and-swap averaging: there a --final-only run computes it; with exact sums (the
// default) the fix takes each voxel's mean from its slot, and the run neither allocates nor writes
// the grid. The final image is the same as a whole run's in both modes.
TEST(OnDemandCursor, TheInjectedGridIsComputedOnlyWhereTheOcclusionFixReadsIt) {
  for (const std::string average : {"exact-sum", "compare-and-swap"}) {
    RunRequest request;
    request.technique = "vct-grid";
    request.width = request.height = 32;
    request.sets = {"voxel.resolution=32", "voxel.format=rgba8", "inject.average=" + average};
    HeadlessSession& s = testing_support::freshSession(request);
    StepCursor& cursor = s.cursor();
    s.demand(/*finalOnly=*/true);
    s.run();
    const bool wanted = average == "compare-and-swap";
    EXPECT_EQ(cursor.outputComputed(cursor.technique().stageIndex("inject"), "radiance-injected"), wanted) << average;
    EXPECT_EQ(cursor.board().hasTexture("radiance-injected"), wanted) << average;
    const CapturedOutput finalOnly = testing_support::capture(s, "composite", "final");
    cursor.demandEverything();
    s.run();
    EXPECT_TRUE(cursor.board().hasTexture("radiance-injected")) << average;
    const CapturedOutput everything = testing_support::capture(s, "composite", "final");
    // The same stages on the same data: measured identical in both modes.
    EXPECT_EQ(finalOnly.levels[0].values, everything.levels[0].values) << average;
  }
}

}  // namespace
}  // namespace voxlab
