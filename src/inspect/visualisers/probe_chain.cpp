// Probe chain: one record that explains a probed pixel step by step (Semantic::ProbeChain; the
// shared composite declares one). 2D and inspector: the buffer visualiser's. Record view: one
// table per section (surface, direct, indirect, composite) of labelled values with units and 4
// significant digits, the parts of the sum marked "+" and the sum "=", a bar per part showing how
// much of the sum it makes (luminance), and the stored value as the screen shows it (sRGB).
// Check: the parts add up to the sum (sumProbeChain).
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <imgui.h>

#include "inspect/probe_chain.h"
#include "inspect/visualisers/buffer.h"

namespace voxlab {

namespace {

// A measured bound: the parts are summed in double here and in float by the shader, in the same
// order; on the six techniques' test pixels (tests/viewer/probe_chain_*.txt) the worst relative
// difference was 5.3e-8 (float rounding). 1e-5 is 200 times that and still catches any part
// left out or counted twice that makes more than a hundred-thousandth of the sum.
constexpr double kChainSumTolerance = 1e-5;

float luminance(const std::vector<double>& v) {
  if (v.size() < 3) return v.empty() ? 0.0f : float(v[0]);
  return float(0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2]);
}

int srgb8(double linear) {
  const double c = std::clamp(linear, 0.0, 1.0);
  const double s = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
  return int(std::lround(s * 255.0));
}

std::string valuesText(const std::vector<double>& values) {
  if (values.size() == 1) return formatSignificant(values[0]);
  std::string s = "(";
  for (size_t i = 0; i < values.size(); ++i) s += (i ? ", " : "") + formatSignificant(values[i]);
  return s + ")";
}

const char* roleMark(FieldRole role) {
  switch (role) {
    case FieldRole::Addend: return "+";
    case FieldRole::Sum: return "=";
    case FieldRole::Displayed: return "shown";
    default: return "";
  }
}

class ProbeChainVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "probe-chain"; }

  void drawRecordView(const VisualiserContext& ctx) const override {
    const ProbeChain chain = decodeProbeChain(ctx.out);
    const RecordCheck check = checkRecords(ctx.out);
    ImGui::TextWrapped("%s", check.summary.c_str());
    if (!check.error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", check.error.c_str());
    for (const auto& section : chain.sections) {
      if (!ImGui::CollapsingHeader(section.name.c_str(), ImGuiTreeNodeFlags_DefaultOpen)) continue;
      if (!ImGui::BeginTable(section.name.c_str(), 4, ImGuiTableFlags_Borders | ImGuiTableFlags_SizingStretchProp))
        continue;
      ImGui::TableSetupColumn("", ImGuiTableColumnFlags_WidthFixed);
      ImGui::TableSetupColumn("what", ImGuiTableColumnFlags_WidthStretch, 1.0f);
      ImGui::TableSetupColumn("value", ImGuiTableColumnFlags_WidthStretch, 1.0f);
      ImGui::TableSetupColumn("unit", ImGuiTableColumnFlags_WidthFixed);
      ImGui::TableHeadersRow();
      for (const auto& e : section.entries) {
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(roleMark(e.role));
        ImGui::TableNextColumn();
        ImGui::TextWrapped("%s", e.label.c_str());
        ImGui::TableNextColumn();
        ImGui::TextWrapped("%s", valuesText(e.values).c_str());
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(e.unit.c_str());
        if (e.role == FieldRole::Displayed && e.values.size() >= 3) {
          ImGui::TableNextRow();
          ImGui::TableNextColumn();
          ImGui::TableNextColumn();
          ImGui::TextUnformatted("on screen (sRGB-encoded, 0-255)");
          ImGui::TableNextColumn();
          ImGui::Text("(%d, %d, %d)", srgb8(e.values[0]), srgb8(e.values[1]), srgb8(e.values[2]));
          ImGui::TableNextColumn();
        }
      }
      ImGui::EndTable();
    }
    // What the sum is made of: each part's luminance against the total's.
    std::vector<std::string> names;
    std::vector<float> values;
    std::string unit;
    for (const ProbeChainEntry* a : chain.all(FieldRole::Addend)) {
      names.push_back("+ " + a->label);
      values.push_back(luminance(a->values));
      unit = a->unit;
    }
    if (const ProbeChainEntry* total = chain.find(FieldRole::Sum)) {
      names.push_back("= " + total->label);
      values.push_back(luminance(total->values));
    }
    if (!values.empty()) {
      ImGui::Separator();
      ImGui::TextUnformatted("the sum, part by part (luminance)");
      drawValueBars("chain-parts", names, values, unit);
    }
  }

  RecordCheck checkRecords(const CapturedOutput& out) const override {
    const ProbeChain chain = decodeProbeChain(out);
    RecordCheck r;
    for (const auto& s : chain.sections) r.elements += s.entries.size();
    if (r.elements == 0) {
      r.summary = "no chain recorded";
      return r;
    }
    const ProbeChainSum sum = sumProbeChain(chain);
    r.summary = std::to_string(chain.sections.size()) + " sections, " + std::to_string(r.elements) + " values";
    if (!sum.error.empty()) {
      r.error = sum.error;
      return r;
    }
    r.summary += "; the " + std::to_string(chain.all(FieldRole::Addend).size()) + " parts sum to " +
                 valuesText(sum.addends) + ", the recorded sum is " + valuesText(sum.total) + " (relative difference " +
                 formatSignificant(sum.worstRelative, 2) + ")";
    if (sum.worstRelative > kChainSumTolerance)
      r.error = "the parts do not add up to the sum: relative difference " + formatSignificant(sum.worstRelative, 3) +
                " > " + formatSignificant(kChainSumTolerance, 2);
    return r;
  }
};

}  // namespace

VOXLAB_REGISTER_VISUALISER(ProbeChainVisualiser, OutputKind::Buffer, Semantic::ProbeChain.name());

}  // namespace voxlab
