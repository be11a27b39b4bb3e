// Parameter widgets, generated from the ParamDescs of every stage (grouped by stage, the selected
// one open); a change marks what it invalidates stale and, with auto re-run, runs it again.
#include <cstdio>

#include "core/error.h"
#include "inspect/script_verbs.h"
#include "inspect/viewer_state.h"

namespace voxlab {

void Viewer::drawParameters() {
  Technique& t = cursor->technique();
  // Parameters, generated from the declarations of every stage.
  ImGui::Separator();
  ImGui::Checkbox("auto re-run", &runs.autoRerun);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("after a change, re-run the stale stages up to the last run one");
  ImGui::SameLine();
  if (ImGui::Button("Defaults")) applyParams(t.defaultParams());
  // What the current parameters allocate against the budget, and the last change refused for it.
  {
    const ResourceEstimate e = cursor->resourceEstimate();
    const size_t budget = size_t(cursor->params().getInt(memoryBudgetParam().name)) << 20;
    ImGui::TextDisabled("GPU memory %s of %s (%s)", formatBytes(e.totalBytes).c_str(), formatBytes(budget).c_str(),
                        memoryBudgetParam().name.c_str());
    if (!budgetRefusal.empty()) {
      ImGui::PushStyleColor(ImGuiCol_Text, kWarningColour);
      ImGui::TextWrapped("not applied: %s", budgetRefusal.c_str());
      ImGui::PopStyleColor();
    }
  }
  ImGui::BeginChild("params", ImVec2(0, 0), false);
  for (int i = 0; i < t.stageCount(); ++i) {
    const auto& decl = t.decl(i);
    if (decl.params.empty()) continue;
    bool open = ImGui::TreeNodeEx(t.stage(i).id(), i == selected ? ImGuiTreeNodeFlags_DefaultOpen : 0);
    if (!open) continue;
    for (size_t pi = 0; pi < decl.params.size(); ++pi) {
      const ParamDesc& p = decl.params[pi];
      // A vector parameter (NAME.x, .y, .z declared in a row, plain floats; ParamSet::vectorComponents)
      // is one row of three fields named NAME, as `--set NAME=X,Y,Z` takes it.
      const std::string base = p.name.size() > 2 ? p.name.substr(0, p.name.size() - 2) : std::string();
      const auto parts = p.name.size() > 2 && p.name.compare(p.name.size() - 2, 2, ".x") == 0
                             ? cursor->params().vectorComponents(base)
                             : std::vector<std::string>{};
      if (parts.size() == 3 && pi + 2 < decl.params.size() && decl.params[pi + 1].name == parts[1] &&
          decl.params[pi + 2].name == parts[2] && !p.sceneDefault && p.type == ParamType::Float &&
          decl.params[pi + 1].type == ParamType::Float && decl.params[pi + 2].type == ParamType::Float &&
          !decl.params[pi + 1].sceneDefault && !decl.params[pi + 2].sceneDefault) {
        ImGui::PushID((std::to_string(i) + base).c_str());
        float v[3], was[3];
        for (int c = 0; c < 3; ++c) v[c] = was[c] = float(cursor->params().value(parts[size_t(c)]));
        float lo = float(p.minValue), hi = float(p.maxValue);
        if (ImGui::DragFloat3(base.c_str(), v, 0.01f, lo, hi, "%.3f")) {
          for (int c = 0; c < 3; ++c)
            if (v[c] != was[c]) setParam(parts[size_t(c)], double(v[c]));
        }
        if (ImGui::IsItemHovered())
          ImGui::SetTooltip("%s\nx, y, z: %s%s%s (drag, or Ctrl+click to type)", p.help.c_str(), p.rangeText().c_str(),
                            p.unit.empty() ? "" : ", ", p.unit.c_str());
        ImGui::PopID();
        pi += 2;
        continue;
      }
      ImGui::PushID((std::to_string(i) + p.name).c_str());
      double v = cursor->params().value(p.name);
      double nv = v;
      switch (p.type) {
        case ParamType::Int: {
          int iv = int(v);
          if (ImGui::SliderInt(p.name.c_str(), &iv, int(p.minValue), int(p.maxValue))) {
            if (p.powerOfTwo) {
              int k = 1;
              while (k < iv) k <<= 1;
              iv = (k - iv <= iv - k / 2) ? k : k / 2;
              iv = std::clamp(iv, int(p.minValue), int(p.maxValue));
            }
            nv = iv;
          }
          break;
        }
        case ParamType::Float: {
          // A "scene" value (NaN) shows as the text "scene" until the slider is moved.
          bool fromScene = p.sceneDefault && ParamDesc::isSceneValue(v);
          float fv = fromScene ? float(p.minValue) : float(v);
          if (ImGui::SliderFloat(p.name.c_str(), &fv, float(p.minValue), float(p.maxValue), fromScene ? "scene" : "%.3f")) nv = fv;
          break;
        }
        case ParamType::Bool: {
          bool b = v != 0.0;
          if (ImGui::Checkbox(p.name.c_str(), &b)) nv = b ? 1.0 : 0.0;
          break;
        }
        case ParamType::Choice: {
          int c = int(v);
          if (ImGui::BeginCombo(p.name.c_str(), p.choices.at(c).c_str())) {
            for (size_t k = 0; k < p.choices.size(); ++k)
              if (ImGui::Selectable(p.choices[k].c_str(), int(k) == c)) nv = double(k);
            ImGui::EndCombo();
          }
          break;
        }
      }
      if (ImGui::IsItemHovered())
        ImGui::SetTooltip("%s\n%s%s%s", p.help.c_str(), p.rangeText().c_str(), p.unit.empty() ? "" : ", ",
                          p.unit.c_str());
      if (!ParamDesc::sameValue(nv, v)) setParam(p.name, nv);  // marks every stage that declares it (and its readers) stale
      ImGui::PopID();
    }
    ImGui::TreePop();
  }
  ImGui::EndChild();
}

// --- Script verbs: parameters ----------------------------------------------------------------------

VOXLAB_REGISTER_SCRIPT_VERBS(parameters, 20,
  {"set", 1, 1, "set NAME=VALUE",
   [](Viewer& viewer, const ScriptCall& call) {
     const std::string& s = call.arg(0);
     const size_t eq = s.find('=');
     if (eq == std::string::npos) call.badArgument("expected NAME=VALUE");
     ParamSet candidate = viewer.cursor->params();
     candidate.setText(s.substr(0, eq), s.substr(eq + 1));
     if (!viewer.applyParams(candidate)) std::printf("%s\n", viewer.status.c_str());
   }},
  {"reset-params", 0, 0, "reset-params",
   [](Viewer& viewer, const ScriptCall&) { viewer.applyParams(viewer.cursor->technique().defaultParams()); }},
  {"expect-refusal", 1, 32,
   "expect-refusal TEXT... (the last parameter change was refused for the resource budget and its line contains "
   "TEXT; the parameters stayed as they were)",
   [](Viewer& viewer, const ScriptCall& call) {
     const std::string text = call.text();
     if (viewer.budgetRefusal.empty() || viewer.budgetRefusal.find(text) == std::string::npos)
       call.fail("last parameter change refusal is '" + viewer.budgetRefusal + "', expected it to contain '" + text + "'");
     std::printf("refused: %s\n", viewer.budgetRefusal.c_str());
   }},
  {"expect-param", 2, 2, "expect-param NAME VALUE",
   [](Viewer& viewer, const ScriptCall& call) {
     const ParamSet& params = viewer.cursor->params();
     const std::string got = params.desc(call.arg(0)).format(params.value(call.arg(0)));
     if (got != call.arg(1)) call.fail(call.arg(0) + " is " + got + ", expected " + call.arg(1));
   }});

}  // namespace voxlab
