// Running a script (voxlab view --script): one action per frame once the viewer is idle, each
// looked up in the verb registry (script_verbs.h) and handed to the handler its feature registered.
// The verbs that belong to no panel are here: waiting, tabs, shader reload, UI scale, quitting.
#include <algorithm>
#include <cstdio>

#include "core/error.h"
#include "inspect/script_verbs.h"
#include "inspect/viewer_state.h"

namespace voxlab {

void Viewer::scriptFail(const ScriptAction& a, const std::string& msg) const {
  throw Error(opt.script + ":" + std::to_string(a.line) + ": " + a.verb + ": " + msg);
}

void Viewer::stepScript() {
  if (scriptBusy()) return;
  if (script.next >= script.actions.size()) {
    quit = true;
    return;
  }
  const ScriptAction a = script.actions[script.next++];  // a copy: walk-stages inserts actions into script
  frameHeavy = true;  // script I/O (saving, comparing) is not UI time
  try {
    execute(a);
  } catch (const Error& e) {
    std::string m = e.what();
    if (m.rfind(opt.script + ":", 0) == 0) throw;
    scriptFail(a, m);
  }
}

void Viewer::execute(const ScriptAction& a) {
  const ScriptVerb* verb = findScriptVerb(a.verb);
  if (!verb) {
    std::vector<std::string> names;
    for (const ScriptVerb& v : scriptVerbs())
      if (v.usage) names.push_back(v.name);
    scriptFail(a, "unknown action; valid: " + joinNames(names));
  }
  const ScriptCall call(a, *verb);
  if (int(a.args.size()) < verb->minArgs || int(a.args.size()) > verb->maxArgs) call.badArgument("wrong arguments");
  verb->run(*this, call);
}

const CapturedOutput& requireShownCapture(Viewer& viewer, const ScriptCall& call) {
  viewer.refreshCapture();
  if (!viewer.capError.empty()) call.fail(viewer.capError);
  return viewer.cap;
}

VOXLAB_REGISTER_SCRIPT_VERBS(script, 140,
  {"reload", 0, 0, "reload (shader hot reload, as F5)",
   [](Viewer& viewer, const ScriptCall&) {
     viewer.reloadShaders();
     if (!viewer.shaderError.empty()) std::printf("shader reload failed: %s\n", viewer.shaderError.c_str());
   }},
  {"wait", 1, 1, "wait FRAMES", [](Viewer& viewer, const ScriptCall& call) { viewer.script.waitFrames = call.intArg(0); }},
  {"tab", 1, 1, "tab inspect|probe|timing|lesson|export (bring a details tab to front)",
   [](Viewer& viewer, const ScriptCall& call) {
     std::vector<std::string> ids;
     for (const auto& tab : detailsTabs()) ids.push_back(tab.id);
     if (std::find(ids.begin(), ids.end(), call.arg(0)) == ids.end())
       call.badArgument("unknown tab '" + call.arg(0) + "'; valid: " + joinNames(ids));
     viewer.wantTab = call.arg(0);
   }},
  {"ui-scale", 1, 1, "ui-scale S (text and widget size, 0.75..3, as --ui-scale)",
   [](Viewer& viewer, const ScriptCall& call) {
     const float s = call.floatArg(0);
     if (!(s >= 0.75f && s <= 3.0f)) call.badArgument("scale must be in 0.75..3, not " + call.arg(0));
     viewer.wantUiScale = s;
     viewer.script.waitFrames = 2;
   }},
  {"quit", 0, 0, "quit", [](Viewer& viewer, const ScriptCall&) { viewer.quit = true; }});

}  // namespace voxlab
