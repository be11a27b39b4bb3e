// The generic probe. Stages declare probe parameters in screen space (a pixel of the camera
// images), volume space (a cell of a volume at a level) or light space (a texel of a light-space
// image), and probe-record outputs (StageBuilder::probe, OutputDesc::probeRecord). A click on an
// image of one of those spaces sets the matching parameters of every stage that declares them and
// queues what went stale; the Probe tab shows every probe record through its visualiser's record
// view. Nothing here names a stage, a parameter or a semantic.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "inspect/script_verbs.h"
#include "inspect/viewer_state.h"

namespace voxlab {

std::vector<std::pair<int, const ProbeDesc*>> Viewer::probesFor(ProbeSpace space, const std::string& resource) const {
  std::vector<std::pair<int, const ProbeDesc*>> found;
  const Technique& t = cursor->technique();
  for (int i = 0; i < t.stageCount(); ++i)
    for (const auto& p : t.decl(i).probes) {
      if (p.space != space) continue;
      if (space == ProbeSpace::Volume && !p.resource.empty() && p.resource != resource) continue;
      if (space == ProbeSpace::Light && p.resource != resource) continue;
      found.emplace_back(i, &p);
    }
  return found;
}

bool Viewer::hasProbes() const {
  const Technique& t = cursor->technique();
  for (int i = 0; i < t.stageCount(); ++i)
    if (!t.decl(i).probes.empty()) return true;
  return false;
}

std::vector<ProbeSpace> Viewer::probeSpacesOfShown() const {
  std::vector<ProbeSpace> spaces;
  if (!capError.empty()) return spaces;
  const std::string& resource = cap.desc.resourceName();
  if (isCameraImage(selected, cap) && !probesFor(ProbeSpace::Screen, "").empty()) spaces.push_back(ProbeSpace::Screen);
  if (cap.desc.kind == OutputKind::Volume3D && !probesFor(ProbeSpace::Volume, resource).empty())
    spaces.push_back(ProbeSpace::Volume);
  if (cap.desc.kind == OutputKind::Image2D && !probesFor(ProbeSpace::Light, resource).empty())
    spaces.push_back(ProbeSpace::Light);
  return spaces;
}

int Viewer::probeShownAt(const glm::ivec3& texel, int level) {
  if (cap.levels.empty()) return 0;
  level = std::clamp(level, 0, int(cap.levels.size()) - 1);
  const glm::ivec3 size = cap.levels[level].size;
  const ParamSet& ps = cursor->params();
  // A parameter takes the value clamped to its declared range.
  auto set = [&](const std::string& name, double value) {
    const ParamDesc& d = ps.desc(name);
    setParam(name, std::clamp(value, d.minValue, d.maxValue));
  };
  int probed = 0, last = -1;
  for (ProbeSpace space : probeSpacesOfShown())
    for (auto [stage, p] : probesFor(space, cap.desc.resourceName())) {
      if (space == ProbeSpace::Volume) {
        // Without a level parameter the probe means level-0 cells: the centre cell of the clicked
        // texel's footprint (a level-L texel covers size0 / sizeL cells per axis).
        glm::ivec3 cell = texel;
        if (p->level.empty() && level > 0) {
          const glm::ivec3 span = cap.levels[0].size / glm::max(size, glm::ivec3(1));
          cell = texel * span + span / 2;
        }
        set(p->x, cell.x);
        set(p->y, cell.y);
        set(p->z, cell.z);
        if (!p->level.empty()) set(p->level, level);
      } else {
        // Fractions of the image, y from the top (image rows are stored bottom-up).
        set(p->x, (texel.x + 0.5) / size.x);
        set(p->y, (size.y - 1 - texel.y + 0.5) / size.y);
      }
      ++probed;
      last = std::max(last, stage);
    }
  if (probed == 0) return 0;
  requestRun(std::max(last, std::max(selected, runs.lastRequest)));
  char buf[160];
  if (size.z > 1)
    std::snprintf(buf, sizeof buf, "probed cell (%d, %d, %d) at level %d: %d probe(s)", texel.x, texel.y, texel.z, level, probed);
  else
    std::snprintf(buf, sizeof buf, "probed pixel %d,%d: %d probe(s)", texel.x, size.y - 1 - texel.y, probed);
  status = buf;
  wantTab = "probe";
  return probed;
}

void Viewer::probePixel(int x, int y) {
  auto screen = probesFor(ProbeSpace::Screen, "");
  if (screen.empty()) throw Error("technique " + cursor->technique().id() + " has no stage that declares a screen-space probe");
  const ViewState& v = cursor->view();
  x = std::clamp(x, 0, v.width - 1);
  y = std::clamp(y, 0, v.height - 1);
  int last = -1;
  for (auto [stage, p] : screen) {
    setParam(p->x, (x + 0.5) / v.width);
    setParam(p->y, (y + 0.5) / v.height);
    last = std::max(last, stage);
  }
  requestRun(std::max(last, std::max(selected, runs.lastRequest)));
  status = "probed pixel " + std::to_string(x) + "," + std::to_string(y);
  wantTab = "probe";
}

const std::vector<ProbeRecords>& Viewer::probeRecords() {
  if (probes.cacheKey == generation) return probes.cache;
  probes.cacheKey = generation;
  probes.cache.clear();
  const Technique& t = cursor->technique();
  for (int i = 0; i < t.stageCount(); ++i) {
    if (t.decl(i).probes.empty()) continue;
    for (const auto& o : t.decl(i).outputs) {
      if (!o.probeRecord) continue;
      ProbeRecords r;
      r.stage = i;
      r.desc = &o;
      r.out.desc = o;
      if (cursor->record(i).state == StageState::NotRun) {
        r.error = std::string("stage ") + t.stage(i).id() + " has not run yet";
      } else {
        try {
          r.out = captureOutput(cursor->board(), o);
          r.records = o.kind == OutputKind::Buffer ? recordsJson(r.out, 32) : nlohmann::json();
        } catch (const Error& e) {
          r.error = e.what();
        }
      }
      probes.cache.push_back(std::move(r));
    }
  }
  return probes.cache;
}

void Viewer::drawProbe() {
  const Technique& t = cursor->technique();
  const ParamSet& ps = cursor->params();
  // Where every probe points now.
  for (int i = 0; i < t.stageCount(); ++i)
    for (const auto& p : t.decl(i).probes) {
      char where[160];
      if (p.space == ProbeSpace::Volume) {
        std::snprintf(where, sizeof where, "cell (%d, %d, %d)", ps.getInt(p.x), ps.getInt(p.y), ps.getInt(p.z));
        std::string s = where;
        if (!p.level.empty()) s += " at level " + std::to_string(ps.getInt(p.level));
        std::snprintf(where, sizeof where, "%s", s.c_str());
      } else if (p.space == ProbeSpace::Screen) {
        std::snprintf(where, sizeof where, "pixel (%.0f, %.0f) of %dx%d", ps.value(p.x) * cursor->view().width - 0.5,
                      ps.value(p.y) * cursor->view().height - 0.5, cursor->view().width, cursor->view().height);
      } else {
        std::snprintf(where, sizeof where, "texel at (%.3f, %.3f) of %s", ps.value(p.x), ps.value(p.y), p.resource.c_str());
      }
      ImGui::Text("%s: %s probe, %s", t.stage(i).id(), probeSpaceName(p.space), where);
    }
  ImGui::TextDisabled("click a camera image (final, G-buffer, ...), a volume slice or a light-space image to probe");
  ImGui::BeginChild("probe-records");
  for (const auto& r : probeRecords()) {
    ImGui::Separator();
    ImGui::TextColored(ImVec4(0.6f, 0.8f, 1.0f, 1), "%s/%s", t.stage(r.stage).id(), r.desc->name.c_str());
    if (!r.error.empty()) {
      ImGui::TextWrapped("%s", r.error.c_str());
      continue;
    }
    const Visualiser& vis = visualiserFor(r.out.desc);
    nlohmann::json stats;  // the record view needs none
    ImGui::PushID(r.desc);
    VisualiserContext ctx{r.out, stats, r.records, view, nullptr};
    ctx.recordStep = &probes.recordStep[std::string(t.stage(r.stage).id()) + "/" + r.desc->name];
    vis.drawRecordView(ctx);
    ImGui::PopID();
  }
  ImGui::EndChild();
}

VOXLAB_REGISTER_DETAILS_TAB(probe, "probe", "Probe", 20, [](const Viewer& v) { return v.hasProbes(); },
                            [](Viewer& v) { v.drawProbe(); });

// --- Script verbs: probes and their records ---------------------------------------------------------

namespace {

std::string recordName(const Viewer& viewer, const ProbeRecords& r) {
  return std::string(viewer.cursor->technique().stage(r.stage).id()) + "/" + r.desc->name;
}

// Every probe record of every probing stage, checked by its visualiser (cone samples: the
// accumulated opacity of every sample is the front-to-back composite of the one before and the
// sample's own alpha).
void expectProbeRecords(Viewer& viewer, const ScriptCall& call) {
  const size_t atLeast = size_t(std::max(call.intArg(0), 0));
  const auto& records = viewer.probeRecords();
  if (records.empty())
    call.fail("technique " + viewer.cursor->technique().id() + " declares no probe-record output on a probing stage");
  for (const auto& r : records) {
    const std::string name = recordName(viewer, r);
    if (!r.error.empty()) call.fail(name + ": " + r.error);
    const Visualiser& vis = visualiserFor(r.out.desc);
    RecordCheck c = vis.checkRecords(r.out);
    if (c.elements <= atLeast)
      call.fail(name + ": " + c.summary + ", expected more than " + std::to_string(atLeast) + " (" + vis.name() + ")");
    if (!c.error.empty()) call.fail(name + ": " + c.error);
    std::printf("probe: %s (%s): %s\n", name.c_str(), vis.name(), c.summary.c_str());
  }
}

// The step slider of a probe record's view (Visualiser::recordSteps): the same int the Probe tab's
// slider moves, kept per record output. record-step moves it; both print what the step shows.
void showRecordStep(Viewer& viewer, const ScriptCall& call) {
  const std::string& wanted = call.arg(0);
  const ProbeRecords* rec = nullptr;
  std::vector<std::string> names;
  for (const auto& r : viewer.probeRecords()) {
    const std::string name = recordName(viewer, r);
    if (r.error.empty() && visualiserFor(r.out.desc).recordSteps(r.out) > 0) names.push_back(name);
    if (name == wanted) rec = &r;
  }
  if (!rec) call.fail("no probe record '" + wanted + "'; with steps now: " + joinNames(names));
  if (!rec->error.empty()) call.fail(wanted + ": " + rec->error);
  const Visualiser& vis = visualiserFor(rec->out.desc);
  const int n = int(vis.recordSteps(rec->out));
  if (n == 0) call.fail(wanted + " (" + vis.name() + ") has no steps to show; with steps now: " + joinNames(names));
  int& k = viewer.probes.recordStep[wanted];
  const bool moves = call.verb() == "record-step";
  if (moves) {
    const std::string& to = call.arg(1);
    if (to == "first") k = 0;
    else if (to == "last") k = n - 1;
    else if (to == "next") k = k + 1;
    else if (to == "prev") k = k - 1;
    else k = call.intArg(1);
    if (k < 0 || k >= n) call.fail("step " + std::to_string(k) + " is outside 0.." + std::to_string(n - 1));
  }
  k = std::clamp(k, 0, n - 1);
  const std::string said = vis.describeRecordStep(rec->out, size_t(k));
  std::printf("%s step %d of %d: %s\n", wanted.c_str(), k, n, said.c_str());
  if (moves) return;
  const std::string text = call.text(1);
  if (said.find(text) == std::string::npos)
    call.fail(wanted + " step " + std::to_string(k) + " shows '" + said + "', expected it to contain '" + text + "'");
}

}  // namespace

VOXLAB_REGISTER_SCRIPT_VERBS(probe, 60,
  {"probe", 2, 2, "probe X Y (pixel of the camera images, from the top left: sets every screen-space probe)",
   [](Viewer& viewer, const ScriptCall& call) { viewer.probePixel(call.intArg(0), call.intArg(1)); }},
  {"expect-probe-records", 1, 1,
   "expect-probe-records MIN (every probe record has more than MIN elements and passes its visualiser's check)",
   expectProbeRecords},
  {"record-step", 2, 2,
   "record-step STAGE/OUTPUT N|first|last|next|prev (move a probe record's step slider in the Probe tab, as dragging "
   "it: a walk's step; prints what the step shows)",
   showRecordStep},
  {"expect-record-step", 2, 32,
   "expect-record-step STAGE/OUTPUT TEXT... (the step the probe record's slider shows is described with TEXT)",
   showRecordStep});

}  // namespace voxlab
