#include "core/args.h"

#include <cmath>

#include <cstdlib>

#include "core/error.h"

namespace voxlab {

Args::Args(const std::string& command, const std::vector<std::string>& args,
           const std::vector<OptionSpec>& specs, size_t maxPositional)
    : command_(command) {
  auto findSpec = [&](const std::string& name) -> const OptionSpec* {
    for (const auto& s : specs)
      if (s.name == name) return &s;
    return nullptr;
  };
  for (size_t i = 0; i < args.size(); ++i) {
    std::string a = args[i];
    std::string inlineValue;
    bool hasInline = false;
    if (a.rfind("--", 0) == 0) {
      if (auto eq = a.find('='); eq != std::string::npos) {
        inlineValue = a.substr(eq + 1);
        a = a.substr(0, eq);
        hasInline = true;
      }
      const OptionSpec* spec = findSpec(a);
      if (!spec) {
        std::vector<std::string> names;
        for (const auto& s : specs) names.push_back(s.name);
        throw Error("'" + command + "' has no option '" + a + "'; valid options: " +
                    (names.empty() ? std::string("none") : joinNames(names)));
      }
      if (values_.count(a) && !spec->repeatable)
        throw Error("option '" + a + "' of '" + command + "' was given twice");
      if (spec->takesValue) {
        if (!hasInline) {
          if (i + 1 >= args.size()) throw Error("option '" + a + "' needs a value");
          inlineValue = args[++i];
        }
        values_[a].push_back(inlineValue);
      } else {
        if (hasInline) throw Error("option '" + a + "' takes no value");
        values_[a].push_back("");
      }
    } else {
      if (positional_.size() >= maxPositional)
        throw Error("'" + command + "' does not take the argument '" + a + "'");
      positional_.push_back(a);
    }
  }
}

bool Args::has(const std::string& name) const { return values_.count(name) != 0; }

std::optional<std::string> Args::find(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end()) return std::nullopt;
  return it->second.back();
}

std::string Args::get(const std::string& name, const std::string& fallback) const {
  auto v = find(name);
  return v ? *v : fallback;
}

std::vector<std::string> Args::all(const std::string& name) const {
  auto it = values_.find(name);
  return it == values_.end() ? std::vector<std::string>{} : it->second;
}

std::string Args::require(const std::string& name) const {
  auto v = find(name);
  if (!v || v->empty()) throw Error("'" + command_ + "' needs " + name);
  return *v;
}

void Args::parseSize(const std::string& text, int& width, int& height) {
  auto x = text.find('x');
  bool ok = x != std::string::npos && x > 0 && x + 1 < text.size();
  if (ok) {
    char* end = nullptr;
    long w = std::strtol(text.c_str(), &end, 10);
    ok = end == text.c_str() + x;
    long h = std::strtol(text.c_str() + x + 1, &end, 10);
    ok = ok && *end == '\0' && w >= 1 && w <= 8192 && h >= 1 && h <= 8192;
    width = static_cast<int>(w);
    height = static_cast<int>(h);
  }
  if (!ok) throw Error("--size '" + text + "' is not WIDTHxHEIGHT with both in 1..8192 (e.g. 512x512)");
}

std::array<float, 3> Args::parseVec3(const std::string& name, const std::string& text) {
  std::array<float, 3> v{};
  const char* p = text.c_str();
  bool ok = true;
  for (int i = 0; i < 3 && ok; ++i) {
    char* end = nullptr;
    double d = std::strtod(p, &end);
    ok = end != p && std::isfinite(d) && *end == (i < 2 ? ',' : '\0');
    v[i] = float(d);
    p = end + 1;
  }
  if (!ok) throw Error(name + " '" + text + "' is not three numbers X,Y,Z (e.g. 0,1,3.5)");
  return v;
}

int Args::parseInt(const std::string& name, const std::string& text, int lo, int hi) {
  char* end = nullptr;
  long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || v < lo || v > hi)
    throw Error(name + " '" + text + "' is not an integer in " + std::to_string(lo) + ".." +
                std::to_string(hi));
  return static_cast<int>(v);
}

}  // namespace voxlab
