// Left panel: technique and scene pickers, the stage timeline (state, queue, iterations) and the
// run buttons; the parameters below it are panel_parameters.cpp.
#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "core/args.h"
#include "core/paths.h"
#include "inspect/script_verbs.h"
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
  if (!sceneError.empty()) {  // wrapped: a path and its reason are often wider than the panel
    ImGui::PushStyleColor(ImGuiCol_Text, kErrorColour);
    ImGui::TextWrapped("%s", sceneError.c_str());
    ImGui::PopStyleColor();
  }

  // Stage timeline.
  ImGui::Separator();
  ImGui::TextUnformatted("Stages");
  // Outputs on demand: a stage neither the final image nor anything shown depends on does not run.
  const std::vector<StagePlan> plan = cursor->plan();
  for (int i = 0; i < t.stageCount(); ++i) {
    const StageRecord& r = cursor->record(i);
    ImVec4 col = r.state == StageState::Done    ? ImVec4(0.4f, 0.9f, 0.4f, 1)
                 : r.state == StageState::Stale ? kWarningColour
                                                : ImVec4(0.6f, 0.6f, 0.6f, 1);
    bool running = (runs.target >= i && plan[size_t(i)].needed && r.state != StageState::Done) || runs.iterateStage == i;
    char state[48];
    if (r.state == StageState::Partial)
      std::snprintf(state, sizeof state, "partial %d/%d", r.iterationsRun, r.iterationsTotal);
    else if (!running && r.state == StageState::NotRun && !plan[size_t(i)].needed)
      std::snprintf(state, sizeof state, "not needed");
    else
      std::snprintf(state, sizeof state, "%s", running ? "(queued)" : stageStateName(r.state));
    // The stages the shown frame of the Frames tab re-ran: marked and drawn in the frame colour.
    const bool reran = frameReran(i);
    if (reran) col = kFrameRerunColour;
    char label[160];
    std::snprintf(label, sizeof label, "%d. %-14s %s%s##stage%d", i + 1, t.stage(i).id(), state,
                  reran ? "  re-ran" : "", i);
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
  if (frames.frame >= 0)
    ImGui::TextColored(kFrameRerunColour, "frame %d of %d: %zu stages re-ran (Frames tab)", frames.frame + 1,
                       frames.count, frames.reran.size());
  if (runs.target >= 0) ImGui::TextColored(kWarningColour, "running through stage %d ...", runs.target + 1);

  drawParameters();
}

// --- Script verbs: technique, scene, stage selection and runs ------------------------------------

namespace {

void expectStat(Viewer& viewer, const ScriptCall& call) {
  const auto& stats = viewer.cursor->record(viewer.cursor->technique().stageIndex(call.arg(0))).stats;
  auto it = stats.find(call.arg(1));
  if (it == stats.end()) call.fail("stage " + call.arg(0) + " has no statistic '" + call.arg(1) + "' (it may not have run)");
  const double got = it->second, want = call.floatArg(3);
  const std::string& op = call.arg(2);
  bool ok = false;
  if (op == "=") ok = got == want;
  else if (op == "<") ok = got < want;
  else if (op == ">") ok = got > want;
  else if (op == "<=") ok = got <= want;
  else if (op == ">=") ok = got >= want;
  else call.badArgument("unknown comparison '" + op + "'; valid: = < > <= >=");
  if (!ok) call.fail(call.arg(0) + " " + call.arg(1) + " is " + std::to_string(got) + ", expected " + op + " " + call.arg(3));
}

void expectIterations(Viewer& viewer, const ScriptCall& call) {
  const StageRecord& r = viewer.cursor->record(viewer.cursor->technique().stageIndex(call.arg(0)));
  const int want = call.intArg(1);
  if (r.iterationsRun != want || (r.state != StageState::Partial && r.state != StageState::Done))
    call.fail(call.arg(0) + " is " + stageStateName(r.state) + " after " + std::to_string(r.iterationsRun) + " of " +
              std::to_string(r.iterationsTotal) + " iterations, expected " + call.arg(1));
  std::printf("%s: %d of %d iterations (%s)\n", call.arg(0).c_str(), r.iterationsRun, r.iterationsTotal,
              stageStateName(r.state));
}

}  // namespace

VOXLAB_REGISTER_SCRIPT_VERBS(timeline, 10,
  {"technique", 1, 1, "technique ID",
   [](Viewer& viewer, const ScriptCall& call) {
     if (call.arg(0) != viewer.cursor->technique().id()) viewer.switchTechnique(call.arg(0));
   }},
  {"scene", 1, 1, "scene NAME|PATH (a failed load keeps the current scene and records the error)",
   [](Viewer& viewer, const ScriptCall& call) {
     if (!viewer.loadSceneNamed(call.arg(0))) std::printf("scene error: %s\n", viewer.sceneError.c_str());
   }},
  {"drop", 1, 1, "drop PATH (as dropping a glTF/GLB file on the window: a failed load keeps the current scene)",
   [](Viewer& viewer, const ScriptCall& call) {
     if (!viewer.dropFile(call.arg(0))) std::printf("scene error: %s\n", viewer.sceneError.c_str());
   }},
  {"expect-scene", 1, 1, "expect-scene NAME (the current scene is NAME, its file's stem)",
   [](Viewer& viewer, const ScriptCall& call) {
     if (viewer.scene->name != call.arg(0)) call.fail("scene is " + viewer.scene->name + ", expected " + call.arg(0));
   }},
  {"expect-scene-error", 1, 32, "expect-scene-error TEXT... (the last scene error contains TEXT)",
   [](Viewer& viewer, const ScriptCall& call) {
     const std::string text = call.text();
     if (viewer.sceneError.empty() || viewer.sceneError.find(text) == std::string::npos)
       call.fail("last scene error is '" + viewer.sceneError + "', expected it to contain '" + text + "'");
   }},
  {"stage", 1, 1, "stage ID (select it)",
   [](Viewer& viewer, const ScriptCall& call) {
     viewer.selectStage(viewer.cursor->technique().stageIndex(call.arg(0)));
   }},
  {"output", 1, 1, "output NAME (of the selected stage)",
   [](Viewer& viewer, const ScriptCall& call) { viewer.selectOutput(call.arg(0)); }},
  {"size", 1, 1, "size WxH (render size)",
   [](Viewer& viewer, const ScriptCall& call) {
     Args::parseSize(call.arg(0), viewer.opt.width, viewer.opt.height);
     viewer.cursor->setViewSize(viewer.opt.width, viewer.opt.height);
     viewer.paramsChanged();
   }},
  {"run", 0, 0, "run (to the selected stage)", [](Viewer& viewer, const ScriptCall&) { viewer.runSelected(); }},
  {"runall", 0, 0, "runall", [](Viewer& viewer, const ScriptCall&) { viewer.runAll(); }},
  {"next", 0, 0, "next (run and select the next stage)",
   [](Viewer& viewer, const ScriptCall&) {
     viewer.selectStage(viewer.selected + 1);
     viewer.runSelected();
   }},
  {"prev", 0, 0, "prev (select the previous stage)",
   [](Viewer& viewer, const ScriptCall&) { viewer.selectStage(viewer.selected - 1); }},
  {"iterate", 0, 0, "iterate (one more iteration of the selected stage, as Step iteration)",
   [](Viewer& viewer, const ScriptCall& call) {
     if (viewer.cursor->iterations(viewer.selected) <= 1)
       call.fail(std::string("stage ") + viewer.cursor->technique().stage(viewer.selected).id() + " is not iterative");
     viewer.stepIteration();
   }},
  {"expect-iterations", 2, 2, "expect-iterations STAGE N (N of STAGE's iterations have run)", expectIterations},
  {"expect-state", 2, 2,
   "expect-state STAGE done|stale|not-run|not-needed (not-needed: not run, and neither the final image nor anything "
   "shown depends on it)",
   [](Viewer& viewer, const ScriptCall& call) {
     const int i = viewer.cursor->technique().stageIndex(call.arg(0));
     const bool notRun = viewer.cursor->record(i).state == StageState::NotRun;
     std::string got = stageStateName(viewer.cursor->record(i).state);
     if (notRun && !viewer.cursor->plan()[size_t(i)].needed) got = "not needed";
     const std::string want = call.arg(1) == "not-run" ? "not run" : call.arg(1) == "not-needed" ? "not needed" : call.arg(1);
     if (got != want && !(want == "not run" && notRun)) call.fail("stage " + call.arg(0) + " is " + got + ", expected " + want);
   }},
  {"expect-computed", 3, 3,
   "expect-computed STAGE OUTPUT yes|no (the last run of STAGE computed OUTPUT: an output on demand is computed only "
   "while something shown needs it)",
   [](Viewer& viewer, const ScriptCall& call) {
     const int i = viewer.cursor->technique().stageIndex(call.arg(0));
     viewer.cursor->technique().findOutput(call.arg(0), call.arg(1));  // throws naming the valid ones
     const bool want = call.arg(2) == "yes";
     if (!want && call.arg(2) != "no") call.badArgument("expected yes or no, not '" + call.arg(2) + "'");
     const bool got = viewer.cursor->outputComputed(i, call.arg(1));
     if (got != want)
       call.fail(call.arg(0) + "/" + call.arg(1) + (got ? " was computed" : " was not computed") + " by the last run of " +
                 call.arg(0) + " (" + stageStateName(viewer.cursor->record(i).state) + ")");
   }},
  {"expect-stat", 4, 4, "expect-stat STAGE NAME =|<|>|<=|>= VALUE (a statistic of the stage's last run)", expectStat},
  {"auto-rerun", 1, 1, "auto-rerun on|off (re-run stale stages after a change, as the checkbox)",
   [](Viewer& viewer, const ScriptCall& call) { viewer.runs.autoRerun = call.onOff(0); }});

}  // namespace voxlab
