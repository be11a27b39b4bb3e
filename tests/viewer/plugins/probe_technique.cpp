// A test-only technique (registered only in voxlab_test_viewer): "cells" writes a small volume of
// cell indices (semantic test-cell-index) and a 16x16 "light-space" image, "record" declares a
// volume-space probe on the volume and writes one probe record (semantic test-probed-cell) with
// the probed cell and the value it reads there, and a light-space probe on the image.
// Nothing outside tests/viewer/plugins names it; the viewer finds the probe and the records from
// the declarations, and the visualisers in this folder show both.
#include <vector>

#include "graph/stage.h"
#include "graph/technique.h"
#include "test_semantics.h"

namespace voxlab::test_plugins {
namespace {

constexpr int kEdge = 8;

class CellsStage : public Stage {
 public:
  const char* id() const override { return "cells"; }
  const char* title() const override { return "Cell indices"; }
  const char* summary() const override { return "an 8^3 volume whose texels hold their own linear index"; }
  void declare(StageBuilder& b) const override {
    b.output("cells", OutputKind::Volume3D, kCellIndex, "x + 8 (y + 8 z) at every cell");
    b.output("light-image", OutputKind::Image2D, Semantic::Fraction, "a light-space image: x / 16 in red");
  }
  void execute(StageContext& ctx) override {
    TextureDesc d;
    d.target = GL_TEXTURE_3D;
    d.format = GL_R32F;
    d.size = {kEdge, kEdge, kEdge};
    d.levels = 2;  // level 1 (4^3) is there to click on: the probe means level-0 cells
    Texture& t = ctx.board.ensureTexture("cells", d);
    std::vector<float> v(kEdge * kEdge * kEdge);
    for (size_t i = 0; i < v.size(); ++i) v[i] = float(i);
    glTextureSubImage3D(t.id(), 0, 0, 0, 0, kEdge, kEdge, kEdge, GL_RED, GL_FLOAT, v.data());
    glGenerateTextureMipmap(t.id());
    ctx.board.place("cells", WorldBox{glm::vec3(0.0f), glm::vec3(1.0f)});
    TextureDesc l;
    l.format = GL_R32F;
    l.size = {16, 16, 1};
    std::vector<float> ramp(16 * 16);
    for (size_t i = 0; i < ramp.size(); ++i) ramp[i] = float(i % 16) / 16.0f;
    glTextureSubImage2D(ctx.board.ensureTexture("light-image", l).id(), 0, 0, 0, 16, 16, GL_RED, GL_FLOAT, ramp.data());
  }
};

class RecordStage : public Stage {
 public:
  const char* id() const override { return "record"; }
  const char* title() const override { return "Record the probed cell"; }
  const char* summary() const override { return "reads the probed cell of the volume back into a probe record"; }
  void declare(StageBuilder& b) const override {
    b.read("cells");
    b.param(ParamDesc::integer("probe.cell-x", 0, 0, kEdge - 1, "probed cell, x", "cells"));
    b.param(ParamDesc::integer("probe.cell-y", 0, 0, kEdge - 1, "probed cell, y", "cells"));
    b.param(ParamDesc::integer("probe.cell-z", 0, 0, kEdge - 1, "probed cell, z", "cells"));
    b.probe(ProbeDesc::volume("probe.cell-x", "probe.cell-y", "probe.cell-z", "", "cells"));
    b.read("light-image");
    b.param(ParamDesc::real("probe.light-x", 0.5, 0.0, 1.0, "probed light-space texel, x (0 left, 1 right)"));
    b.param(ParamDesc::real("probe.light-y", 0.5, 0.0, 1.0, "probed light-space texel, y (0 top, 1 bottom)"));
    b.probe(ProbeDesc::light("probe.light-x", "probe.light-y", "light-image"));
    BufferLayout layout;
    layout.stride = sizeof(ProbedCellRecord);
    layout.fields = {{"x", FieldType::I32, 0}, {"y", FieldType::I32, 4}, {"z", FieldType::I32, 8},
                     {"value", FieldType::F32, 12}};
    OutputDesc& o = b.output("probed-cell", OutputKind::Buffer, kProbedCell, "the probed cell and its value");
    o.layout = layout;
    o.probeRecord = true;
  }
  void execute(StageContext& ctx) override {
    ProbedCellRecord r{ctx.params.getInt("probe.cell-x"), ctx.params.getInt("probe.cell-y"),
                       ctx.params.getInt("probe.cell-z"), 0.0f};
    glGetTextureSubImage(ctx.board.texture("cells").id(), 0, r.x, r.y, r.z, 1, 1, 1, GL_RED, GL_FLOAT, 4, &r.value);
    ctx.board.ensureBuffer("probed-cell", sizeof r).upload(&r, sizeof r);
  }
};

std::unique_ptr<Technique> makeTestProbe() {
  auto t = std::make_unique<Technique>("test-probe", "Test: a volume-space probe",
                                       "A volume of cell indices and a stage that records the cell a click points at.");
  t->add<CellsStage>();
  t->add<RecordStage>();
  t->setFinalOutput("record", "probed-cell");
  return t;
}

}  // namespace
}  // namespace voxlab::test_plugins

namespace voxlab {
using test_plugins::makeTestProbe;
VOXLAB_REGISTER_TECHNIQUE("test-probe", "Test: a volume-space probe", makeTestProbe);
}  // namespace voxlab
