// voxlab handout: lessons as HTML handouts with the picture of every step (handout/handout.h).
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "app/command.h"
#include "core/args.h"
#include "core/error.h"
#include "core/paths.h"
#include "core/progress.h"
#include "handout/handout.h"
#include "handout/step_picture.h"

namespace voxlab {
namespace {

int runHandout(const std::vector<std::string>& argv) {
  Args args("handout", argv,
            {{"--all", false, false, "every lesson in the lesson folder, and index.html"},
             {"--lessons", true, false, "the lesson folder for --all (default: lessons/ of the project)"},
             {"--size", true, false, "picture size WIDTHxHEIGHT (default 512x512, the viewer's)"},
             {"--out", true, false, "folder to write the handouts into"}},
            1);
  const bool all = args.has("--all");
  if (all == !args.positional().empty())
    throw Error(all ? "give either --all or a lesson file, not both"
                    : "handout needs a lesson file (voxlab handout LESSON.md --out DIR) or --all");
  if (!all && args.has("--lessons")) throw Error("--lessons goes with --all");
  int width = 512, height = 512;
  if (args.has("--size")) Args::parseSize(args.get("--size"), width, height);
  const std::string out = args.require("--out");

  std::vector<std::string> files = all ? lessonFiles(args.get("--lessons", projectPath("lessons"))) : args.positional();
  if (files.empty()) throw Error("no lessons (*.md besides README.md) in '" + args.get("--lessons", projectPath("lessons")) + "'");
  // Every lesson is validated before anything renders, so a bad one fails at once.
  std::vector<Lesson> lessons;
  for (const auto& f : files) lessons.push_back(loadLesson(f));
  int total = 0;
  for (const auto& l : lessons) total += int(l.steps.size());

  ProgressBar bar("handout");
  int before = 0;
  auto t0 = std::chrono::steady_clock::now();
  HandoutProgress progress = [&](int done, int, const std::string& label) { bar.update(before + done, total, label); };
  StepRenderer renderer(width, height);
  std::vector<HandoutPage> pages;
  for (const auto& l : lessons) {
    try {
      pages.push_back(writeHandout(l, out, renderer, progress));
    } catch (const Error&) {
      bar.finish();
      throw;
    }
    before += int(l.steps.size());
  }
  bar.finish();
  if (all) writeHandoutIndex(pages, out);
  double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (const auto& p : pages)
    std::printf("voxlab handout: %s/%s (%d steps)\n", out.c_str(), p.file.c_str(), p.steps);
  std::printf("voxlab handout: %d steps in %.1f s%s\n", total, s,
              all ? (", index " + out + "/index.html").c_str() : "");
  return 0;
}

}  // namespace

VOXLAB_REGISTER_COMMAND("handout", "voxlab handout (LESSON.md | --all [--lessons DIR]) [--size WxH] --out DIR",
                        "render lessons to HTML handouts with the picture of every step", &runHandout);

}  // namespace voxlab
