#include "graph/reference_mode.h"

#include "core/error.h"

namespace voxlab {
namespace {

// Splits a reference mode into literal text and {name} references; calls text(piece) and
// name(piece) in order. Throws on an unmatched, nested or empty brace.
template <class Text, class Name>
void scanReferenceMode(const OutputDesc& desc, Text text, Name name) {
  const std::string& m = desc.referenceMode;
  size_t at = 0;
  while (at < m.size()) {
    const size_t open = m.find_first_of("{}", at);
    if (open == std::string::npos) {
      text(m.substr(at));
      return;
    }
    const size_t close = m[open] == '{' ? m.find('}', open + 1) : std::string::npos;
    if (close == std::string::npos || close == open + 1 || m.find('{', open + 1) < close)
      throw Error("output " + desc.name + ": reference mode '" + m +
                  "' has an unmatched or empty brace; expected text with {parameter} names, e.g. indirect-{paths.bounces}");
    text(m.substr(at, open - at));
    name(m.substr(open + 1, close - open - 1));
    at = close + 1;
  }
}

}  // namespace

std::vector<std::string> referenceModeParams(const OutputDesc& desc) {
  std::vector<std::string> names;
  scanReferenceMode(desc, [](const std::string&) {}, [&](const std::string& n) { names.push_back(n); });
  return names;
}

std::string referenceModeUnder(const OutputDesc& desc, const ParamSet& params) {
  std::string mode;
  scanReferenceMode(
      desc, [&](const std::string& t) { mode += t; },
      [&](const std::string& n) {
        if (!params.has(n))
          throw Error("output " + desc.name + ": reference mode '" + desc.referenceMode + "' names '" + n +
                      "', which is not a parameter of the technique; {name} must name one of its parameters");
        mode += params.desc(n).format(params.value(n));
      });
  return mode;
}

}  // namespace voxlab
