// voxlab run: runs a technique up to a stage headless and writes every output and a manifest; with
// --frames, a sequence of frames while the scene plays its animation and --animate'd parameters
// change (run/frames.h).
#include <cstdio>

#include "app/command.h"
#include "run/frames.h"
#include "run/session.h"
#include "core/args.h"
#include "core/error.h"
#include "graph/output.h"

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
             {"--look-from", true, false, "X,Y,Z: a free camera's position (with --look-at; keeps --camera's field of view)"},
             {"--look-at", true, false, "X,Y,Z: the point a free camera looks at"},
             {"--final-only", false, false, "write only the technique's final output"},
             {"--only", true, true, "write only this output: technique/stage/output[@level], repeatable"},
             {"--frames", true, false, "run N frames (1..1000), each into OUT/frames/NNNN/, re-running only what changed"},
             {"--animate", true, true, "NAME=FROM:TO: a number parameter moved linearly over the frames, repeatable"},
             {"--time-range", true, false, "FROM:TO: seconds of the scene's animation the frames span (default: all of it)"},
             {"--out", true, false, "folder to write the outputs and manifest.json into"}});
  RunRequest req;
  req.technique = args.require("--technique");
  req.scene = args.get("--scene", "cornell-box");
  req.until = args.get("--until");
  req.sets = args.all("--set");
  if (args.has("--size")) Args::parseSize(args.get("--size"), req.width, req.height);
  if (args.has("--camera")) req.camera = Args::parseInt("--camera", args.get("--camera"), 0, 1000);
  auto vec = [&](const char* name) {
    auto v = Args::parseVec3(name, args.get(name));
    return glm::vec3(v[0], v[1], v[2]);
  };
  if (args.has("--look-from")) req.lookFrom = vec("--look-from");
  if (args.has("--look-at")) req.lookAt = vec("--look-at");
  std::string out = args.require("--out");

  std::vector<OutputAddress> only;
  for (const auto& a : args.all("--only")) {
    OutputAddress addr = OutputAddress::parse(a);
    if (addr.technique != req.technique)
      throw Error("--only " + a + " names technique '" + addr.technique + "', but the run is " + req.technique);
    only.push_back(addr);
  }
  HeadlessSession session(req);
  for (const auto& a : only) {
    const Technique& t = session.cursor().technique();
    auto [stage, desc] = t.findOutput(a.stage, a.output);  // throws naming the valid stages/outputs
    (void)desc;
    if (stage > session.untilStage()) throw Error("--only " + a.str() + " is after --until " + req.until);
  }
  // Outputs on demand: --final-only and --only compute only what they write.
  session.demand(args.has("--final-only"), only);
  if (args.has("--animate") && !args.has("--frames"))
    throw Error("--animate needs --frames N (the number of frames to move it over)");
  if (args.has("--time-range") && !args.has("--frames"))
    throw Error("--time-range needs --frames N (the number of frames to play it over)");
  if (args.has("--frames")) {
    FramesRequest fr;
    fr.frames = Args::parseInt("--frames", args.get("--frames"), 1, 1000);
    for (const auto& a : args.all("--animate")) fr.animations.push_back(parseAnimation(session.cursor().params(), a));
    if (args.has("--time-range")) fr.timeRange = parseTimeRange(args.get("--time-range"));
    fr.finalOnly = args.has("--final-only");
    fr.only = only;
    auto m = runFrames(session, fr, out, [&](int frame, const std::vector<std::string>& reran) {
      std::string list;
      for (const auto& id : reran) list += (list.empty() ? "" : " ") + id;
      std::printf("voxlab run: frame %d/%d re-ran %zu stage(s)%s%s\n", frame, fr.frames, reran.size(),
                  reran.empty() ? "" : ": ", list.c_str());
    });
    if (m["temporal"].contains("mean_flicker"))
      std::printf("voxlab run: %d frames of %s on %s written to %s/frames/; %s: mean flicker %.4g, mean %.4g (manifest.json)\n",
                  fr.frames, req.technique.c_str(), m["scene"].get<std::string>().c_str(), out.c_str(),
                  m["temporal"]["output"].get<std::string>().c_str(), m["temporal"]["mean_flicker"].get<double>(),
                  m["temporal"]["mean_energy"].get<double>());
    return 0;
  }
  session.run();
  auto manifest = session.writeOutputs(out, args.has("--final-only"), only);
  size_t files = 0;
  for (const auto& s : manifest["stages"])
    for (const auto& o : s["outputs"]) files += o["files"].size();
  std::printf("voxlab run: %s on %s, %zu stages, %zu files, %.1f ms (cpu), written to %s/manifest.json\n",
              req.technique.c_str(), manifest["scene"].get<std::string>().c_str(), manifest["stages"].size(),
              files, manifest["total_cpu_ms"].get<double>(), out.c_str());
  for (const auto& s : manifest["stages"])
    for (const auto& o : s["outputs"])
      if (o.contains("reference_missing"))
        std::printf("voxlab run: %s not compared: no reference image of mode %s (%s); make it with voxlab reference --mode %s\n",
                    o["address"].get<std::string>().c_str(), o["reference_missing"]["mode"].get<std::string>().c_str(),
                    o["reference_missing"]["reference"].get<std::string>().c_str(),
                    o["reference_missing"]["mode"].get<std::string>().c_str());
  if (manifest.contains("references_skipped"))
    std::printf("voxlab run: not compared with the reference images: %s\n",
                manifest["references_skipped"].get<std::string>().c_str());
  return 0;
}

}  // namespace

VOXLAB_REGISTER_COMMAND("run",
                        "voxlab run --technique T [--scene S] [--until STAGE] [--set name=value]... "
                        "[--size WxH] [--camera N] [--look-from X,Y,Z --look-at X,Y,Z] [--final-only] [--only technique/stage/output[@level]]... "
                        "[--frames N [--time-range FROM:TO] [--animate NAME=FROM:TO]...] --out DIR",
                        "run a technique headless and write every stage output and a manifest", &runRun);

}  // namespace voxlab
