// Sub-commands of the voxlab binary ("list", "run", "bench", "reference", ...).
//
// Each command lives in its own src/app/cmd_*.cpp and registers itself with
// VOXLAB_REGISTER_COMMAND; main() only dispatches. A command returns the process exit code and
// reports bad input by throwing voxlab::Error (main prints it as one line and exits 2).
#pragma once
#include <string>
#include <vector>

namespace voxlab {

struct Command {
  const char* name;
  const char* usage;    // "voxlab run --technique T --scene S [...]"
  const char* summary;  // one line
  int (*run)(const std::vector<std::string>& args);
};

void registerCommand(const Command& command);
const std::vector<Command>& commands();

struct CommandRegistrar {
  explicit CommandRegistrar(const Command& c) { registerCommand(c); }
};

}  // namespace voxlab

#define VOXLAB_CONCAT_INNER(a, b) a##b
#define VOXLAB_CONCAT(a, b) VOXLAB_CONCAT_INNER(a, b)
#define VOXLAB_REGISTER_COMMAND(...) \
  static ::voxlab::CommandRegistrar VOXLAB_CONCAT(voxlabCommand_, __LINE__){::voxlab::Command{__VA_ARGS__}}
