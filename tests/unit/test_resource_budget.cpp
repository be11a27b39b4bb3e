// The resource budget (graph/resource_budget.h): every technique's declared resources match what
// it allocates, and a run that does not fit is refused with one line before any allocation.
// Techniques come from the registry; no technique is named here.
#include <gtest/gtest.h>

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
        EXPECT_EQ(board.textures().at(item.resource)->byteSize(), item.bytes) << item.resource;
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
    ++techniques;
    SCOPED_TRACE(entry.id);
    ParamSet p = t->defaultParams();
    const ViewState view;
    const ResourceLimits limits;
    for (int r = 16; r < 512; r *= 2) {
      p.set("voxel.resolution", r);
      const size_t atR = estimateResources(*t, p, view).totalBytes;
      const size_t budgetMiB = (atR + (size_t(1) << 20) - 1) >> 20;
      p.set("voxel.resolution", 2 * r);
      const size_t atNext = estimateResources(*t, p, view).totalBytes;
      if (budgetMiB < 64 || (budgetMiB << 20) >= atNext) continue;
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
  EXPECT_EQ(checked, techniques) << "every technique with voxel.resolution grows past 64 MiB below 512";
}

// A 3D texture over GL_MAX_3D_TEXTURE_SIZE is named with the limit.
TEST(ResourceBudget, TextureLimitIsNamed) {
  for (const auto& entry : techniqueRegistry()) {
    auto t = createTechnique(entry.id);
    if (!declaresResolution(*t)) continue;
    SCOPED_TRACE(entry.id);
    ParamSet p = t->defaultParams();
    p.set("voxel.resolution", 512);
    ResourceLimits limits;
    limits.max3DTextureSize = 256;
    const std::string line = checkResourceBudget(*t, p, ViewState{}, limits);
    EXPECT_NE(line.find("exceeds GL_MAX_3D_TEXTURE_SIZE 256"), std::string::npos) << line;
    EXPECT_NE(line.find("the largest voxel.resolution that fits is 256"), std::string::npos) << line;
  }
}

// The check: voxel.resolution=512 with every technique either runs or is refused with
// the one-line message before any GL allocation (nothing on the blackboard).
void runOrRefuse(const std::string& technique, std::vector<std::string> sets, bool mustRefuse) {
  SCOPED_TRACE(technique);
  RunRequest r = smallRun(technique, sets);
  try {
    HeadlessSession& s = session(r);  // runs it
    EXPECT_FALSE(mustRefuse) << "ran although the budget should refuse it";
    EXPECT_EQ(s.cursor().resourceBudgetExcess(), "");
    const size_t budget = size_t(s.cursor().params().getInt("gpu.memory-budget")) << 20;
    EXPECT_LE(s.cursor().board().totalBytes(), budget);
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("voxel.resolution=512 is too large, the largest voxel.resolution that fits is"),
              std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    HeadlessSession& s = session(r);  // the refused session, kept by the cache
    EXPECT_TRUE(s.cursor().board().textures().empty());
    EXPECT_TRUE(s.cursor().board().buffers().empty());
  }
}

TEST(ResourceBudget, Resolution512RunsOrIsRefused) {
  for (const auto& entry : techniqueRegistry())
    if (declaresResolution(*createTechnique(entry.id))) runOrRefuse(entry.id, {"voxel.resolution=512"}, false);
}

TEST(ResourceBudget, Resolution512RefusedUnderSmallBudget) {
  for (const auto& entry : techniqueRegistry())
    if (declaresResolution(*createTechnique(entry.id)))
      runOrRefuse(entry.id, {"voxel.resolution=512", "gpu.memory-budget=128"}, true);
}

}  // namespace
}  // namespace voxlab
