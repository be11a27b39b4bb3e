// voxlab sweep: one technique on one scene at every value of one parameter (or every pair of
// values of two), to answer "what does this parameter buy, and what does it cost" (run/sweep.h
// runs it, writes sweep.json, the plots and sweep.html). Bad input (a parameter the technique does
// not declare, a value outside its range, a malformed range) is one line naming what is wrong and
// what is valid, before anything runs.
#include <cstdio>

#include "app/command.h"
#include "core/args.h"
#include "core/error.h"
#include "core/progress.h"
#include "run/sweep.h"

namespace voxlab {
namespace {

int runSweepCommand(const std::vector<std::string>& argv) {
  Args args("sweep", argv,
            {{"--technique", true, false, "technique id"},
             {"--scene", true, false, "scene name or glTF path (default cornell-box)"},
             {"--param", true, true,
              "NAME=V1,V2,... or NAME=FROM:TO:STEPS: the parameter swept; twice for the grid of two"},
             {"--set", true, true, "NAME=VALUE for every run, repeatable"},
             {"--size", true, false, "image size WIDTHxHEIGHT (default 256x256; the references' size or a divisor of it)"},
             {"--repeat", true, false, "timed runs per value (default 1); a stage's time is its median over them"},
             {"--time-stage", true, true, "stage id, repeatable: the time plotted is of these stages (default: all)"},
             {"--error", true, false, "the error plotted: ssim (1 - SSIM, default) or energy (|1 - energy ratio|)"},
             {"--out", true, false, "folder for sweep.json, sweep.html, the plots (SVG) and the runs"}});
  SweepRequest request;
  request.technique = args.require("--technique");
  const std::string out = args.require("--out");
  request.scene = args.get("--scene", "cornell-box");
  if (args.has("--size")) Args::parseSize(args.get("--size"), request.width, request.height);
  request.repeats = args.has("--repeat") ? Args::parseInt("--repeat", args.get("--repeat"), 1, 15) : 1;
  request.error = args.get("--error", "ssim");
  request.params = args.all("--param");
  request.sets = args.all("--set");
  request.timeStages = args.all("--time-stage");

  ProgressBar bar("sweep");
  const auto report = runSweep(
      request, out, [&](int done, int total, const std::string& label) { bar.update(done, total, label); },
      [&](const std::string& label, const std::string& message) {
        bar.finish();
        std::fprintf(stderr, "voxlab sweep: %s failed: %s\n", label.c_str(), message.c_str());
      });
  bar.finish();
  std::printf("voxlab sweep: %s on %s, %zu runs in %.0f s; error = %s of %s; written to %s/sweep.{json,html}\n",
              request.technique.c_str(), report["scene"].get<std::string>().c_str(), report["runs"].size(),
              report["wall_s"].get<double>(), report["error"]["definition"].get<std::string>().c_str(),
              report["error"]["output"].get<std::string>().c_str(), out.c_str());
  return report["failed_runs"].get<int>() > 0 ? 1 : 0;
}

}  // namespace

VOXLAB_REGISTER_COMMAND("sweep",
                        "voxlab sweep --technique T [--scene S] --param NAME=V1,V2,...|NAME=FROM:TO:STEPS [--param ...] "
                        "[--set NAME=VALUE]... [--size WxH] [--repeat N] [--error ssim|energy] --out DIR",
                        "one technique at every value of one or two parameters: error against the reference, time, "
                        "GPU memory, plots",
                        &runSweepCommand);

}  // namespace voxlab
