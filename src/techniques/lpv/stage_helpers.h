// Helpers shared by the lpv stage files (grids.cpp defines them); not part of the technique's
// interface (stages.h).
#pragma once
#include <array>
#include <string>

#include "gpu/gl.h"
#include "graph/stage.h"
#include "techniques/lpv/stages.h"

namespace voxlab::lpv {

std::string voxelBuffer(int cascade);
ParamDesc resolutionParam();
ParamDesc fineExtentParam();
// lpv.steps; 0 (the default) sizes the propagation from the scene and the grid.
ParamDesc stepsParam();
// The steps the propagate stage runs: lpv.steps, or for 0 ceil(resolution / fine-extent), the steps
// light needs to cross the scene's largest extent in the fine cascade (whose cell is fine-extent x
// that extent / resolution), at most 64.
int propagationSteps(const ParamSet& p);
// Cell indices, so that the viewer's volume probe (a click on a cell of an lpv volume) sets them;
// -1 (the default) is the middle cell, larger values are clamped to the grid.
ParamDesc probeParam(const char* axis);
glm::ivec3 probeCell(const ParamSet& p);
TextureDesc shDesc(int res);
size_t cellCount(const ParamSet& p);
size_t voxelBufferBytes(const ParamSet& p);
void barrier();
std::array<gpu::LpvGrid, kCascades> readGrids(Blackboard& board);
void setGridUniforms(GLuint program, const gpu::LpvGrid& g);

}  // namespace voxlab::lpv
