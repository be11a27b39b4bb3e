// Inspect tab: the stage's summary and statistics, then the shown output's controls and tables
// as its visualiser draws them (levels, slices, channels, statistics; records).
#include "inspect/viewer_state.h"

namespace voxlab {

namespace {

void drawInspector(Viewer& v) {
  const Technique& t = v.cursor->technique();
  ImGui::TextWrapped("%s", t.stage(v.selected).summary());
  const StageRecord& rec = v.cursor->record(v.selected);
  if (!rec.stats.empty() && ImGui::CollapsingHeader("stage statistics", ImGuiTreeNodeFlags_DefaultOpen)) {
    nlohmann::json j(rec.stats);
    drawStatisticsTable("stagestats", j);
  }
  ImGui::Separator();
  const Visualiser* vis = v.shownVisualiser();
  if (!vis) return;
  ImGui::TextDisabled("visualiser: %s", vis->name());
  vis->drawInspector(v.visualiserContext());
}

}  // namespace

VOXLAB_REGISTER_DETAILS_TAB(inspect, "inspect", "Inspect", 10, nullptr, [](Viewer& v) { drawInspector(v); });

}  // namespace voxlab
