#include "graph/stage.h"

#include "core/error.h"

namespace voxlab {

StageBuilder& StageBuilder::alongside(std::initializer_list<std::string> outputs) {
  for (const std::string& name : outputs) {
    bool found = false;
    for (auto& o : decl_.outputs)
      if (o.name == name) o.alongside = found = true;
    if (!found) throw Error("alongside: no output '" + name + "' is declared before it");
  }
  return *this;
}

OutputDesc& StageBuilder::output(const std::string& name, OutputKind kind, Semantic semantic,
                                 const std::string& help) {
  OutputDesc d;
  d.name = name;
  d.kind = kind;
  d.semantic = semantic;
  d.help = help;
  decl_.outputs.push_back(d);
  return decl_.outputs.back();
}

const char* probeSpaceName(ProbeSpace space) {
  switch (space) {
    case ProbeSpace::Screen: return "screen";
    case ProbeSpace::Volume: return "volume";
    case ProbeSpace::Light: return "light";
  }
  return "?";
}

std::vector<std::string> ProbeDesc::paramNames() const {
  std::vector<std::string> names;
  for (const std::string* n : {&x, &y, &z, &level})
    if (!n->empty()) names.push_back(*n);
  return names;
}

}  // namespace voxlab
