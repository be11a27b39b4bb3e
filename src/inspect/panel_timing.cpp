// Timing tab: per-stage CPU and GPU times with their recent history, UI frame times, and the
// blackboard's resources with their sizes.
#include <algorithm>
#include <cfloat>
#include <cstdio>

#include "inspect/script_verbs.h"
#include "inspect/viewer_state.h"

namespace voxlab {

void Viewer::drawTiming() {
  const Technique& t = cursor->technique();
  double cpu = 0, gpu = 0;
  // The state is in the timeline; here the room goes to each stage's recent GPU times.
  if (ImGui::BeginTable("timing", 4, ImGuiTableFlags_Borders | ImGuiTableFlags_SizingStretchProp)) {
    ImGui::TableSetupColumn("stage", ImGuiTableColumnFlags_WidthStretch, 1.15f);
    ImGui::TableSetupColumn("cpu ms", ImGuiTableColumnFlags_WidthStretch, 0.6f);
    ImGui::TableSetupColumn("gpu ms", ImGuiTableColumnFlags_WidthStretch, 0.6f);
    ImGui::TableSetupColumn("gpu ms, last runs", ImGuiTableColumnFlags_WidthStretch, 1.65f);
    ImGui::TableHeadersRow();
    for (int i = 0; i < t.stageCount(); ++i) {
      const StageRecord& r = cursor->record(i);
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(t.stage(i).id());
      ImGui::TableNextColumn();
      ImGui::Text("%.1f", r.cpuMs);
      ImGui::TableNextColumn();
      ImGui::Text("%.1f", r.gpuMs);
      ImGui::TableNextColumn();
      const auto& h = timeHistory.at(i);
      if (!h.empty()) {
        std::vector<float> g;
        for (const auto& e : h) g.push_back(e.second);
        std::vector<float> sorted = g;
        std::sort(sorted.begin(), sorted.end());
        char overlay[48];
        std::snprintf(overlay, sizeof overlay, "median %.1f (%zu)", sorted[sorted.size() / 2], g.size());
        ImGui::PushID(i);
        ImGui::PlotLines("##history", g.data(), int(g.size()), 0, overlay, 0.0f, FLT_MAX,
                         ImVec2(std::max(ImGui::GetContentRegionAvail().x, 40.0f), 18.0f * uiScale));
        ImGui::PopID();
      }
      cpu += r.cpuMs;
      gpu += r.gpuMs;
    }
    ImGui::EndTable();
  }
  ImGui::Text("total cpu %.1f ms, gpu %.1f ms", cpu, gpu);
  if (!idleFrameMs.empty()) {
    size_t n = std::min<size_t>(idleFrameMs.size(), 120);
    std::vector<float> recent(idleFrameMs.end() - n, idleFrameMs.end());
    ImGui::PlotLines("UI ms", recent.data(), int(n), 0, nullptr, 0.0f, FLT_MAX, ImVec2(0, 40));
  }
  ImGui::Separator();
  const Blackboard& b = cursor->board();
  ImGui::Text("resources: %s", formatBytes(b.totalBytes()).c_str());
  if (ImGui::BeginTable("memory", 3, ImGuiTableFlags_Borders | ImGuiTableFlags_SizingFixedFit | ImGuiTableFlags_ScrollY,
                        ImVec2(0, 260))) {
    ImGui::TableSetupColumn("resource");
    ImGui::TableSetupColumn("shape");
    ImGui::TableSetupColumn("bytes");
    ImGui::TableHeadersRow();
    for (const auto& [name, tex] : b.textures()) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(name.c_str());
      ImGui::TableNextColumn();
      glm::ivec3 s = tex->levelSize(0);
      ImGui::Text("%dx%dx%d %s x%d", s.x, s.y, s.z, formatName(tex->desc().format), tex->levels());
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(formatBytes(tex->byteSize()).c_str());
    }
    for (const auto& [name, buf] : b.buffers()) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(name.c_str());
      ImGui::TableNextColumn();
      ImGui::TextUnformatted("buffer");
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(formatBytes(buf->size()).c_str());
    }
    ImGui::EndTable();
  }
}

VOXLAB_REGISTER_DETAILS_TAB(timing, "timing", "Timing", 30, nullptr, [](Viewer& v) { v.drawTiming(); });

VOXLAB_REGISTER_SCRIPT_VERBS(timing, 120,
  {"frame-stats", 0, 0, "frame-stats (prints UI frame times)",
   [](Viewer& viewer, const ScriptCall&) { viewer.printFrameStats(); }});

}  // namespace voxlab
