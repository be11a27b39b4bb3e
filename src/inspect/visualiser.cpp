#include "inspect/visualiser.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <map>

#include <imgui.h>

#include "core/error.h"
#include "graph/step_cursor.h"

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
        if (v != recs[size_t(r)].end()) ImGui::TextUnformatted(v->dump().c_str());
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
      ImGui::TextUnformatted(it.value().dump().c_str());
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
        if (o.kind == OutputKind::Volume3D) {
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
          if (byName ? o.name == what : std::strcmp(o.semantic.name(), what) == 0) {
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

}  // namespace voxlab
