// voxlab view: the interactive viewer (GLFW + ImGui); with --script it replays actions for tests.
#include <cstdio>
#include <cstdlib>

#include "app/command.h"
#include "core/args.h"
#include "core/error.h"
#include "inspect/inspect_logic.h"
#include "inspect/viewer.h"

namespace voxlab {
namespace {

int runView(const std::vector<std::string>& argv) {
  for (const auto& a : argv)
    if (a == "--script-help") {
      std::printf("script actions, one per line ('#' comments, ${ENV} substituted):\n%s", scriptVerbsHelp().c_str());
      return 0;
    }
  Args args("view", argv,
            {{"--technique", true, false, "technique id (default vct-grid)"},
             {"--scene", true, false, "scene name in scenes/ or a glTF path (default cornell-box)"},
             {"--lesson", true, false, "lesson Markdown file to play"},
             {"--script", true, false, "replay actions from FILE and quit (voxlab view --script-help)"},
             {"--size", true, false, "render size WIDTHxHEIGHT (default 512x512)"},
             {"--window", true, false, "window size WIDTHxHEIGHT (default 1280x720)"},
             {"--ui-scale", true, false, "size of text and widgets, 0.75..3 (default 1; 1.5-2 for a projector)"},
             {"--present", false, false, "presenter mode: the view fills the window beside the lesson in large type "
                                         "(keys P / F11 toggle it)"}});
  ViewerOptions o;
  o.technique = args.get("--technique", "vct-grid");  // the documented default of `voxlab view`
  o.scene = args.get("--scene", o.scene);
  o.lesson = args.get("--lesson");
  o.script = args.get("--script");
  if (args.has("--size")) Args::parseSize(args.get("--size"), o.width, o.height);
  o.present = args.has("--present");
  if (args.has("--window")) Args::parseSize(args.get("--window"), o.windowWidth, o.windowHeight);
  if (args.has("--ui-scale")) {
    const std::string text = args.get("--ui-scale");
    char* end = nullptr;
    double s = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !(s >= 0.75 && s <= 3.0))
      throw Error("--ui-scale '" + text + "' is not a number in 0.75..3 (e.g. 1.5 for a projector)");
    o.uiScale = float(s);
  }
  return runViewer(o);
}

}  // namespace

VOXLAB_REGISTER_COMMAND("view",
                        "voxlab view [--technique T] [--scene S] [--lesson FILE] [--script FILE] [--size WxH] "
                        "[--window WxH] [--ui-scale S] [--present]",
                        "open the viewer: step through stages, inspect outputs, probe cones, play lessons", &runView);

}  // namespace voxlab
