// Reference modes that depend on parameters. OutputDesc::referenceMode names the reference path
// tracer mode an output approximates ("full", "indirect-1", ...; reference/path_tracer.h). A mode
// may name parameters of the technique in braces, e.g. voxel-path-tracing's
// "indirect-{paths.bounces}": K bounces approximate the reference's indirect-K, so the mode follows
// the run. Every reader (voxlab run's comparison, voxlab gallery, voxlab list, the tests) reads a
// mode through referenceModeUnder with the run's parameters, never the declared text;
// Technique::validate() refuses a name the technique does not declare.
#pragma once
#include <string>
#include <vector>

#include "graph/output.h"
#include "graph/param.h"

namespace voxlab {

// desc.referenceMode with each "{name}" replaced by parameter name's value under 'params'
// (ParamDesc::format: "2", a choice by its name); "" when the output has no reference mode. Throws
// Error in one line naming the output and what is wrong: a name that is not a parameter of
// 'params', an unmatched or empty brace.
std::string referenceModeUnder(const OutputDesc& desc, const ParamSet& params);

// The parameter names desc.referenceMode refers to, in order ({} for a fixed mode). Throws as
// referenceModeUnder on an unmatched or empty brace.
std::vector<std::string> referenceModeParams(const OutputDesc& desc);

}  // namespace voxlab
