// The script verb walk-stages, expanded into the actions a user would take (select, iterate,
// run, screenshot, save and compare every output of every stage), and the frame statistics the
// scripts print (frame-stats). Nothing here names a stage, a technique or a semantic.
#include <algorithm>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "core/paths.h"
#include "inspect/script_verbs.h"
#include "inspect/viewer_state.h"

namespace voxlab {

namespace {

// walk-stages: the least fraction of the window that must change between the screenshots of two
// consecutive stages: the least measured was 0.077 (lrsm occlusion-voxels to occlusion-mips; vct-grid
// inject to occlusion-fix 0.078), every technique of the walk; a quarter of it.
const char* const kWalkMinChangedFraction = "0.02";

}  // namespace

std::vector<ScriptAction> Viewer::walkStagesActions(const ScriptAction& a) const {
  const Technique& t = cursor->technique();
  const std::string out = a.args.at(0), run = a.args.at(1);
  // Per-output tolerances of the snapshot suite: what was measured to vary between runs.
  nlohmann::json tol = nlohmann::json::parse(readTextFile(a.args.at(2)));
  auto toleranceOf = [&](const std::string& address) {
    double d = tol.at("default").at("max_abs").get<double>();
    if (tol.contains("outputs") && tol["outputs"].contains(address)) d = tol["outputs"][address].value("max_abs", d);
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", d);
    return std::string(buf);
  };
  std::vector<ScriptAction> acts;
  auto add = [&](std::string verb, std::vector<std::string> args) {
    ScriptAction s;
    s.verb = std::move(verb);
    s.args = std::move(args);
    s.line = a.line;
    acts.push_back(std::move(s));
  };
  std::string previous;
  for (int i = 0; i < t.stageCount(); ++i) {
    const std::string id = t.stage(i).id();
    add("stage", {id});
    const int n = cursor->iterations(i);
    if (n > 1)
      for (int k = 1; k <= n; ++k) {
        add("iterate", {});
        add("expect-iterations", {id, std::to_string(k)});
      }
    add("run", {});
    char shot[32];
    std::snprintf(shot, sizeof shot, "/%02d-", i + 1);
    std::string png = out + shot + id + ".png";
    add("screenshot", {png});
    // Consecutive screenshots differ at least in the timeline's highlighted stage and the view.
    if (!previous.empty()) add("expect-images-differ", {previous, png, kWalkMinChangedFraction});
    previous = png;
    for (const auto& o : t.decl(i).outputs) {
      add("output", {o.name});
      add("save-output", {out + "/view"});
      add("compare-output", {out + "/view", run, toleranceOf(t.id() + "/" + id + "/" + o.name)});
    }
  }
  return acts;
}

void Viewer::printFrameStats() const {
  if (idleFrameMs.empty()) {
    std::printf("frame-stats: no idle frames\n");
    return;
  }
  std::vector<double> s = idleFrameMs;
  std::sort(s.begin(), s.end());
  double sum = 0;
  for (double x : s) sum += x;
  int w, h;
  window->framebufferSize(w, h);
  std::printf("frame-stats: %zu idle UI frames at %dx%d: mean %.1f ms, median %.1f ms, p95 %.1f ms, max %.1f ms\n",
              s.size(), w, h, sum / s.size(), s[s.size() / 2], s[std::min(s.size() - 1, size_t(s.size() * 0.95))],
              s.back());
  if (!view3d.renderMs.empty()) {
    std::vector<double> r = view3d.renderMs;
    std::sort(r.begin(), r.end());
    double total = 0;
    for (double x : r) total += x;
    std::printf("frame-stats: %zu 3D view renders at %dx%d: mean %.1f ms, median %.1f ms, max %.1f ms\n", r.size(),
                View3D::kSize, View3D::kSize, total / r.size(), r[r.size() / 2], r.back());
  }
  std::fflush(stdout);
}

VOXLAB_REGISTER_SCRIPT_VERBS(walk, 150,
  {"walk-stages", 3, 3,
   "walk-stages OUT_DIR RUN_DIR TOLERANCES.json (every stage: step its iterations, run, screenshot; every output: "
   "save and compare with voxlab run's files in RUN_DIR)",
   [](Viewer& viewer, const ScriptCall& call) {
     const auto more = viewer.walkStagesActions(call.action());
     viewer.script.actions.insert(viewer.script.actions.begin() + long(viewer.script.next), more.begin(), more.end());
   }});

}  // namespace voxlab
