// voxlab lesson --check FILE|FOLDER: validates lessons against the technique registry and the
// repository, and renders every step's picture headless to find blank ones (lesson/lesson_check.h).
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
#include "lesson/lesson_check.h"

namespace voxlab {
namespace {

int runLesson(const std::vector<std::string>& argv) {
  Args args("lesson", argv,
            {{"--check", true, false, "lesson Markdown file, or a folder of them (README.md left out), to check"},
             {"--no-render", false, false, "check the text only; do not render the step pictures"},
             {"--size", true, false, "picture size WIDTHxHEIGHT for the blank-picture check (default 512x512)"}});
  const std::string target = args.require("--check");
  int width = 512, height = 512;
  if (args.has("--size")) Args::parseSize(args.get("--size"), width, height);
  const std::vector<std::string> files =
      std::filesystem::is_directory(target) ? lessonFiles(target) : std::vector<std::string>{target};
  if (files.empty()) throw Error("no lessons (*.md besides README.md) in '" + target + "'");

  std::vector<Lesson> lessons;
  std::vector<std::string> problems;
  for (const auto& f : files) {
    lessons.push_back(loadLesson(f));  // a step block that does not parse stops here, with FILE:LINE
    for (auto& p : lessonTextProblems(lessons.back(), readTextFile(f))) problems.push_back(p);
  }
  if (!args.has("--no-render")) {
    int total = 0, done = 0;
    for (const auto& l : lessons) total += int(l.steps.size());
    ProgressBar bar("lesson");
    StepRenderer renderer(width, height);
    for (const auto& l : lessons)
      for (size_t i = 0; i < l.steps.size(); ++i) {
        bar.update(done++, total, l.path + " step " + std::to_string(i + 1));
        try {
          StepPicture pic = renderer.render(l, l.steps[i]);
          std::string blank = blankPictureProblem(l, int(i), pic);
          if (!blank.empty()) problems.push_back(blank);
        } catch (const Error& e) {
          problems.push_back(e.what());
        }
      }
    bar.finish();
  }
  for (const auto& p : problems) std::fprintf(stderr, "%s\n", p.c_str());
  for (const auto& l : lessons)
    std::printf("voxlab lesson: %s: \"%s\", %zu steps%s\n", l.path.c_str(), l.title.c_str(), l.steps.size(),
                problems.empty() ? (args.has("--no-render") ? ", text valid" : ", valid, every picture shows something")
                                 : "");
  if (!problems.empty()) {
    std::printf("voxlab lesson: %zu problem%s\n", problems.size(), problems.size() == 1 ? "" : "s");
    return 1;
  }
  return 0;
}

}  // namespace

VOXLAB_REGISTER_COMMAND("lesson", "voxlab lesson --check FILE|FOLDER [--no-render] [--size WxH]",
                        "check lessons: step blocks, headings, named steps, files, outputs and keys, and that "
                        "every step's picture shows something (exit 1 listing every problem)",
                        &runLesson);

}  // namespace voxlab
