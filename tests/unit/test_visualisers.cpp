// The visualiser registry and the probe declarations, without a window: lookup by (kind, semantic)
// with the fallback by kind, the tier the snapshot suite uses, texel mappings, and the checks
// Technique::validate makes on probes.
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "capture/output_handler.h"
#include "core/error.h"
#include "graph/technique.h"
#include "inspect/visualiser.h"

namespace voxlab {
namespace {

OutputDesc desc(OutputKind kind, Semantic semantic) {
  OutputDesc d;
  d.name = "x";
  d.kind = kind;
  d.semantic = semantic;
  return d;
}

TEST(Visualisers, LookedUpBySemanticThenByKind) {
  EXPECT_STREQ(visualiserFor(OutputKind::Buffer, Semantic::ConeSamples).name(), "cone-samples");
  EXPECT_STREQ(visualiserFor(OutputKind::Buffer, Semantic::Points).name(), "points");
  // Semantics without a visualiser of their own get their kind's.
  constexpr Semantic kUnknown{"no-such-semantic"};
  EXPECT_STREQ(visualiserFor(OutputKind::Buffer, kUnknown).name(), "buffer");
  EXPECT_STREQ(visualiserFor(OutputKind::Image2D, kUnknown).name(), "image");
  EXPECT_STREQ(visualiserFor(OutputKind::Volume3D, Semantic::Occupancy).name(), "volume");
  // The headless registry holds the same objects.
  EXPECT_EQ(static_cast<const OutputHandler*>(&visualiserFor(OutputKind::Buffer, Semantic::ConeSamples)),
            &outputHandler(OutputKind::Buffer, Semantic::ConeSamples));
}

// Every output every registered technique declares, as (kind, semantic, "technique/stage/output").
std::vector<SemanticUse> declaredOutputSemantics() {
  std::vector<SemanticUse> uses;
  for (const auto& entry : techniqueRegistry()) {
    auto t = entry.create();
    for (int i = 0; i < t->stageCount(); ++i)
      for (const auto& o : t->decl(i).outputs)
        uses.push_back({o.kind, o.semantic.name(), entry.id + "/" + t->stage(i).id() + "/" + o.name});
  }
  return uses;
}

// A semantic is declared once (a constant the output declaration and the view's registration both
// name), so a view is reached by every output of its semantic; a misspelt or stale registration
// would leave the outputs with the generic view and is reported instead.
TEST(Visualisers, EveryDeclaredSemanticWithAViewResolvesToIt) {
  const std::vector<SemanticUse> registered = registeredVisualiserSemantics();
  const std::vector<SemanticUse> declared = declaredOutputSemantics();
  std::set<std::string> reached;
  for (const SemanticUse& d : declared)
    for (const SemanticUse& r : registered)
      if (d.kind == r.kind && d.semantic == r.semantic) {
        EXPECT_STREQ(visualiserFor(d.kind, Semantic(d.semantic.c_str())).name(), r.where.c_str()) << d.where;
        reached.insert(r.where + "|" + r.semantic);
      }
  EXPECT_EQ(reached.size(), registered.size());
  // The technique views (lpv, clipmap, near-field, svo, lrsm, volumetric) and the shared ones.
  EXPECT_GE(registered.size(), 20u);
  EXPECT_EQ(semanticMismatches(declared, registered), std::vector<std::string>{});
}

TEST(Visualisers, AViewNoOutputReachesIsReported) {
  const std::vector<SemanticUse> declared = {{OutputKind::Buffer, "lpv-energy", "lpv/propagate/energy"},
                                             {OutputKind::Image2D, "sh-l1", "lpv/inject/flat"}};
  const std::vector<SemanticUse> registered = {{OutputKind::Buffer, "lpv-energy", "lpv-energy"},
                                               {OutputKind::Buffer, "lpv-enregy", "lpv-energy-typo"},
                                               {OutputKind::Volume3D, "sh-l1", "sh-volume"}};
  const std::vector<std::string> problems = semanticMismatches(declared, registered);
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_NE(problems[0].find("lpv-energy-typo"), std::string::npos) << problems[0];
  EXPECT_NE(problems[0].find("no output declares"), std::string::npos) << problems[0];
  EXPECT_NE(problems[1].find("sh-volume"), std::string::npos) << problems[1];
  EXPECT_NE(problems[2].find("lpv/inject/flat"), std::string::npos) << problems[2];
  EXPECT_NE(problems[2].find("generic view"), std::string::npos) << problems[2];
  EXPECT_TRUE(semanticMismatches(declared, {registered[0]}).empty());
}

TEST(Visualisers, SemanticsAreNamesComparedByText) {
  const std::string text = "cone-samples";
  EXPECT_EQ(Semantic(text.c_str()), Semantic::ConeSamples);
  EXPECT_NE(Semantic("color"), Semantic::Normal);
  EXPECT_STREQ(semanticName(Semantic::RadianceHDR), "radiance-hdr");
}

TEST(Visualisers, TierIsDeclaredOrTheVisualisersDefault) {
  EXPECT_EQ(captureTier(desc(OutputKind::Volume3D, Semantic::Occupancy)), CaptureTier::Exact);
  EXPECT_EQ(captureTier(desc(OutputKind::Buffer, Semantic::Points)), CaptureTier::Exact);
  EXPECT_EQ(captureTier(desc(OutputKind::Image2D, Semantic::Color)), CaptureTier::Tolerance);
  EXPECT_EQ(captureTier(desc(OutputKind::Buffer, Semantic::ConeSamples)), CaptureTier::Tolerance);
  OutputDesc declared = desc(OutputKind::Image2D, Semantic::Color);
  declared.tier = CaptureTier::None;
  EXPECT_EQ(captureTier(declared), CaptureTier::None);
}

TEST(Visualisers, TexelMappingsBySemantic) {
  uint8_t rgb[3];
  const float white[4] = {1.0f, 1.0f, 1.0f, 1.0f};
  texelMapping(Semantic::Color).map(white, 4, 1.0f, 0.0f, 0.0f, rgb);
  EXPECT_EQ(rgb[0], 255);
  // Reinhard: 1 / (1 + 1) = 0.5 linear, sRGB-encoded 0.7354 -> 188.
  texelMapping(Semantic::RadianceHDR).map(white, 4, 1.0f, 0.0f, 0.0f, rgb);
  EXPECT_EQ(rgb[0], 188);
  EXPECT_TRUE(texelMapping(Semantic::Depth).normalise);
  EXPECT_TRUE(texelMapping(Semantic::Opacity).alphaIsOpacity);
  EXPECT_FALSE(texelMapping(Semantic::Normal).alphaIsOpacity);
  // A semantic without a mapping is shown normalised min..max in false colour.
  constexpr Semantic kUnknown{"no-such-semantic"};
  EXPECT_TRUE(texelMapping(kUnknown).normalise);
  uint8_t lo[3], hi[3];
  const float zero = 0.0f, one = 1.0f;
  texelMapping(kUnknown).map(&zero, 1, 1.0f, 0.0f, 1.0f, lo);
  texelMapping(kUnknown).map(&one, 1, 1.0f, 0.0f, 1.0f, hi);
  EXPECT_LT(lo[0] + lo[1] + lo[2], hi[0] + hi[1] + hi[2]);  // brighter for larger values
}

// A stage whose probe names parameters it may or may not declare.
class ProbingStage : public Stage {
 public:
  ProbingStage(ProbeDesc probe, bool declareParams) : probe_(std::move(probe)), declare_(declareParams) {}
  const char* id() const override { return "probing"; }
  const char* title() const override { return "Probing"; }
  const char* summary() const override { return "declares a probe"; }
  void declare(StageBuilder& b) const override {
    if (declare_)
      for (const auto& n : probe_.paramNames()) b.param(ParamDesc::integer(n, 0, 0, 7, "probe"));
    b.probe(probe_);
    b.output("image", OutputKind::Image2D, Semantic::Color, "an image");
  }
  void execute(StageContext&) override {}

 private:
  ProbeDesc probe_;
  bool declare_;
};

std::string validationError(ProbeDesc probe, bool declareParams) {
  Technique t("probe-test", "Probe test", "a probe declaration");
  t.add<ProbingStage>(std::move(probe), declareParams);
  t.setFinalOutput("probing", "image");
  try {
    t.validate();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Probes, ValidateChecksTheNamedParameters) {
  EXPECT_EQ(validationError(ProbeDesc::volume("c.x", "c.y", "c.z", "c.level", "radiance"), true), "");
  EXPECT_EQ(validationError(ProbeDesc::screen("p.x", "p.y"), true), "");
  std::string m = validationError(ProbeDesc::volume("c.x", "c.y", "c.z"), false);
  EXPECT_NE(m.find("volume probe names parameter 'c.x', which the stage does not declare"), std::string::npos) << m;
  m = validationError(ProbeDesc::light("l.x", "l.y", ""), true);
  EXPECT_NE(m.find("a light probe names the light-space image"), std::string::npos) << m;
  m = validationError(ProbeDesc{ProbeSpace::Volume, "c.x", "c.y", "", "", ""}, true);
  EXPECT_NE(m.find("needs parameters for x, y and z"), std::string::npos) << m;
}

TEST(Probes, VctGridDeclaresItsConeSamplesAsAScreenProbeRecord) {
  // Declarations only: no GL. Two stages probe the screen: cone-trace records the pixel's cone
  // samples, the composite its chain (semantic probe-chain), both on the same probe.x/probe.y.
  auto t = createTechnique("vct-grid");
  int probing = 0, records = 0, chains = 0;
  for (int i = 0; i < t->stageCount(); ++i) {
    for (const auto& p : t->decl(i).probes) {
      probing += p.space == ProbeSpace::Screen;
      EXPECT_EQ(p.x, "probe.x");
    }
    for (const auto& o : t->decl(i).outputs) {
      records += o.probeRecord;
      chains += o.probeRecord && o.semantic == Semantic::ProbeChain;
    }
  }
  EXPECT_EQ(probing, 2);
  EXPECT_EQ(records, 2);
  EXPECT_EQ(chains, 1);
}

TEST(Probes, EveryCompositingTechniqueExplainsThePixelWithAChain) {
  // The composite every technique shares declares the chain, with the technique's own terms.
  for (const char* id : {"vct-grid", "svo", "lrsm", "lpv", "near-field", "clipmap"}) {
    auto t = createTechnique(id);
    const auto [stage, chain] = t->findOutput("composite", "probe-chain");
    EXPECT_TRUE(chain->probeRecord) << id;
    EXPECT_EQ(chain->semantic, Semantic::ProbeChain) << id;
    int addends = 0, sums = 0, shown = 0;
    for (const auto& f : chain->layout.fields) {
      addends += f.role == FieldRole::Addend;
      sums += f.role == FieldRole::Sum;
      shown += f.role == FieldRole::Displayed;
    }
    EXPECT_GE(addends, 3) << id << ": reflected, emission and at least one indirect term";
    EXPECT_EQ(sums, 1) << id;
    EXPECT_EQ(shown, 1) << id;
  }
}

}  // namespace
}  // namespace voxlab
