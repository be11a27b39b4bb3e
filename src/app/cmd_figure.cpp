// voxlab figure: a labelled SVG of one output of a run (inspect/figure.h): the title, the scene,
// size and changed parameters, the output as the viewer shows it, a colour bar for a false-colour
// view and the reference beside it. The viewer's Camera/Export tab writes the same figure.
#include <cstdio>
#include <fstream>

#include "app/command.h"
#include "core/args.h"
#include "core/error.h"
#include "inspect/figure.h"
#include "run/session.h"

namespace voxlab {
namespace {

int runFigure(const std::vector<std::string>& argv) {
  Args args("figure", argv,
            {{"--technique", true, false, "technique id"},
             {"--scene", true, false, "scene name or glTF path (default cornell-box)"},
             {"--set", true, true, "NAME=VALUE, repeatable"},
             {"--output", true, false, "STAGE/OUTPUT[@LEVEL] (default the technique's final output)"},
             {"--size", true, false, "render size WIDTHxHEIGHT (default 256x256, the references' size)"},
             {"--camera", true, false, "scene camera index (default 0)"},
             {"--width", true, false, "the figure's width in pixels, 64..4096 (default 800)"},
             {"--exposure", true, false, "multiplies the values before the display mapping (default 1)"},
             {"--no-reference", false, false, "leave the reference out"},
             {"--out", true, false, "the figure: a path ending in .svg"}});
  const std::string out = args.require("--out");
  if (out.size() < 4 || out.compare(out.size() - 4, 4, ".svg") != 0)
    throw Error("--out '" + out + "': a figure is written as SVG; valid: a path ending in .svg");
  RunRequest request;
  request.technique = args.require("--technique");
  request.scene = args.get("--scene", "cornell-box");
  request.sets = args.all("--set");
  request.width = request.height = 256;
  if (args.has("--size")) Args::parseSize(args.get("--size"), request.width, request.height);
  if (args.has("--camera")) request.camera = Args::parseInt("--camera", args.get("--camera"), 0, 1 << 20);
  const int width = args.has("--width") ? Args::parseInt("--width", args.get("--width"), 64, 4096) : 800;
  FigureRequest figure;
  figure.withReference = !args.has("--no-reference");
  if (args.has("--exposure")) {
    const std::string text = args.get("--exposure");
    char* end = nullptr;
    figure.display.exposure = std::strtof(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !(figure.display.exposure > 0.0f))
      throw Error("--exposure '" + text + "' is not valid; valid: a number above 0");
  }
  // The output is checked against the technique before the run (one line listing the valid ones).
  const auto declared = createTechnique(request.technique);
  std::string address = args.get("--output", declared->finalStage() + "/" + declared->finalOutput());
  const OutputAddress parsed = OutputAddress::parse(request.technique + "/" + address);
  declared->findOutput(parsed.stage, parsed.output);
  figure.stage = parsed.stage;
  figure.output = parsed.output;
  figure.level = std::max(parsed.level, 0);
  request.until = parsed.stage;

  HeadlessSession session(request);
  session.run();
  const std::string svg = figureSvg(outputFigure(session.cursor(), figure), width);
  std::ofstream file(out, std::ios::binary);
  if (!file || !(file << svg)) throw Error("cannot write '" + out + "' (folder missing or not writable?)");
  std::printf("voxlab figure: %s/%s/%s@%d on %s written to %s\n", request.technique.c_str(), figure.stage.c_str(),
              figure.output.c_str(), figure.level, request.scene.c_str(), out.c_str());
  return 0;
}

}  // namespace

VOXLAB_REGISTER_COMMAND("figure",
                        "voxlab figure --technique T [--scene S] [--set NAME=VALUE]... [--output STAGE/OUTPUT[@LEVEL]] "
                        "[--size WxH] [--camera N] [--width PX] [--exposure X] [--no-reference] --out FILE.svg",
                        "a labelled SVG of one output: title, parameters, colour bar, the reference beside it",
                        &runFigure);

}  // namespace voxlab
