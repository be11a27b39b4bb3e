// Test-only visualisers (voxlab_test_viewer): volumes of semantic test-cell-index and buffers of
// semantic test-probed-cell. Each shows that a visualiser registered outside src/ is found by
// kind and semantic everywhere: the view (a checkerboard of cells), the value under the cursor
// ("cell N"), the statistics ("cells"), the files save-output writes (an .index.txt next to the
// usual ones) and the probe record check.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>

#include <imgui.h>

#include "inspect/visualisers/buffer.h"
#include "inspect/visualisers/levels.h"
#include "test_semantics.h"

namespace voxlab::test_plugins {
namespace {

class CellIndexVisualiser : public VolumeVisualiser {
 public:
  const char* name() const override { return "test-cell-index"; }
  CaptureTier defaultTier(const OutputDesc&) const override { return CaptureTier::Exact; }

  nlohmann::json statistics(const CapturedOutput& out) const override {
    nlohmann::json s = VolumeVisualiser::statistics(out);
    s["cells"] = out.levels.empty() ? 0 : out.levels[0].texelCount();
    return s;
  }

  nlohmann::json writeFiles(const CapturedOutput& out, const std::string& dir, const std::string& prefix) const override {
    nlohmann::json entry = VolumeVisualiser::writeFiles(out, dir, prefix);
    // One line per cell of level 0: "x y z index".
    std::ofstream f(dir + "/" + prefix + ".index.txt");
    const LevelData& L = out.levels.at(0);
    for (int z = 0; z < L.size.z; ++z)
      for (int y = 0; y < L.size.y; ++y)
        for (int x = 0; x < L.size.x; ++x) f << x << " " << y << " " << z << " " << L.at(x, y, z, 0) << "\n";
    entry["files"].push_back(prefix + ".index.txt");
    return entry;
  }

  // Cells as a checkerboard of two hues, brighter for a larger index.
  SliceImage image2D(const VisualiserContext& ctx) const override {
    SliceImage img = VolumeVisualiser::image2D(ctx);
    const LevelData* L = shownLevel(ctx);
    if (!L) return img;
    SliceSpec s = sliceToShow(*L, ctx.view.slice);
    const float cells = float(L->texelCount());
    for (int py = 0; py < img.height; ++py)
      for (int px = 0; px < img.width; ++px) {
        glm::ivec3 t = sliceTexel(*L, s, px, py);
        float v = 0.25f + 0.75f * L->at(t.x, t.y, t.z, 0) / cells;
        bool odd = (t.x + t.y + t.z) % 2 != 0;
        uint8_t* o = &img.rgba[(size_t(py) * img.width + px) * 4];
        o[0] = unitToByte(odd ? v : 0.2f * v);
        o[1] = unitToByte(0.3f * v);
        o[2] = unitToByte(odd ? 0.2f * v : v);
      }
    return img;
  }

  std::string describeElement(const VisualiserContext& ctx, const glm::ivec3& t) const override {
    const LevelData* L = shownLevel(ctx);
    if (!L) return "";
    char buf[96];
    std::snprintf(buf, sizeof buf, "cell (%d, %d, %d): index %.0f", t.x, t.y, t.z, L->at(t.x, t.y, t.z, 0));
    return buf;
  }
};

class ProbedCellVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "test-probed-cell"; }

  void drawRecordView(const VisualiserContext& ctx) const override {
    RecordCheck c = checkRecords(ctx.out);
    ImGui::Text("%s", c.summary.c_str());
    if (!c.error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", c.error.c_str());
  }

  // Every record's value is the index of its own cell (8^3 volume).
  RecordCheck checkRecords(const CapturedOutput& out) const override {
    RecordCheck c;
    for (uint32_t i = 0; i < out.recordCount; ++i) {
      ProbedCellRecord r;
      std::memcpy(&r, &out.records[size_t(i) * sizeof r], sizeof r);
      float want = float(r.x + 8 * (r.y + 8 * r.z));
      char buf[128];
      std::snprintf(buf, sizeof buf, "cell (%d, %d, %d) holds %.0f", r.x, r.y, r.z, r.value);
      c.summary += (c.summary.empty() ? "" : "; ") + std::string(buf);
      if (r.value != want) c.error = std::string(buf) + ", expected its index " + std::to_string(int(want));
      ++c.elements;
    }
    if (c.elements == 0) c.summary = "no probed cell recorded";
    return c;
  }
};

}  // namespace

VOXLAB_REGISTER_VISUALISER(CellIndexVisualiser, OutputKind::Volume3D, kCellIndex.name());
VOXLAB_REGISTER_VISUALISER(ProbedCellVisualiser, OutputKind::Buffer, kProbedCell.name());

}  // namespace voxlab::test_plugins
