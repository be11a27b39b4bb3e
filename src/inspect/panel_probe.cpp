// The generic probe. Stages declare probe parameters in screen space (a pixel of the camera
// images), volume space (a cell of a volume at a level) or light space (a texel of a light-space
// image), and probe-record outputs (StageBuilder::probe, OutputDesc::probeRecord). A click on an
// image of one of those spaces sets the matching parameters of every stage that declares them and
// queues what went stale; the Probe tab shows every probe record through its visualiser's record
// view: first the chains that explain the probed pixel (Semantic::ProbeChain), then the records of
// the stages probing the space last clicked (the cones or rays of that pixel), open, and the
// others folded. Nothing here names a stage or a parameter.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "inspect/probe_chain.h"
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
  probes.lastSpace = probeSpacesOfShown().front();
  ++probes.clicks;
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
  probes.lastSpace = ProbeSpace::Screen;
  ++probes.clicks;
  requestRun(std::max(last, std::max(selected, runs.lastRequest)));
  status = "probed pixel " + std::to_string(x) + "," + std::to_string(y);
  wantTab = "probe";
}

bool Viewer::lessonStepSets(const std::string& name) const {
  if (lessonStep < 0 || lessonStep >= int(lesson.steps.size())) return false;
  for (const auto& [n, value] : lesson.steps[size_t(lessonStep)].sets)
    if (n == name) return true;
  return false;
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
      } else if (!cursor->outputHeld(i, o.name)) {
        r.error = std::string(t.stage(i).id()) + "/" + o.name + " was not computed by the last run";
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
  // A stage's records are open when it probes the space last clicked.
  auto probesLastSpace = [&](int stage) {
    for (const auto& p : t.decl(stage).probes)
      if (p.space == probes.lastSpace) return true;
    return false;
  };
  const auto& records = probeRecords();
  for (int chainsFirst = 1; chainsFirst >= 0; --chainsFirst)
    for (const auto& r : records) {
      if ((r.desc->semantic == Semantic::ProbeChain) != bool(chainsFirst)) continue;
      const std::string name = std::string(t.stage(r.stage).id()) + "/" + r.desc->name;
      ImGui::PushID(r.desc);
      const bool open = probesLastSpace(r.stage);
      // After a click, open what it probed and fold the rest; between clicks the user's choice holds.
      ImGui::SetNextItemOpen(open, probes.clicks != probes.clicksShown ? ImGuiCond_Always : ImGuiCond_Once);
      const std::string title = name + (chainsFirst ? ": the probed pixel, explained" : "") +
                                (open ? "" : std::string(" (probes the ") + probeSpaceName(t.decl(r.stage).probes.front().space) +
                                                 "; click there to pick)");
      const bool shown = ImGui::CollapsingHeader(title.c_str());
      if (!shown) {
        ImGui::PopID();
        continue;
      }
      if (!r.error.empty()) {
        ImGui::TextWrapped("%s", r.error.c_str());
        ImGui::PopID();
        continue;
      }
      const Visualiser& vis = visualiserFor(r.out.desc);
      nlohmann::json stats;  // the record view needs none
      VisualiserContext ctx{r.out, stats, r.records, view, nullptr};
      ctx.recordStep = &probes.recordStep[name];
      if (probes.scrollTo == name) {
        ImGui::SetScrollHereY(0.0f);
        probes.scrollTo.clear();
      }
      ImGui::Indent();
      vis.drawRecordView(ctx);
      ImGui::Unindent();
      ImGui::PopID();
    }
  probes.clicksShown = probes.clicks;
  ImGui::EndChild();
}

VOXLAB_REGISTER_DETAILS_TAB(probe, "probe", "Probe", 20, [](const Viewer& v) { return v.hasProbes(); },
                            [](Viewer& v) { v.drawProbe(); });

// --- Script verbs: probes and their records ---------------------------------------------------------

namespace {

std::string recordName(const Viewer& viewer, const ProbeRecords& r) {
  return std::string(viewer.cursor->technique().stage(r.stage).id()) + "/" + r.desc->name;
}

// Every probe record of every probing stage that has run, checked by its visualiser (cone
// samples: the accumulated opacity of every sample is the front-to-back composite of the one
// before and the sample's own alpha). Records of stages after the ones run (a script that runs up
// to an earlier stage) are named and skipped; at least one must be checked.
void expectProbeRecords(Viewer& viewer, const ScriptCall& call) {
  const size_t atLeast = size_t(std::max(call.intArg(0), 0));
  const auto& records = viewer.probeRecords();
  if (records.empty())
    call.fail("technique " + viewer.cursor->technique().id() + " declares no probe-record output on a probing stage");
  size_t checked = 0;
  for (const auto& r : records) {
    const std::string name = recordName(viewer, r);
    if (viewer.cursor->record(r.stage).state == StageState::NotRun) {
      std::printf("probe: %s: its stage has not run, skipped\n", name.c_str());
      continue;
    }
    ++checked;
    if (!r.error.empty()) call.fail(name + ": " + r.error);
    const Visualiser& vis = visualiserFor(r.out.desc);
    RecordCheck c = vis.checkRecords(r.out);
    if (c.elements <= atLeast)
      call.fail(name + ": " + c.summary + ", expected more than " + std::to_string(atLeast) + " (" + vis.name() + ")");
    if (!c.error.empty()) call.fail(name + ": " + c.error);
    std::printf("probe: %s (%s): %s\n", name.c_str(), vis.name(), c.summary.c_str());
  }
  if (checked == 0) call.fail("no probing stage has run: run before expect-probe-records");
}

// The chains that explain the probed pixel (Semantic::ProbeChain records): each has the sections
// named, its parts add up to its sum (the visualiser's check), and its displayed value is what the
// technique's final image holds at the pixel its stage's screen probe points at. Prints each chain.
void expectProbeChain(Viewer& viewer, const ScriptCall& call) {
  const Technique& t = viewer.cursor->technique();
  size_t chains = 0;
  for (const auto& r : viewer.probeRecords()) {
    if (r.desc->semantic != Semantic::ProbeChain) continue;
    ++chains;
    const std::string name = recordName(viewer, r);
    if (!r.error.empty()) call.fail(name + ": " + r.error);
    const ProbeChain chain = decodeProbeChain(r.out);
    std::printf("probe chain %s:\n", name.c_str());
    std::vector<std::string> sections;
    for (const auto& sec : chain.sections) {
      sections.push_back(sec.name);
      for (const auto& e : sec.entries) {
        std::string values;
        for (size_t i = 0; i < e.values.size(); ++i) values += (i ? ", " : "") + formatSignificant(e.values[i]);
        std::printf("  %s: %s = %s%s%s\n", sec.name.c_str(), e.label.c_str(), values.c_str(), e.unit.empty() ? "" : " ",
                    e.unit.c_str());
      }
    }
    for (size_t i = 0; i < call.count(); ++i)
      if (std::find(sections.begin(), sections.end(), call.arg(i)) == sections.end())
        call.fail(name + " has no section '" + call.arg(i) + "'; its sections: " + joinNames(sections));
    const RecordCheck check = visualiserFor(r.out.desc).checkRecords(r.out);
    std::printf("  check: %s\n", check.summary.c_str());
    if (!check.error.empty()) call.fail(name + ": " + check.error);
    // The displayed value against the final image at the probed pixel (GL rows from the bottom,
    // as the stage maps its screen probe: the pixel the fractions fall in).
    const ProbeChainEntry* shown = chain.find(FieldRole::Displayed);
    if (!shown) call.fail(name + " declares no Displayed field");
    const ProbeDesc* screen = nullptr;
    for (const auto& p : t.decl(r.stage).probes)
      if (p.space == ProbeSpace::Screen) screen = &p;
    if (!screen) call.fail(name + ": its stage declares no screen probe");
    auto [finalStage, finalDesc] = t.findOutput(t.finalStage(), t.finalOutput());
    if (viewer.cursor->record(finalStage).state == StageState::NotRun)
      call.fail(t.finalStage() + " has not run: run before expect-probe-chain");
    const CapturedOutput fin = captureOutput(viewer.cursor->board(), *finalDesc);
    const LevelData& L = fin.levels.at(0);
    const ParamSet& ps = viewer.cursor->params();
    const int x = std::min(int(ps.getFloat(screen->x) * float(L.size.x)), L.size.x - 1);
    const int y = std::min(int((1.0f - ps.getFloat(screen->y)) * float(L.size.y)), L.size.y - 1);
    // The chain stores the value rounded to 8 bits as the final image does; a value exactly between
    // two steps may round either way on the GPU, one step (1/255) at most.
    constexpr double kOneStep = 1.0 / 255.0 + 1e-6;
    double worst = 0.0;
    for (int c = 0; c < std::min(int(shown->values.size()), L.channels); ++c) {
      const double image = L.values[(size_t(y) * size_t(L.size.x) + size_t(x)) * size_t(L.channels) + size_t(c)];
      worst = std::max(worst, std::fabs(image - shown->values[size_t(c)]));
      if (std::fabs(image - shown->values[size_t(c)]) > kOneStep)
        call.fail(name + ": displayed channel " + std::to_string(c) + " is " + formatSignificant(shown->values[size_t(c)]) +
                  ", but " + t.finalStage() + "/" + t.finalOutput() + " holds " + formatSignificant(image) + " at pixel (" +
                  std::to_string(x) + ", " + std::to_string(y) + ")");
    }
    std::printf("  displayed value matches %s/%s at pixel (%d, %d from the bottom): largest difference %s\n",
                t.finalStage().c_str(), t.finalOutput().c_str(), x, y, formatSignificant(worst).c_str());
  }
  if (chains == 0) call.fail("technique " + t.id() + " records no probe chain (no stage declares a probe-chain output)");
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
  if (moves) viewer.probes.scrollTo = wanted;  // the Probe tab brings that record into view
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
  {"expect-probe-chain", 1, 8,
   "expect-probe-chain SECTION... (the probed pixel's chain has these sections, its parts add up to its sum and its "
   "displayed value is the final image's at the pixel; prints the chain)",
   expectProbeChain},
  {"expect-probe-marks", 1, 1,
   "expect-probe-marks N (N probe marks were drawn over the view in the last frame: rings in presenter mode)",
   [](Viewer& viewer, const ScriptCall& call) {
     if (viewer.probes.marksShown != call.intArg(0))
       call.fail(std::to_string(viewer.probes.marksShown) + " probe marks drawn, expected " + call.arg(0));
   }},
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
