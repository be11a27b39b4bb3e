#include "core/log.h"

#include <cstdlib>
#include <cstring>

namespace voxlab::log {

Level threshold() {
  static const Level level = [] {
    const char* env = std::getenv("VOXLAB_LOG");
    if (!env) return Level::Warn;
    if (!std::strcmp(env, "error")) return Level::Error;
    if (!std::strcmp(env, "info")) return Level::Info;
    if (!std::strcmp(env, "debug")) return Level::Debug;
    return Level::Warn;
  }();
  return level;
}

void write(Level level, const std::string& message) {
  if (static_cast<int>(level) > static_cast<int>(threshold())) return;
  static const char* names[] = {"error", "warning", "info", "debug"};
  std::fprintf(stderr, "voxlab %s: %s\n", names[static_cast<int>(level)], message.c_str());
}

}  // namespace voxlab::log
