#include "graph/output.h"

#include <cstdlib>

#include "core/error.h"
#include "graph/param.h"

namespace voxlab {

const char* kindName(OutputKind k) {
  switch (k) {
    case OutputKind::Image2D: return "image2d";
    case OutputKind::Volume3D: return "volume3d";
    case OutputKind::Buffer: return "buffer";
  }
  return "?";
}

const char* semanticName(Semantic s) { return s.name(); }

bool conditionHolds(const std::string& c, const ParamSet& params, const std::string& what) {
  if (c.empty()) return true;
  if (size_t ge = c.find(">="); ge != std::string::npos) {
    const std::string number = c.substr(ge + 2);
    char* end = nullptr;
    const double least = std::strtod(number.c_str(), &end);
    if (number.empty() || *end) throw Error(what + ": condition '" + c + "' is not param>=number");
    return params.value(c.substr(0, ge)) >= least;
  }
  if (size_t gt = c.find('>'); gt != std::string::npos) {
    const std::string number = c.substr(gt + 1);
    char* end = nullptr;
    const double bound = std::strtod(number.c_str(), &end);
    if (number.empty() || *end) throw Error(what + ": condition '" + c + "' is not param>number");
    return params.value(c.substr(0, gt)) > bound;
  }
  const size_t eq = c.find('=');
  if (eq == std::string::npos)
    throw Error(what + ": condition '" + c + "' is not param=value, param>=number or param>number");
  const std::string name = c.substr(0, eq);
  return params.desc(name).format(params.value(name)) == c.substr(eq + 1);
}

bool isPlaceholderUnder(const OutputDesc& desc, const ParamSet& params) {
  return !conditionHolds(desc.placeholderUnless, params, "output " + desc.name + " placeholder");
}

OutputAddress OutputAddress::parse(const std::string& text) {
  OutputAddress a;
  std::string rest = text;
  if (auto at = rest.find('@'); at != std::string::npos) {
    std::string lv = rest.substr(at + 1);
    char* end = nullptr;
    long l = std::strtol(lv.c_str(), &end, 10);
    if (lv.empty() || *end || l < 0 || l > 64)
      throw Error("output address '" + text + "' has a bad level; expected technique/stage/output@LEVEL");
    a.level = int(l);
    rest = rest.substr(0, at);
  }
  auto s1 = rest.find('/');
  auto s2 = s1 == std::string::npos ? s1 : rest.find('/', s1 + 1);
  if (s1 == std::string::npos || s2 == std::string::npos || rest.find('/', s2 + 1) != std::string::npos)
    throw Error("output address '" + text + "' is not technique/stage/output[@level]");
  a.technique = rest.substr(0, s1);
  a.stage = rest.substr(s1 + 1, s2 - s1 - 1);
  a.output = rest.substr(s2 + 1);
  if (a.technique.empty() || a.stage.empty() || a.output.empty())
    throw Error("output address '" + text + "' is not technique/stage/output[@level]");
  return a;
}

std::string OutputAddress::str() const {
  return technique + "/" + stage + "/" + output + (level >= 0 ? "@" + std::to_string(level) : "");
}

}  // namespace voxlab
