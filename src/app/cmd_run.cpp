// voxlab run: runs a technique up to a stage headless and writes every output and a manifest.
#include <cstdio>

#include "app/command.h"
#include "app/session.h"
#include "core/args.h"

namespace voxlab {
namespace {

int runRun(const std::vector<std::string>& argv) {
  Args args("run", argv,
            {{"--technique", true, false, "technique id (voxlab list)"},
             {"--scene", true, false, "scene name in scenes/ or a glTF path (default cornell-box)"},
             {"--until", true, false, "last stage to run (default: all)"},
             {"--set", true, true, "NAME=VALUE parameter override, repeatable"},
             {"--size", true, false, "output size WIDTHxHEIGHT (default 512x512)"},
             {"--camera", true, false, "index of the scene camera (default 0)"},
             {"--final-only", false, false, "write only the technique's final output"},
             {"--out", true, false, "folder to write the outputs and manifest.json into"}});
  RunRequest req;
  req.technique = args.require("--technique");
  req.scene = args.get("--scene", "cornell-box");
  req.until = args.get("--until");
  req.sets = args.all("--set");
  if (args.has("--size")) Args::parseSize(args.get("--size"), req.width, req.height);
  if (args.has("--camera")) req.camera = Args::parseInt("--camera", args.get("--camera"), 0, 1000);
  std::string out = args.require("--out");

  HeadlessSession session(req);
  session.run();
  auto manifest = session.writeOutputs(out, args.has("--final-only"));
  size_t files = 0;
  for (const auto& s : manifest["stages"])
    for (const auto& o : s["outputs"]) files += o["files"].size();
  std::printf("voxlab run: %s on %s, %zu stages, %zu files, %.1f ms (cpu), written to %s/manifest.json\n",
              req.technique.c_str(), manifest["scene"].get<std::string>().c_str(), manifest["stages"].size(),
              files, manifest["total_cpu_ms"].get<double>(), out.c_str());
  return 0;
}

}  // namespace

VOXLAB_REGISTER_COMMAND("run",
                        "voxlab run --technique T [--scene S] [--until STAGE] [--set name=value]... "
                        "[--size WxH] [--camera N] [--final-only] --out DIR",
                        "run a technique headless and write every stage output and a manifest", &runRun);

}  // namespace voxlab
