// The resource budget (graph/resource_budget.h): every technique's declared resources match what
// it allocates, and a run that does not fit is refused with one line before any allocation.
// Techniques come from the registry; no technique is named here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "core/error.h"
#include "graph/resource_budget.h"
#include "test_support.h"

namespace voxlab {
namespace {

using testing_support::session;

RunRequest smallRun(const std::string& technique, std::vector<std::string> sets) {
  RunRequest r;
  r.technique = technique;
  r.scene = "cornell-box";
  r.width = r.height = 32;  // the screen images do not matter here; volumes do
  r.sets = std::move(sets);
  return r;
}

bool declaresResolution(const Technique& t) { return t.defaultParams().has("voxel.resolution"); }

// The estimate of technique t at voxel.resolution=r (other parameters at their defaults). Some
// techniques take voxel.resolution only for the shared fragment list and size their own grids by
// other parameters (lpv's lpv.resolution; near-field's binary voxels are res x res 2D textures),
// so which of the checks below apply is read from the estimates, never from technique ids.
ResourceEstimate estimateAt(const Technique& t, int r) {
  ParamSet p = t.defaultParams();
  p.set("voxel.resolution", r);
  return estimateResources(t, p, ViewState{});
}

bool has3DTextureOver(const ResourceEstimate& e, int size) {
  for (const auto& item : e.items)
    if (item.is3D && std::max({item.size.x, item.size.y, item.size.z}) > size) return true;
  return false;
}

// Runs at small settings: every declared texture has exactly the bytes the stage allocated, a
// pool at least its declared start, and every 3D texture on the blackboard is declared.
TEST(ResourceBudget, DeclarationsMatchAllocations) {
  for (const auto& entry : techniqueRegistry()) {
    SCOPED_TRACE(entry.id);
    std::vector<std::string> sets;
    if (declaresResolution(*createTechnique(entry.id))) sets.push_back("voxel.resolution=32");
    HeadlessSession& s = session(smallRun(entry.id, sets));
    const ResourceEstimate e = s.cursor().resourceEstimate();
    std::map<std::string, const ResourceEstimateItem*> declared;
    for (const auto& item : e.items) {
      EXPECT_TRUE(declared.emplace(item.resource, &item).second) << item.resource << " declared twice";
      const Blackboard& board = s.cursor().board();
      if (item.isTexture) {
        ASSERT_TRUE(board.hasTexture(item.resource)) << item.stage << " declares texture " << item.resource
                                                     << " but did not allocate it";
        const size_t actual = board.textures().at(item.resource)->byteSize();
        if (item.pool) EXPECT_GE(actual, item.bytes) << item.resource;
        else EXPECT_EQ(actual, item.bytes) << item.resource;
      } else {
        ASSERT_TRUE(board.hasBuffer(item.resource)) << item.stage << " declares buffer " << item.resource
                                                    << " but did not allocate it";
        const size_t actual = board.buffers().at(item.resource)->size();
        if (item.pool) EXPECT_GE(actual, item.bytes) << item.resource;
        else EXPECT_EQ(actual, item.bytes) << item.resource;
      }
    }
    for (const auto& [name, texture] : s.cursor().board().textures())
      if (texture->is3D()) EXPECT_TRUE(declared.count(name)) << "3D texture " << name << " is not declared";
  }
}

// The largest-value search and the message, without GL: for the first resolution r whose run
// needs at least the budget's minimum (64 MiB), a budget of exactly that (rounded up to MiB)
// must name r as the largest voxel.resolution that fits at 512, and r must fit.
TEST(ResourceBudget, RefusalNamesParameterAndLargestFit) {
  int checked = 0, techniques = 0;
  for (const auto& entry : techniqueRegistry()) {
    auto t = createTechnique(entry.id);
    if (!declaresResolution(*t)) continue;
    // Only techniques whose memory at 512 passes the 64 MiB minimum budget have a largest fit.
    if (estimateAt(*t, 512).totalBytes <= (size_t(64) << 20)) continue;
    ++techniques;
    SCOPED_TRACE(entry.id);
    ParamSet p = t->defaultParams();
    const ViewState view;
    const ResourceLimits limits;
    for (int r = 16; r < 512; r *= 2) {
      p.set("voxel.resolution", r);
      const size_t atR = estimateResources(*t, p, view).totalBytes;
      // The budget parameter's minimum is 64 MiB: a technique still under it at r is checked with 64.
      const size_t budgetMiB = std::max<size_t>(64, (atR + (size_t(1) << 20) - 1) >> 20);
      p.set("voxel.resolution", 2 * r);
      const size_t atNext = estimateResources(*t, p, view).totalBytes;
      if ((budgetMiB << 20) >= atNext) continue;
      p.set("gpu.memory-budget", double(budgetMiB));
      p.set("voxel.resolution", 512);
      const std::string line = checkResourceBudget(*t, p, view, limits);
      EXPECT_NE(line.find("over gpu.memory-budget=" + std::to_string(budgetMiB) + " MiB"), std::string::npos) << line;
      EXPECT_NE(line.find("voxel.resolution=512 is too large, the largest voxel.resolution that fits is " +
                          std::to_string(r)), std::string::npos) << line;
      EXPECT_EQ(line.find('\n'), std::string::npos);
      p.set("voxel.resolution", r);
      EXPECT_EQ(checkResourceBudget(*t, p, view, limits), "");
      ++checked;
      break;
    }
  }
  EXPECT_EQ(checked, techniques) << "every technique that needs over 64 MiB at 512 has a largest fit below it";
  EXPECT_GE(techniques, 3) << "vct-grid, voxelization, svo and lrsm need over 64 MiB at 512";
}

// A 3D texture over GL_MAX_3D_TEXTURE_SIZE is named with the limit (for every technique whose 3D
// textures follow voxel.resolution past 256).
TEST(ResourceBudget, TextureLimitIsNamed) {
  int checked = 0;
  for (const auto& entry : techniqueRegistry()) {
    auto t = createTechnique(entry.id);
    if (!declaresResolution(*t) || !has3DTextureOver(estimateAt(*t, 512), 256)) continue;
    ++checked;
    SCOPED_TRACE(entry.id);
    ParamSet p = t->defaultParams();
    p.set("voxel.resolution", 512);
    ResourceLimits limits;
    limits.max3DTextureSize = 256;
    const std::string line = checkResourceBudget(*t, p, ViewState{}, limits);
    EXPECT_NE(line.find("exceeds GL_MAX_3D_TEXTURE_SIZE 256"), std::string::npos) << line;
    EXPECT_NE(line.find("the largest voxel.resolution that fits is 256"), std::string::npos) << line;
  }
  EXPECT_GE(checked, 3);
}

// What a run must do, decided by the test from the estimate's items and the context's limits
// (not by calling checkResourceBudget): three states, so that a test expecting a run cannot pass
// by being refused, nor one expecting a refusal by running or by being refused for another reason.
enum class Expect { Runs, RefusedOverBudget, RefusedOverGLLimit };

const char* expectName(Expect e) {
  return e == Expect::Runs ? "runs" : e == Expect::RefusedOverBudget ? "refused over the memory budget"
                                                                     : "refused over a GL limit";
}

Expect expectedOutcome(const ResourceEstimate& e, size_t budgetBytes, const ResourceLimits& limits) {
  for (const auto& item : e.items) {
    const int biggest = std::max({item.size.x, item.size.y, item.is3D ? item.size.z : 0});
    if (item.isTexture && biggest > (item.is3D ? limits.max3DTextureSize : limits.max2DTextureSize))
      return Expect::RefusedOverGLLimit;
    if (!item.isTexture && item.bytes > limits.maxBufferBytes) return Expect::RefusedOverGLLimit;
  }
  return e.totalBytes > budgetBytes ? Expect::RefusedOverBudget : Expect::Runs;
}

// The limits of the tests' GL context (a session makes it current first).
const ResourceLimits& contextLimits() {
  static const ResourceLimits limits = [] {
    for (const auto& entry : techniqueRegistry()) {
      session(smallRun(entry.id, declaresResolution(*createTechnique(entry.id))
                                     ? std::vector<std::string>{"voxel.resolution=32"}
                                     : std::vector<std::string>{}));
      break;
    }
    return ResourceLimits::query();
  }();
  return limits;
}

// The 512^3 check: voxel.resolution=512 with every technique either runs (within the budget,
// and then it must) or is refused with the one-line message before any GL allocation (nothing on
// the blackboard), for the reason the estimate gives.
void runOrRefuse(const std::string& technique, std::vector<std::string> sets, Expect expected,
                 const std::string& sizeParam = "voxel.resolution") {
  SCOPED_TRACE(std::string(technique) + ": expected " + expectName(expected));
  RunRequest r = smallRun(technique, sets);
  try {
    HeadlessSession& s = session(r);  // runs it
    EXPECT_EQ(expected, Expect::Runs) << "ran although the budget should refuse it";
    EXPECT_EQ(s.cursor().resourceBudgetExcess(), "");
    const size_t budget = size_t(s.cursor().params().getInt("gpu.memory-budget")) << 20;
    EXPECT_LE(s.cursor().board().totalBytes(), budget);
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(expected, Expect::Runs) << "refused although it fits: " << what;
    if (expected == Expect::RefusedOverBudget)
      EXPECT_NE(what.find("of GPU memory, over gpu.memory-budget="), std::string::npos) << what;
    if (expected == Expect::RefusedOverGLLimit) EXPECT_NE(what.find(" exceeds GL_MAX_"), std::string::npos) << what;
    EXPECT_NE(what.find(sets.front() + " is too large, the largest " + sizeParam + " that fits is"),
              std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    HeadlessSession& s = session(r);  // the refused session, kept by the cache
    EXPECT_TRUE(s.cursor().board().textures().empty());
    EXPECT_TRUE(s.cursor().board().buffers().empty());
  }
}

// Pools are sized from the scene's counts as the stages run, so the estimate holds them at their
// starting size. With the budget set to the smallest that the estimate passes, a technique whose
// pools grow past it must stop with one line naming the resource (the blackboard's check), having
// allocated nothing over the budget; one whose pools stay inside it runs. Measured (2026-12-02,
// Cornell box, defaults): svo's node and brick pools grow past it; at least one technique must be
// refused so that the check is exercised.
TEST(ResourceBudget, PoolsGrowingPastTheBudgetStopWithOneLine) {
  contextLimits();  // a current GL context for the estimates' limits
  int refused = 0;
  for (const auto& entry : techniqueRegistry()) {
    auto t = createTechnique(entry.id);
    // At 256^3 where the technique takes voxel.resolution: the pools (fragment lists, octree nodes
    // and bricks) are then large enough against the budget's 64 MiB minimum to show.
    ParamSet p = t->defaultParams();
    std::vector<std::string> sets;
    if (declaresResolution(*t)) {
      p.set("voxel.resolution", 256);
      sets.push_back("voxel.resolution=256");
    }
    const ResourceEstimate e = estimateResources(*t, p, ViewState{});
    if (std::none_of(e.items.begin(), e.items.end(), [](const ResourceEstimateItem& i) { return i.pool; })) continue;
    // The smallest budget the estimate passes (the parameter's minimum is 64 MiB).
    const size_t budgetMiB = std::max<size_t>((e.totalBytes >> 20) + 1, size_t(memoryBudgetParam().minValue));
    const std::string budgetSet = "gpu.memory-budget=" + std::to_string(budgetMiB);
    SCOPED_TRACE(entry.id + " with " + budgetSet);
    // The run's view is 32x32, smaller than the estimate's default view: the estimate passes.
    sets.push_back(budgetSet);
    const RunRequest r = smallRun(entry.id, sets);
    try {
      HeadlessSession& s = session(r);
      std::printf("%s ran: estimate %s, allocated %s\n", entry.id.c_str(), formatBytes(e.totalBytes).c_str(),
                  formatBytes(s.cursor().board().totalBytes()).c_str());
      EXPECT_LE(s.cursor().board().totalBytes(), budgetMiB << 20);
    } catch (const Error& err) {
      const std::string what = err.what();
      ++refused;
      std::printf("%s stopped at gpu.memory-budget=%zu (estimate %s): %s\n", entry.id.c_str(), budgetMiB,
                  formatBytes(e.totalBytes).c_str(), what.c_str());
      EXPECT_NE(what.find("over gpu.memory-budget=" + std::to_string(budgetMiB) + " MiB (sized from the scene's counts"),
                std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      HeadlessSession& s = session(r);  // the stopped session, kept by the cache
      EXPECT_LE(s.cursor().board().totalBytes(), budgetMiB << 20);
    }
  }
  EXPECT_GE(refused, 1);
}

// At the default budget (4 GiB) what fits runs; at least one technique must actually run at 512
// (lpv's grids follow lpv.resolution) so that the run path is exercised.
TEST(ResourceBudget, Resolution512RunsOrIsRefused) {
  int runs = 0;
  for (const auto& entry : techniqueRegistry()) {
    auto t = createTechnique(entry.id);
    if (!declaresResolution(*t)) continue;
    const size_t budget = size_t(t->defaultParams().getInt("gpu.memory-budget")) << 20;
    const Expect expected = expectedOutcome(estimateAt(*t, 512), budget, contextLimits());
    runs += expected == Expect::Runs;
    runOrRefuse(entry.id, {"voxel.resolution=512"}, expected);
  }
  EXPECT_GE(runs, 1);
}

// The grid-size parameters of a technique that has no voxel.resolution (its grids follow its own
// parameters, e.g. a clipmap's cells per level or a medium's density grid): its integer
// parameters named "*.resolution" whose 3D textures take more bytes at their maximum than at their
// minimum. Read from the declarations and estimates, never from technique ids.
std::vector<ParamDesc> ownGridSizeParams(const Technique& t) {
  std::vector<ParamDesc> out;
  const ParamSet defaults = t.defaultParams();
  for (const auto& [name, desc] : defaults.descs()) {
    if (desc.type != ParamType::Int || name.size() < 11 || name.compare(name.size() - 11, 11, ".resolution") != 0)
      continue;
    ParamSet lo = defaults, hi = defaults;
    lo.set(name, desc.minValue);
    hi.set(name, desc.maxValue);
    auto bytes3D = [&](const ParamSet& p) {
      size_t sum = 0;
      for (const auto& item : estimateResources(t, p, ViewState{}).items) sum += item.is3D ? item.bytes : 0;
      return sum;
    };
    if (bytes3D(hi) > bytes3D(lo)) out.push_back(desc);  // it sizes a 3D texture (not e.g. shadow.resolution)
  }
  return out;
}

// The same check for the techniques without voxel.resolution (clipmap: clipmap.resolution up to
// 64; volumetric: density.resolution up to 256, as declared today): each grid-size parameter at
// its declared maximum runs or is refused for the reason its estimate gives, at the default
// budget and under 128 MiB. Every such technique must have one, so that none is skipped silently.
// Measured: clipmap.resolution=64 51 MiB (runs under both budgets), density.resolution=256
// 161 MiB (runs; refused under 128 MiB, naming density.resolution and its largest fit).
TEST(ResourceBudget, OwnGridParametersAtTheirMaximumRunOrAreRefused) {
  int techniques = 0, checked = 0;
  for (const auto& entry : techniqueRegistry()) {
    auto t = createTechnique(entry.id);
    if (declaresResolution(*t)) continue;
    ++techniques;
    const auto params = ownGridSizeParams(*t);
    EXPECT_FALSE(params.empty()) << entry.id << " has neither voxel.resolution nor a grid-size parameter";
    for (const ParamDesc& d : params) {
      const std::string set = d.name + "=" + std::to_string(int(d.maxValue));
      ParamSet p = t->defaultParams();
      p.set(d.name, d.maxValue);
      const ResourceEstimate e = estimateResources(*t, p, ViewState{});
      const size_t budget = size_t(p.getInt("gpu.memory-budget")) << 20;
      ::testing::Test::RecordProperty(entry.id + "_" + set,
                                      std::to_string(e.totalBytes >> 20) + " MiB: " +
                                          expectName(expectedOutcome(e, budget, contextLimits())) + "; under 128 MiB " +
                                          expectName(expectedOutcome(e, size_t(128) << 20, contextLimits())));
      runOrRefuse(entry.id, {set}, expectedOutcome(e, budget, contextLimits()), d.name);
      runOrRefuse(entry.id, {set, "gpu.memory-budget=128"}, expectedOutcome(e, size_t(128) << 20, contextLimits()),
                  d.name);
      ++checked;
    }
  }
  // clipmap and volumetric have no voxel.resolution today; each has one grid-size parameter.
  EXPECT_GE(techniques, 2);
  EXPECT_GE(checked, techniques);
}

// Under a 128 MiB budget the techniques whose estimate at 512 is over it must be refused for the
// budget; a technique that fits (lpv: its grids follow lpv.resolution) must run.
TEST(ResourceBudget, Resolution512RefusedUnderSmallBudget) {
  int refused = 0, runs = 0;
  for (const auto& entry : techniqueRegistry()) {
    auto t = createTechnique(entry.id);
    if (!declaresResolution(*t)) continue;
    const Expect expected = expectedOutcome(estimateAt(*t, 512), size_t(128) << 20, contextLimits());
    refused += expected == Expect::RefusedOverBudget;
    runs += expected == Expect::Runs;
    runOrRefuse(entry.id, {"voxel.resolution=512", "gpu.memory-budget=128"}, expected);
  }
  EXPECT_GE(refused, 3);
  EXPECT_GE(runs, 1);
}

}  // namespace
}  // namespace voxlab
