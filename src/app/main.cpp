// voxlab: run voxel global-illumination techniques stage by stage.
// main() only dispatches to the commands registered in src/app/cmd_*.cpp.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "app/command.h"
#include "app/huge_pages.h"
#include "core/error.h"
#include "gpu/gl_debug.h"

// With VOXLAB_GL_ERRORS_FATAL=1 (every CTest test sets it) a command that caused GL messages of
// severity high or medium exits with status 3 after naming the first one; each was printed once.
static int failOnGLErrors(const char* command, int status) {
  const char* fatal = std::getenv("VOXLAB_GL_ERRORS_FATAL");
  if (!fatal || std::string(fatal) != "1") return status;
  const size_t count = voxlab::glFailureCount();
  if (count == 0) return status;
  std::fprintf(stderr, "voxlab %s: %zu GL message(s) of severity high or medium (printed above)\n", command, count);
  return 3;
}

static void printUsage() {
  std::printf("usage: voxlab COMMAND [options]\n\ncommands:\n");
  auto cmds = voxlab::commands();
  std::sort(cmds.begin(), cmds.end(),
            [](const auto& a, const auto& b) { return std::strcmp(a.name, b.name) < 0; });
  for (const auto& c : cmds) std::printf("  %-10s %s\n", c.name, c.summary);
  std::printf("\n'voxlab help COMMAND' shows a command's options.\n");
}

int main(int argc, char** argv) {
  voxlab::restartWithHugePagesIfUseful(argv);
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    printUsage();
    return args.empty() ? 2 : 0;
  }
  std::string name = args[0];
  if (name == "help" && args.size() > 1) {
    name = args[1];
    args = {name, "--help"};
  }
  for (const auto& c : voxlab::commands()) {
    if (name != c.name) continue;
    std::vector<std::string> rest(args.begin() + 1, args.end());
    if (!rest.empty() && (rest[0] == "--help" || rest[0] == "-h")) {
      std::printf("usage: %s\n%s\n", c.usage, c.summary);
      return 0;
    }
    try {
      return failOnGLErrors(c.name, c.run(rest));
    } catch (const voxlab::Error& e) {
      std::fprintf(stderr, "voxlab %s: %s\n", c.name, e.what());
      return failOnGLErrors(c.name, 2);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "voxlab %s: internal error: %s\n", c.name, e.what());
      return 3;
    }
  }
  std::vector<std::string> names;
  for (const auto& c : voxlab::commands()) names.push_back(c.name);
  std::sort(names.begin(), names.end());
  std::fprintf(stderr, "voxlab: unknown command '%s'; valid commands: %s\n", name.c_str(),
               voxlab::joinNames(names).c_str());
  return 2;
}
