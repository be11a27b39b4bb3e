#include "core/paths.h"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"

namespace voxlab {

std::string projectRoot() {
  if (const char* env = std::getenv("VOXLAB_ROOT"); env && *env) return env;
  return VOXLAB_SOURCE_DIR;
}

std::string projectPath(const std::string& relative) { return projectRoot() + "/" + relative; }

std::string readTextFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot read '" + path + "': " + std::strerror(errno));
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

bool fileExists(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

}  // namespace voxlab
