#include "app/command.h"

namespace voxlab {

static std::vector<Command>& commandTable() {
  static std::vector<Command> table;
  return table;
}

void registerCommand(const Command& command) { commandTable().push_back(command); }
const std::vector<Command>& commands() { return commandTable(); }

}  // namespace voxlab
