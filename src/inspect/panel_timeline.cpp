// Left panel: technique and scene pickers, the stage timeline (state, queue, iterations) and the
// run buttons; the parameters below it are panel_parameters.cpp.
#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "core/paths.h"
#include "inspect/viewer_state.h"

namespace voxlab {

namespace fs = std::filesystem;

void Viewer::drawLeftPanel() {
  Technique& t = cursor->technique();
  // Technique and scene pickers.
  if (ImGui::BeginCombo("technique", t.id().c_str())) {
    for (const auto& e : techniqueRegistry())
      if (ImGui::Selectable(e.id.c_str(), e.id == t.id()) && e.id != t.id()) switchTechnique(e.id);
    ImGui::EndCombo();
  }
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", t.title().c_str());
  if (ImGui::BeginCombo("scene", scene->name.c_str())) {
    std::error_code ec;
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(projectPath("scenes"), ec)) {
      auto ext = e.path().extension().string();
      if (ext == ".gltf" || ext == ".glb") names.push_back(e.path().stem().string());
    }
    std::sort(names.begin(), names.end());
    for (const auto& n : names)
      if (ImGui::Selectable(n.c_str(), n == scene->name)) loadSceneNamed(n);
    ImGui::EndCombo();
  }
  ImGui::InputText("##scenepath", scenePath, sizeof scenePath);
  ImGui::SameLine();
  if (ImGui::Button("Load")) loadSceneNamed(scenePath);
  if (!sceneError.empty()) ImGui::TextColored(kErrorColour, "%s", sceneError.c_str());

  // Stage timeline.
  ImGui::Separator();
  ImGui::TextUnformatted("Stages");
  for (int i = 0; i < t.stageCount(); ++i) {
    const StageRecord& r = cursor->record(i);
    ImVec4 col = r.state == StageState::Done    ? ImVec4(0.4f, 0.9f, 0.4f, 1)
                 : r.state == StageState::Stale ? kWarningColour
                                                : ImVec4(0.6f, 0.6f, 0.6f, 1);
    bool running = (runTarget >= i && r.state != StageState::Done) || iterateStage == i;
    char state[48];
    if (r.state == StageState::Partial)
      std::snprintf(state, sizeof state, "partial %d/%d", r.iterationsRun, r.iterationsTotal);
    else
      std::snprintf(state, sizeof state, "%s", running ? "(queued)" : stageStateName(r.state));
    char label[160];
    std::snprintf(label, sizeof label, "%d. %-14s %s##stage%d", i + 1, t.stage(i).id(), state, i);
    ImGui::PushStyleColor(ImGuiCol_Text, col);
    if (ImGui::Selectable(label, selected == i)) selectStage(i);
    ImGui::PopStyleColor();
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s\n%s", t.stage(i).title(), t.stage(i).summary());
  }
  if (ImGui::Button("< Prev")) selectStage(selected - 1);
  ImGui::SameLine();
  if (ImGui::Button("Next >")) {
    selectStage(selected + 1);
    runSelected();
  }
  ImGui::SameLine();
  if (ImGui::Button("Run to here")) runSelected();
  ImGui::SameLine();
  if (ImGui::Button("Run all")) runAll();
  const int iterations = cursor->iterations(selected);
  if (iterations > 1) {
    const StageRecord& r = cursor->record(selected);
    if (ImGui::Button("Step iteration")) stepIteration();
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("run the next of this stage's %d iterations (after the stages before it)", iterations);
    ImGui::SameLine();
    if (r.state == StageState::Partial)
      ImGui::Text("iteration %d of %d done", r.iterationsRun, r.iterationsTotal);
    else
      ImGui::TextDisabled("%d iterations", iterations);
  }
  ImGui::TextDisabled("keys: Left/Right stage, R run, A all, I iteration, F5 reload");
  if (runTarget >= 0) ImGui::TextColored(kWarningColour, "running through stage %d ...", runTarget + 1);

  drawParameters();
}

}  // namespace voxlab
