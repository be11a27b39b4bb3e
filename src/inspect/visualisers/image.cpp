// Images and the shared part of every level visualiser: the 2D view of a level (the semantic's
// colours, or one channel in grey, times an exposure), the value under the cursor, the level /
// channel / exposure controls and the level's statistics; files: PNG (display) + EXR (values) per
// level; golden: per-value tolerance, exact for semantics whose values are structural.
#include <algorithm>
#include <cstdio>

#include <imgui.h>

#include "inspect/visualisers/levels.h"

namespace voxlab {

CaptureTier LevelVisualiser::defaultTier(const OutputDesc& d) const {
  return texelMapping(d.semantic).exact ? CaptureTier::Exact : CaptureTier::Tolerance;
}

nlohmann::json LevelVisualiser::statistics(const CapturedOutput& out) const { return levelStatistics(out); }

nlohmann::json LevelVisualiser::writeFiles(const CapturedOutput& out, const std::string& dir,
                                           const std::string& prefix) const {
  nlohmann::json entry = manifestEntry(out, statistics(out));
  entry["levels"] = int(out.levels.size());
  nlohmann::json files = nlohmann::json::array();
  writeLevelFiles(out, dir, prefix, files);
  entry["files"] = files;
  return entry;
}

GoldenResult LevelVisualiser::compareGolden(const CapturedOutput& out, const GoldenRequest& request) const {
  return compareLevelsWithGolden(out, request);
}

const LevelData* LevelVisualiser::shownLevel(const VisualiserContext& ctx) {
  if (ctx.out.levels.empty()) return nullptr;
  ctx.view.level = std::clamp(ctx.view.level, 0, int(ctx.out.levels.size()) - 1);
  return &ctx.out.levels[ctx.view.level];
}

SliceImage LevelVisualiser::image2D(const VisualiserContext& ctx) const {
  const LevelData* L = shownLevel(ctx);
  if (!L) return {};
  return mapSlice(*L, ctx.out.desc.semantic, sliceToShow(*L, ctx.view.slice), ctx.view.display);
}

bool LevelVisualiser::elementAt(const VisualiserContext& ctx, int px, int py, glm::ivec3& element) const {
  const LevelData* L = shownLevel(ctx);
  if (!L) return false;
  SliceSpec s = sliceToShow(*L, ctx.view.slice);
  glm::ivec2 e = sliceExtent(*L, s);
  if (px < 0 || py < 0 || px >= e.x || py >= e.y) return false;
  element = sliceTexel(*L, s, px, py);
  return true;
}

std::string LevelVisualiser::describeElement(const VisualiserContext& ctx, const glm::ivec3& t) const {
  const LevelData* L = shownLevel(ctx);
  if (!L || t.x < 0 || t.y < 0 || t.z < 0 || t.x >= L->size.x || t.y >= L->size.y || t.z >= L->size.z) return "";
  std::string values;
  char buf[96];
  for (int c = 0; c < L->channels; ++c) {
    std::snprintf(buf, sizeof buf, "%s%.4g", c ? ", " : "", L->at(t.x, t.y, t.z, c));
    values += buf;
  }
  // Images count rows from the top (as the probe does); volumes keep texel coordinates.
  const bool volume = L->size.z > 1;
  std::snprintf(buf, sizeof buf, "%s (%d, %d, %d) = (", volume ? "voxel" : "pixel", t.x, volume ? t.y : L->size.y - 1 - t.y, t.z);
  return buf + values + ")";
}

void LevelVisualiser::drawInspector(const VisualiserContext& ctx) const {
  const LevelData* L = shownLevel(ctx);
  if (!L) return;
  ViewSettings& v = ctx.view;
  int levels = int(ctx.out.levels.size());
  if (levels > 1) ImGui::SliderInt("level", &v.level, 0, levels - 1);
  L = shownLevel(ctx);
  ImGui::Text("size %d x %d x %d, %d channels", L->size.x, L->size.y, L->size.z, L->channels);
  if (L->size.z > 1) {
    ImGui::TextUnformatted("slice axis");
    for (int a = 0; a < 3; ++a) {
      ImGui::SameLine();
      ImGui::RadioButton(a == 0 ? "x" : a == 1 ? "y" : "z", &v.slice.axis, a);
    }
    int extent = v.slice.axis == 0 ? L->size.x : v.slice.axis == 1 ? L->size.y : L->size.z;
    if (v.slice.index < 0) v.slice.index = extent / 2;
    v.slice.index = std::clamp(v.slice.index, 0, extent - 1);
    ImGui::SliderInt("slice", &v.slice.index, 0, extent - 1);
  }
  const char* channels[] = {"all (semantic)", "r / 0", "g / 1", "b / 2", "a / 3"};
  int ch = v.display.channel + 1;
  if (ImGui::Combo("channel", &ch, channels, std::min(L->channels, 4) + 1)) v.display.channel = ch - 1;
  ImGui::SliderFloat("exposure", &v.display.exposure, 0.05f, 16.0f, "%.2f", ImGuiSliderFlags_Logarithmic);
  const nlohmann::json& stats = ctx.statistics;
  if (stats.contains("levels") && stats["levels"].size() > size_t(v.level)) {
    ImGui::Separator();
    ImGui::Text("level %d statistics", v.level);
    drawStatisticsTable("levelstats", stats["levels"][v.level]);
  }
}

VOXLAB_REGISTER_VISUALISER(ImageVisualiser, OutputKind::Image2D, kAnySemantic);

}  // namespace voxlab
