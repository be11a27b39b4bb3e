// voxlab lesson --check FILE: validates a lesson against the technique registry.
#include <cstdio>

#include "app/command.h"
#include "core/args.h"
#include "lesson/lesson.h"

namespace voxlab {
namespace {

int runLesson(const std::vector<std::string>& argv) {
  Args args("lesson", argv, {{"--check", true, false, "lesson Markdown file to validate"}});
  std::string path = args.require("--check");
  Lesson lesson = loadLesson(path);
  std::printf("voxlab lesson: %s: \"%s\", %zu steps, valid\n", path.c_str(), lesson.title.c_str(),
              lesson.steps.size());
  return 0;
}

}  // namespace

VOXLAB_REGISTER_COMMAND("lesson", "voxlab lesson --check FILE",
                        "validate a lesson (exit 2 with file:line on the first error)", &runLesson);

}  // namespace voxlab
