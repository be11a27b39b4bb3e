// Reference modes that depend on parameters (OutputDesc::referenceMode with {parameter} names,
// resolved by referenceModeUnder): the resolution itself, its one-line errors, Technique::validate
// refusing a name the technique does not declare, and, over the whole registry, that every declared
// mode resolves to a mode the reference path tracer knows for every value of the parameters it
// names. voxel-path-tracing's K-bounce outputs must follow paths.bounces (indirect-K), never the
// all-bounce "indirect".
#include <gtest/gtest.h>

#include <string>

#include "core/error.h"
#include "graph/reference_mode.h"
#include "graph/param.h"
#include "graph/technique.h"
#include "reference/path_tracer.h"

namespace voxlab {
namespace {

OutputDesc outputWithMode(const std::string& mode) {
  OutputDesc o;
  o.name = "indirect";
  o.referenceMode = mode;
  return o;
}

ParamSet bounceParams(int bounces) {
  ParamSet p;
  p.declare(ParamDesc::integer("paths.bounces", 2, 1, 8, "bounces"));
  p.declare(ParamDesc::choice("mode", {"fast", "exact"}, 1, "a choice"));
  p.set("paths.bounces", bounces);
  return p;
}

std::string errorOf(const OutputDesc& o, const ParamSet& p) {
  try {
    referenceModeUnder(o, p);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(ReferenceModeUnder, ResolvesParameterNamesAgainstTheRun) {
  EXPECT_EQ(referenceModeUnder(outputWithMode("indirect-1"), bounceParams(3)), "indirect-1");
  EXPECT_EQ(referenceModeUnder(outputWithMode(""), bounceParams(3)), "");
  for (int k = 1; k <= 8; ++k)
    EXPECT_EQ(referenceModeUnder(outputWithMode("indirect-{paths.bounces}"), bounceParams(k)),
              "indirect-" + std::to_string(k));
  // Formatted as the parameter's own text (a choice by name), anywhere in the mode, more than once.
  EXPECT_EQ(referenceModeUnder(outputWithMode("{mode}-{paths.bounces}x{paths.bounces}"), bounceParams(4)),
            "exact-4x4");
  EXPECT_EQ(referenceModeParams(outputWithMode("{mode}-{paths.bounces}")),
            (std::vector<std::string>{"mode", "paths.bounces"}));
  EXPECT_TRUE(referenceModeParams(outputWithMode("full")).empty());
}

TEST(ReferenceModeUnder, BadModesAreRefusedInOneLine) {
  const std::string unknown = errorOf(outputWithMode("indirect-{paths.bounce}"), bounceParams(2));
  EXPECT_NE(unknown.find("output indirect: reference mode 'indirect-{paths.bounce}' names 'paths.bounce'"),
            std::string::npos) << unknown;
  EXPECT_NE(unknown.find("must name one of its parameters"), std::string::npos) << unknown;
  for (const char* bad : {"indirect-{paths.bounces", "indirect-}", "indirect-{}", "indirect-{{paths.bounces}}"}) {
    const std::string e = errorOf(outputWithMode(bad), bounceParams(2));
    EXPECT_NE(e.find("unmatched or empty brace"), std::string::npos) << bad << ": " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

// A stage whose output's mode names a parameter: Technique::validate (run by createTechnique for
// every registered technique) must refuse it unless some stage of the technique declares it.
class ModeStage : public Stage {
 public:
  ModeStage(std::string mode, bool declareBounces) : mode_(std::move(mode)), declareBounces_(declareBounces) {}
  const char* id() const override { return "trace"; }
  const char* title() const override { return "trace"; }
  const char* summary() const override { return "test stage"; }
  void declare(StageBuilder& b) const override {
    if (declareBounces_) b.param(ParamDesc::integer("paths.bounces", 2, 1, 8, "bounces"));
    b.output("indirect", OutputKind::Image2D, Semantic::RadianceHDR, "test").referenceMode = mode_;
  }
  void execute(StageContext&) override {}

 private:
  std::string mode_;
  bool declareBounces_;
};

TEST(ReferenceModeUnder, ValidateRefusesAModeNamingAnUndeclaredParameter) {
  Technique good("t", "t", "t");
  good.add<ModeStage>("indirect-{paths.bounces}", true);
  good.setFinalOutput("trace", "indirect");
  EXPECT_NO_THROW(good.validate());
  Technique bad("t", "t", "t");
  bad.add<ModeStage>("indirect-{paths.bounces}", false);
  bad.setFinalOutput("trace", "indirect");
  try {
    bad.validate();
    FAIL() << "validate accepted a reference mode naming an undeclared parameter";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("t/trace: output indirect: reference mode"), std::string::npos) << e.what();
  }
}

// Every declared mode, of every registered technique, at every value of each Int or Choice
// parameter it names (the others at their defaults), is a mode `voxlab reference --mode` accepts:
// so `voxlab run` can always say which reference image it wants.
TEST(ReferenceModeUnder, EveryDeclaredModeResolvesToAReferenceModeAtEveryValue) {
  int templated = 0;
  for (const auto& entry : techniqueRegistry()) {
    auto t = createTechnique(entry.id);
    const ParamSet defaults = t->defaultParams();
    for (int i = 0; i < t->stageCount(); ++i)
      for (const auto& o : t->decl(i).outputs) {
        if (o.referenceMode.empty()) continue;
        const std::string where = entry.id + "/" + t->stage(i).id() + "/" + o.name;
        EXPECT_NO_THROW(reference::parseMode(referenceModeUnder(o, defaults))) << where;
        for (const auto& name : referenceModeParams(o)) {
          ++templated;
          const ParamDesc& d = defaults.desc(name);
          ASSERT_TRUE(d.type == ParamType::Int || d.type == ParamType::Choice) << where << " names " << name;
          const int hi = d.type == ParamType::Int ? int(d.maxValue) : int(d.choices.size()) - 1;
          for (int v = d.type == ParamType::Int ? int(d.minValue) : 0; v <= hi; ++v) {
            ParamSet p = defaults;
            p.set(name, v);
            const std::string mode = referenceModeUnder(o, p);
            EXPECT_NO_THROW(reference::parseMode(mode)) << where << " with " << name << "=" << v << ": " << mode;
          }
        }
      }
  }
  EXPECT_GE(templated, 2) << "voxel-path-tracing's paths/indirect and filter/indirect-filtered name paths.bounces";
}

// The K-bounce estimate is compared with the K-bounce reference: indirect-K for paths.bounces = K,
// through the declarations alone (the code path of voxlab run, gallery and list). Declaring the
// all-bounce "indirect" again, or a fixed "indirect-2", fails here.
TEST(ReferenceModeUnder, VoxelPathTracingFollowsPathsBounces) {
  auto t = createTechnique("voxel-path-tracing");
  for (const char* address : {"paths/indirect", "filter/indirect-filtered"}) {
    const std::string a = address;
    auto [stage, desc] = t->findOutput(a.substr(0, a.find('/')), a.substr(a.find('/') + 1));
    (void)stage;
    const ParamSet defaults = t->defaultParams();  // a copy: desc() points into it
    const ParamDesc& d = defaults.desc("paths.bounces");
    ASSERT_EQ(int(d.minValue), 1);
    ASSERT_EQ(int(d.maxValue), reference::Mode::kMaxIndirectBounces);
    for (int k = int(d.minValue); k <= int(d.maxValue); ++k) {
      ParamSet p = defaults;
      p.set("paths.bounces", k);
      const std::string mode = referenceModeUnder(*desc, p);
      EXPECT_EQ(mode, "indirect-" + std::to_string(k)) << address;
      EXPECT_EQ(reference::parseMode(mode), reference::Mode::indirect(k)) << address;
    }
  }
}

}  // namespace
}  // namespace voxlab
