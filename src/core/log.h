// Minimal logging to stderr. Level from VOXLAB_LOG (error, warn, info, debug); default warn.
#pragma once
#include <cstdio>
#include <string>

namespace voxlab::log {

enum class Level { Error = 0, Warn = 1, Info = 2, Debug = 3 };
Level threshold();
void write(Level level, const std::string& message);
inline void error(const std::string& m) { write(Level::Error, m); }
inline void warn(const std::string& m) { write(Level::Warn, m); }
inline void info(const std::string& m) { write(Level::Info, m); }
inline void debug(const std::string& m) { write(Level::Debug, m); }

}  // namespace voxlab::log
