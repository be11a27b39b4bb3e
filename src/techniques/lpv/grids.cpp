// The parameters, resource names and sizes and the grid helpers the lpv stages share (see lpv.cpp
// for the overview and the choice of every default).
#include "techniques/lpv/stages.h"
#include "techniques/lpv/stage_helpers.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "scene/scene.h"
#include "techniques/common/voxel_space.h"
#include "techniques/lpv/sh.h"

namespace voxlab::lpv {

const char* const kCascadeNames[kCascades] = {"fine", "coarse"};
const char* const kChannelNames[3] = {"red", "green", "blue"};

std::string shVolume(const char* prefix, int cascade, int channel) {
  return std::string(prefix) + "-" + kCascadeNames[cascade] + "-" + kChannelNames[channel];
}
std::string voxelBuffer(int cascade) { return std::string("voxels-") + kCascadeNames[cascade]; }

// --- Parameters (one definition each; every stage that needs one declares the same) -------------

ParamDesc resolutionParam() {
  return ParamDesc::integer("lpv.resolution", 32, 8, 64, "cells along each axis of each cascade", "cells").pow2();
}
ParamDesc fineExtentParam() {
  return ParamDesc::real("lpv.fine-extent", 1.5, 0.25, 4.0,
                         "edge of the fine grid as a multiple of the scene's largest extent (1.5: the whole scene "
                         "inside the cascade blend shell)");
}
ParamDesc stepsParam() {
  return ParamDesc::integer("lpv.steps", 0, 0, 64,
                            "propagation steps (iterations); the light's frontier moves one cell per step, its bulk "
                            "as a random walk (lesson 05, step 11). 0 (scene): ceil(lpv.resolution / "
                            "lpv.fine-extent), the steps the frontier needs to cross the scene's largest extent in "
                            "the fine cascade (22 at the defaults); the coarse cascade's cells are lpv.cascade-ratio "
                            "larger, so it carries the light that much farther",
                            "steps");
}
int propagationSteps(const ParamSet& p) {
  const int steps = p.getInt("lpv.steps");
  if (steps > 0) return steps;
  const double acrossScene = std::ceil(double(p.getInt("lpv.resolution")) / double(p.getFloat("lpv.fine-extent")) - 1e-6);
  return std::clamp(int(acrossScene), 1, 64);
}
// Cell indices, so that the viewer's volume probe (a click on a cell of an lpv volume) sets them;
// -1 (the default) is the middle cell, larger values are clamped to the grid.
ParamDesc probeParam(const char* axis) {
  return ParamDesc::integer(std::string("probe.cell-") + axis, -1, -1, 1023,
                            std::string("picked cell along ") + axis + " (-1: the middle cell; clamped to the grid)",
                            "cells");
}

glm::ivec3 probeCell(const ParamSet& p) {
  int res = p.getInt("lpv.resolution");
  auto c = [&](const char* n) {
    const int v = p.getInt(n);
    return v < 0 ? res / 2 : std::min(v, res - 1);
  };
  return {c("probe.cell-x"), c("probe.cell-y"), c("probe.cell-z")};
}

TextureDesc shDesc(int res) {
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = GL_RGBA32F;
  d.size = {res, res, res};
  d.minFilter = d.magFilter = GL_LINEAR;
  return d;
}
size_t cellCount(const ParamSet& p) {
  const size_t res = size_t(p.getInt("lpv.resolution"));
  return res * res * res;
}
size_t voxelBufferBytes(const ParamSet& p) { return sizeof(gpu::LpvVoxel) * cellCount(p); }

float areaUnits(float cellSize, float voxelSize) {
  const double edge = std::ceil(double(cellSize) / double(voxelSize)) + 1.0;
  return float(std::min(65536.0, std::floor(double(1u << 31) / (edge * edge * edge))));
}
void barrier() {
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT |
                  GL_TEXTURE_UPDATE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}
std::array<gpu::LpvGrid, kCascades> readGrids(Blackboard& board) {
  std::array<gpu::LpvGrid, kCascades> g;
  auto bytes = board.buffer("lpv-grids").download(sizeof(g));
  std::memcpy(g.data(), bytes.data(), sizeof(g));
  return g;
}
void setGridUniforms(GLuint program, const gpu::LpvGrid& g) {
  setUniform(program, "u_gridOrigin", glm::vec3(g.originCell));
  setUniform(program, "u_cellSize", g.originCell.w);
  setUniform(program, "u_gridRes", int(g.centreRes.w));
}
}  // namespace voxlab::lpv
