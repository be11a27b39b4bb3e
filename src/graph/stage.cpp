#include "graph/stage.h"

namespace voxlab {

OutputDesc& StageBuilder::output(const std::string& name, OutputKind kind, Semantic semantic,
                                 const std::string& help) {
  OutputDesc d;
  d.name = name;
  d.kind = kind;
  d.semantic = semantic;
  d.help = help;
  d.tier = (semantic == Semantic::Occupancy || semantic == Semantic::Points)
               ? CaptureTier::Exact
               : CaptureTier::Tolerance;
  decl_.outputs.push_back(d);
  return decl_.outputs.back();
}

}  // namespace voxlab
