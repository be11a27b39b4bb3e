#include "inspect/visualiser.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>

#include <imgui.h>

#include "core/error.h"
#include "graph/step_cursor.h"
#include "inspect/probe_chain.h"

namespace voxlab {

namespace {

std::map<std::pair<int, std::string>, std::unique_ptr<Visualiser>>& visualisers() {
  static std::map<std::pair<int, std::string>, std::unique_ptr<Visualiser>> m;
  return m;
}

}  // namespace

const Visualiser& visualiserFor(OutputKind kind, Semantic semantic) {
  auto& m = visualisers();
  auto it = m.find({int(kind), semantic.name()});
  if (it == m.end()) it = m.find({int(kind), ""});
  if (it == m.end())
    throw Error(std::string("no visualiser shows ") + kindName(kind) + " outputs (semantic " + semantic.name() +
                "); register one with VOXLAB_REGISTER_VISUALISER");
  return *it->second;
}

bool registerVisualiser(OutputKind kind, const char* semantic, std::unique_ptr<Visualiser> v) {
  registerOutputHandler(kind, semantic, v.get());
  visualisers()[{int(kind), semantic ? semantic : ""}] = std::move(v);
  return true;
}

std::vector<SemanticUse> registeredVisualiserSemantics() {
  std::vector<SemanticUse> uses;
  for (const auto& [key, v] : visualisers())
    if (!key.second.empty()) uses.push_back({OutputKind(key.first), key.second, v->name()});
  return uses;
}

std::vector<std::string> semanticMismatches(const std::vector<SemanticUse>& declared,
                                            const std::vector<SemanticUse>& registered) {
  std::vector<std::string> problems;
  auto same = [](const SemanticUse& a, const SemanticUse& b) { return a.kind == b.kind && a.semantic == b.semantic; };
  for (const SemanticUse& r : registered)
    if (std::none_of(declared.begin(), declared.end(), [&](const SemanticUse& d) { return same(d, r); }))
      problems.push_back(std::string("visualiser ") + r.where + " is registered for " + kindName(r.kind) +
                         " outputs of semantic \"" + r.semantic + "\", which no output declares");
  for (const SemanticUse& d : declared) {
    if (std::any_of(registered.begin(), registered.end(), [&](const SemanticUse& r) { return same(d, r); })) continue;
    for (const SemanticUse& r : registered)
      if (r.semantic == d.semantic) {
        problems.push_back("output " + d.where + " (" + kindName(d.kind) + ", semantic \"" + d.semantic +
                           "\") gets the generic view: its visualiser " + r.where + " shows " + kindName(r.kind) +
                           " outputs");
        break;
      }
  }
  return problems;
}

void Visualiser::drawRecordView(const VisualiserContext& ctx) const {
  ImGui::Text("%u records", ctx.out.recordCount);
  drawRecordsTable("probe-records", ctx.records, 240.0f);
}

RecordCheck Visualiser::checkRecords(const CapturedOutput& out) const {
  RecordCheck c;
  c.elements = out.recordCount;
  c.summary = std::to_string(out.recordCount) + " records";
  return c;
}

void drawStatisticsTable(const char* id, const nlohmann::json& stats) {
  if (!stats.is_object() || stats.empty()) return;
  auto text = [](const nlohmann::json& v) {
    char buf[48];
    if (v.is_number()) {
      std::snprintf(buf, sizeof buf, "%.6g", v.get<double>());
      return std::string(buf);
    }
    if (v.is_array()) {
      std::string s;
      for (const auto& e : v) {
        if (e.is_number()) std::snprintf(buf, sizeof buf, "%.4g", e.get<double>());
        else std::snprintf(buf, sizeof buf, "%s", e.dump().c_str());
        s += (s.empty() ? "" : ", ") + std::string(buf);
      }
      return s;
    }
    return v.is_string() ? v.get<std::string>() : v.dump();
  };
  if (ImGui::BeginTable(id, 2, ImGuiTableFlags_Borders | ImGuiTableFlags_SizingStretchProp)) {
    for (auto it = stats.begin(); it != stats.end(); ++it) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(it.key().c_str());
      ImGui::TableNextColumn();
      ImGui::TextWrapped("%s", text(it.value()).c_str());
    }
    ImGui::EndTable();
  }
}

void drawRecordsTable(const char* id, const nlohmann::json& recs, float height) {
  if (!recs.is_array() || recs.empty() || !recs[0].is_object()) return;
  int cols = int(recs[0].size()) + 1;
  // Dear ImGui tables hold at most 64 columns: a record with more fields (lpv's probe record: 84)
  // is drawn transposed, one row per field and one column per record (the first 63 records).
  if (cols > 64) {
    const int shown = int(std::min<size_t>(recs.size(), 63));
    if (shown < int(recs.size())) ImGui::TextDisabled("first %d of %zu records", shown, recs.size());
    if (!ImGui::BeginTable(id, shown + 1,
                           ImGuiTableFlags_Borders | ImGuiTableFlags_ScrollY | ImGuiTableFlags_ScrollX |
                               ImGuiTableFlags_SizingFixedFit,
                           ImVec2(0, height)))
      return;
    ImGui::TableSetupColumn("field");
    for (int r = 0; r < shown; ++r) ImGui::TableSetupColumn(std::to_string(r).c_str());
    ImGui::TableHeadersRow();
    for (auto it = recs[0].begin(); it != recs[0].end(); ++it) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(it.key().c_str());
      for (int r = 0; r < shown; ++r) {
        ImGui::TableNextColumn();
        auto v = recs[size_t(r)].find(it.key());
        if (v != recs[size_t(r)].end()) ImGui::TextUnformatted(formatRecordValue(*v).c_str());
      }
    }
    ImGui::EndTable();
    return;
  }
  if (!ImGui::BeginTable(id, cols,
                         ImGuiTableFlags_Borders | ImGuiTableFlags_ScrollY | ImGuiTableFlags_ScrollX |
                             ImGuiTableFlags_SizingFixedFit,
                         ImVec2(0, height)))
    return;
  ImGui::TableSetupColumn("#");
  for (auto it = recs[0].begin(); it != recs[0].end(); ++it) ImGui::TableSetupColumn(it.key().c_str());
  ImGui::TableHeadersRow();
  for (size_t r = 0; r < recs.size(); ++r) {
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    ImGui::Text("%zu", r);
    for (auto it = recs[r].begin(); it != recs[r].end(); ++it) {
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(formatRecordValue(it.value()).c_str());
    }
  }
  ImGui::EndTable();
}

std::function<bool(CapturedOutput&, std::string&)> contextVolumeLookup(StepCursor& cursor, int selected) {
  return [&cursor, selected](CapturedOutput& out, std::string& name) {
    const Technique& t = cursor.technique();
    for (int i = selected - 1; i >= 0; --i) {
      if (cursor.record(i).state == StageState::NotRun) continue;
      for (const auto& o : t.decl(i).outputs)
        if (o.kind == OutputKind::Volume3D && cursor.outputHeld(i, o.name)) {
          try {
            out = captureOutput(cursor.board(), o);
          } catch (const Error&) {
            continue;
          }
          if (out.levels.empty()) continue;
          name = std::string(t.stage(i).id()) + "/" + o.name;
          return true;
        }
    }
    return false;
  };
}

std::function<bool(const char*, CapturedOutput&)> contextOutputLookup(StepCursor& cursor, int selected) {
  return [&cursor, selected](const char* what, CapturedOutput& out) {
    const Technique& t = cursor.technique();
    for (bool byName : {false, true})
      for (int i = selected; i >= 0; --i) {
        if (cursor.record(i).state == StageState::NotRun) continue;
        for (const auto& o : t.decl(i).outputs)
          if ((byName ? o.name == what : std::strcmp(o.semantic.name(), what) == 0) && cursor.outputHeld(i, o.name)) {
            try {
              out = captureOutput(cursor.board(), o);
              return true;
            } catch (const Error&) {
            }
          }
      }
    return false;
  };
}

void drawAxesPlot(const char* id, const std::vector<float>& xs, const std::vector<float>& ys, const std::string& xAxis,
                  const std::string& yAxis, float yLo, float yHi, float height) {
  const size_t n = std::min(xs.size(), ys.size());
  ImGui::PushID(id);
  if (n == 0) {
    ImGui::TextDisabled("%s: no values", yAxis.c_str());
    ImGui::PopID();
    return;
  }
  float lo = yLo, hi = yHi;
  if (std::isnan(lo)) lo = *std::min_element(ys.begin(), ys.begin() + long(n));
  if (std::isnan(hi)) hi = *std::max_element(ys.begin(), ys.begin() + long(n));
  if (!(hi > lo)) hi = lo + (lo == 0.0f ? 1.0f : std::fabs(lo));
  const float x0 = xs.front(), x1 = n > 1 && xs[n - 1] > xs.front() ? xs[n - 1] : xs.front() + 1.0f;
  const std::string loText = formatSignificant(lo, 3), hiText = formatSignificant(hi, 3);
  const float margin = std::max(ImGui::CalcTextSize(loText.c_str()).x, ImGui::CalcTextSize(hiText.c_str()).x) + 6.0f;
  const float line = ImGui::GetTextLineHeight();
  ImGui::TextUnformatted(yAxis.c_str());
  const ImVec2 at = ImGui::GetCursorScreenPos();
  const float width = std::max(ImGui::GetContentRegionAvail().x - margin, 80.0f);
  ImGui::InvisibleButton("plot", ImVec2(margin + width, height + line + 2.0f));
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImVec2 p0(at.x + margin, at.y), p1(at.x + margin + width, at.y + height);
  const ImU32 axis = ImGui::GetColorU32(ImGuiCol_TextDisabled), text = ImGui::GetColorU32(ImGuiCol_Text);
  dl->AddRectFilled(p0, p1, ImGui::GetColorU32(ImGuiCol_FrameBg));
  dl->AddLine(ImVec2(p0.x, p0.y), ImVec2(p0.x, p1.y), axis);
  dl->AddLine(ImVec2(p0.x, p1.y), ImVec2(p1.x, p1.y), axis);
  dl->AddText(ImVec2(at.x, p0.y), text, hiText.c_str());
  dl->AddText(ImVec2(at.x, p1.y - line), text, loText.c_str());
  const std::string xLo = formatSignificant(x0, 3), xHi = formatSignificant(x1, 3);
  dl->AddText(ImVec2(p0.x, p1.y + 1.0f), text, xLo.c_str());
  dl->AddText(ImVec2(p1.x - ImGui::CalcTextSize(xHi.c_str()).x, p1.y + 1.0f), text, xHi.c_str());
  dl->AddText(ImVec2(0.5f * (p0.x + p1.x) - 0.5f * ImGui::CalcTextSize(xAxis.c_str()).x, p1.y + 1.0f), axis,
              xAxis.c_str());
  auto toScreen = [&](size_t i) {
    const float fx = (xs[i] - x0) / (x1 - x0), fy = (std::clamp(ys[i], lo, hi) - lo) / (hi - lo);
    return ImVec2(p0.x + fx * width, p1.y - fy * height);
  };
  for (size_t i = 0; i + 1 < n; ++i) dl->AddLine(toScreen(i), toScreen(i + 1), ImGui::GetColorU32(ImGuiCol_PlotLines), 1.5f);
  for (size_t i = 0; i < n; ++i) dl->AddCircleFilled(toScreen(i), 2.0f, ImGui::GetColorU32(ImGuiCol_PlotLines));
  if (ImGui::IsItemHovered()) {
    const float mx = ImGui::GetIO().MousePos.x;
    size_t best = 0;
    for (size_t i = 1; i < n; ++i)
      if (std::fabs(toScreen(i).x - mx) < std::fabs(toScreen(best).x - mx)) best = i;
    dl->AddCircle(toScreen(best), 4.0f, text);
    ImGui::SetTooltip("%s %s, %s %s", xAxis.c_str(), formatSignificant(xs[best]).c_str(), yAxis.c_str(),
                      formatSignificant(ys[best]).c_str());
  }
  ImGui::PopID();
}

void drawValueBars(const char* id, const std::vector<std::string>& names, const std::vector<float>& values,
                   const std::string& unit) {
  ImGui::PushID(id);
  float top = 0.0f;
  for (float v : values) top = std::max(top, v);
  if (!(top > 0.0f)) top = 1.0f;
  float labelWidth = 0.0f;
  for (const auto& name : names) labelWidth = std::max(labelWidth, ImGui::CalcTextSize(name.c_str()).x);
  labelWidth = std::min(labelWidth + 8.0f, 0.5f * ImGui::GetContentRegionAvail().x);
  const float line = ImGui::GetTextLineHeightWithSpacing();
  const float width = std::max(ImGui::GetContentRegionAvail().x - labelWidth, 80.0f);
  const ImVec2 at = ImGui::GetCursorScreenPos();
  const size_t n = std::min(names.size(), values.size());
  ImGui::Dummy(ImVec2(labelWidth + width, line * float(n + 1)));
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImU32 text = ImGui::GetColorU32(ImGuiCol_Text), axis = ImGui::GetColorU32(ImGuiCol_TextDisabled);
  for (size_t i = 0; i < n; ++i) {
    const float y = at.y + line * float(i);
    dl->PushClipRect(ImVec2(at.x, y), ImVec2(at.x + labelWidth - 4.0f, y + line), true);
    dl->AddText(ImVec2(at.x, y), text, names[i].c_str());
    dl->PopClipRect();
    const float w = std::max(values[i], 0.0f) / top * width;
    dl->AddRectFilled(ImVec2(at.x + labelWidth, y + 2.0f), ImVec2(at.x + labelWidth + w, y + line - 2.0f),
                      ImGui::GetColorU32(ImGuiCol_PlotHistogram));
    const std::string v = formatSignificant(values[i]);
    dl->AddText(ImVec2(at.x + labelWidth + std::min(w + 4.0f, width - ImGui::CalcTextSize(v.c_str()).x), y), text,
                v.c_str());
  }
  const float y = at.y + line * float(n);
  dl->AddLine(ImVec2(at.x + labelWidth, y), ImVec2(at.x + labelWidth + width, y), axis);
  dl->AddText(ImVec2(at.x + labelWidth, y), axis, "0");
  const std::string hi = formatSignificant(top) + (unit.empty() ? "" : " " + unit);
  dl->AddText(ImVec2(at.x + labelWidth + width - ImGui::CalcTextSize(hi.c_str()).x, y), axis, hi.c_str());
  ImGui::PopID();
}

}  // namespace voxlab
