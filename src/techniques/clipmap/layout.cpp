// The clipmap's parameters, layout and camera path, and the uniforms its shaders share (see
// clipmap.cpp for the overview).
#include "techniques/clipmap/stages.h"
#include "techniques/clipmap/stage_helpers.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/log.h"
#include "gpu/shader_library.h"
#include "scene/scene.h"

namespace voxlab::clipmap {

static constexpr int64_t kMaxCell = int64_t(1) << 30;  // shaders hold cells in int32
// The per-level counters, then one more: fixed-point light sums that wrapped past 2^32.
size_t countersBytes(int levels) { return size_t(4 * (kCountersPerLevel * levels + 1)); }

// --- Parameters and layout ------------------------------------------------------------------------

std::vector<ParamDesc> layoutParams() {
  return {
      ParamDesc::integer("clipmap.levels", 5, 1, kMaxLevels,
                         "clip levels L; level k has voxels 2^k times level 0's (1: one level and the mips of it)", "levels"),
      // N >= 8: the coarsest level then has at least one mip, which the cone tracer's far phase reads.
      ParamDesc::integer("clipmap.resolution", 32, 8, 64, "cells N along each axis of every level", "voxels").pow2(),
      ParamDesc::fromScene("clipmap.voxel-size", 1e-4, 100.0,
                           "edge s_0 of a level-0 voxel; scene: the scene's largest extent E times the power of two that lets "
                           "the coarsest level span at least 8 E",
                           "m"),
      ParamDesc::choice("clipmap.faces", {"isotropic", "anisotropic"}, 1,
                        "isotropic: one value per cell; anisotropic: also six directional values, each showing a cone "
                        "travelling that way the fronts of the surfaces it sees, filtered between levels front to back "
                        "(the under operator)"),
      ParamDesc::real("clipmap.look-ahead", 0.125, 0.0, 0.25,
                      "how far each level's centre lies ahead of the camera along the view direction, as a fraction of "
                      "the level's extent N s_k (up to 1/4, which keeps every level inside the next)",
                      "extents"),
  };
}

// What the cells hold (as vct-grid's and svo's inject.mode): the scene's direct light, or one
// uniform radiance in every occupied cell (the furnace and dense-grid equivalence tests).
std::vector<ParamDesc> injectParams() {
  return {
      ParamDesc::choice("inject.mode", {"direct-light", "uniform"}, 0,
                        "what voxels hold: the scene's direct light, or one uniform radiance (a furnace test)"),
      ParamDesc::real("inject.uniform-radiance", 0.5, 0.0, 1.0, "radiance every voxel gets in uniform mode", "W/(m^2 sr)"),
  };
}

ParamDesc fixedPointParam() {
  return ParamDesc::integer("clipmap.fixed-point-bits", 14, 8, 30,
                            "fraction bits b of the fixed-point radiance sums: steps of 2^-b; a cell's 32-bit sums "
                            "overflow when its fragments' light adds up to 2^(32-b) (every wrap is counted and reported)",
                            "bits");
}

ParamDesc atlasFormatParam() {
  return ParamDesc::choice("clipmap.format", {"rgba8", "rgba16f"}, 1,
                           "what the atlas, its mips and the unrolled levels store: rgba8 clamps radiance to [0,1] (the "
                           "cells by a lamp or in the sun lose most of their light); rgba16f keeps up to 64 W/(m^2 sr) "
                           "in half floats (HDR cells, twice the memory)");
}
GLenum atlasFormat(const ParamSet& params) {
  return params.getChoice("clipmap.format") == "rgba16f" ? GL_RGBA16F : GL_RGBA8;
}
std::string atlasFormatDefines(const ParamSet& params) {
  return atlasFormat(params) == GL_RGBA16F ? "#define CLIPMAP_ATLAS_FORMAT rgba16f\n" : "";
}
static int maxRadianceLog2(const ParamSet& params) { return atlasFormat(params) == GL_RGBA16F ? 6 : 0; }  // 64 or 1

// Words per cell of the accumulators (shaders/clipmap/clipmap.glsl, accumulatorIndex): 4 with one
// face; with six, also the facing code and per direction the fronts' fragments and light.
static uint32_t cellWords(const ParamSet& params) { return facesOf(params) == 7 ? 32u : 4u; }

// The accumulators' uniforms of shaders/clipmap/clipmap.glsl (u_cellWords, u_accumulatorLevels,
// u_fixedScale, u_maxRadiance).
void setAccumulatorUniforms(GLuint program, const ParamSet& params, int accumulatorLevels) {
  setUniform(program, "u_cellWords", unsigned(cellWords(params)));
  setUniform(program, "u_accumulatorLevels", accumulatorLevels);
  const int bits = params.getInt("clipmap.fixed-point-bits");
  const int radianceBits = maxRadianceLog2(params);
  setUniform(program, "u_fixedScale", float(std::ldexp(1.0, bits)));
  setUniform(program, "u_maxRadiance", float(std::ldexp(1.0, radianceBits)));
}

// One line on stderr and a statistic when fixed-point light sums wrapped past 2^32 (or one
// fragment's light alone passed it).
void reportOverflow(StageContext& ctx, const char* stage, uint32_t wraps) {
  ctx.stats["accumulator_overflows"] = wraps;
  if (wraps == 0) return;
  const int bits = ctx.params.getInt("clipmap.fixed-point-bits");
  log::warn(std::string("clipmap/") + stage + ": " + std::to_string(wraps) + " fixed-point light sums overflowed " +
            "32 bits (clipmap.fixed-point-bits=" + std::to_string(bits) + "); lower clipmap.fixed-point-bits, or " +
            "clipmap.voxel-size so that fewer triangles share a cell");
}

std::vector<ParamDesc> pathParams() {
  return {
      ParamDesc::real("clipmap.path-step.x", 0.0, -1e6, 1e6, "x of the camera's displacement per path move", "m"),
      ParamDesc::real("clipmap.path-step.y", 0.0, -1e6, 1e6, "y of the camera's displacement per path move", "m"),
      ParamDesc::real("clipmap.path-step.z", 0.0, -1e6, 1e6, "z of the camera's displacement per path move", "m"),
      ParamDesc::integer("clipmap.path-moves", 0, 0, 256,
                         "camera moves after the first build; the update stage runs one per iteration", "moves"),
      ParamDesc::choice("clipmap.policy", {"all", "priority"}, 0,
                        "all: every level follows every move; priority: one level per move, finer levels more often "
                        "(level i when (move - 2^i + 1) mod 2^(i+1) = 0)"),
  };
}

Layout layoutOf(const ParamSet& params, const Scene& scene) {
  Layout l;
  l.levels = params.getInt("clipmap.levels");
  l.n = params.getInt("clipmap.resolution");
  double s0 = params.value("clipmap.voxel-size");
  if (std::isnan(s0)) {
    glm::vec3 e = scene.bounds.valid() ? scene.bounds.extent() : glm::vec3(1.0f);
    double extent = std::max({double(e.x), double(e.y), double(e.z), 1e-3});
    // A power-of-two fraction of the extent (not of a metre), so that the same scene in other units
    // gets the same lattice relative to its geometry (lights.scaled_cornell_box).
    s0 = extent * std::exp2(std::ceil(std::log2(8.0 / (double(l.n) * double(int64_t(1) << (l.levels - 1))))));
  }
  l.voxelSize0 = s0;
  return l;
}

int facesOf(const ParamSet& params) { return params.getChoice("clipmap.faces") == "anisotropic" ? 7 : 1; }

int mipCount(int n) {
  int m = 0;
  while ((n >> (m + 1)) >= 4) ++m;
  return m;
}

TextureDesc atlasDesc(const ParamSet& params) {
  const int n = params.getInt("clipmap.resolution"), b = n + 2;
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = atlasFormat(params);
  d.size = {facesOf(params) * b, params.getInt("clipmap.levels") * b, b};
  return d;
}

size_t accumulatorBytes(const ParamSet& p, int accumulatorLevels) {
  const size_t n = size_t(p.getInt("clipmap.resolution"));
  return 4 * size_t(cellWords(p)) * size_t(accumulatorLevels) * n * n * n;
}

std::vector<PathState> cameraPath(const ParamSet& params, const Scene& scene, const ViewState& view) {
  const Layout layout = layoutOf(params, scene);
  const glm::vec3 camera = view.position;
  // lookAtRH's third row is minus the view direction; the path keeps the orientation.
  const glm::dvec3 forward = -glm::dvec3(view.view[0][2], view.view[1][2], view.view[2][2]);
  const glm::dvec3 lead = params.value("clipmap.look-ahead") * forward;
  const glm::dvec3 step(params.value("clipmap.path-step.x"), params.value("clipmap.path-step.y"),
                        params.value("clipmap.path-step.z"));
  const int moves = params.getInt("clipmap.path-moves");
  const Policy policy = params.getChoice("clipmap.policy") == "priority" ? Policy::Priority : Policy::All;
  std::vector<PathState> path;
  PathState s{snapOrigins(layout, glm::dvec3(camera), lead), std::vector<int>(size_t(layout.levels), 0),
              glm::dvec3(camera)};
  path.push_back(s);
  for (int j = 1; j <= moves; ++j) {
    s.camera = glm::dvec3(camera) + double(j) * step;
    auto target = snapOrigins(layout, s.camera, lead);
    for (int k = 0; k < layout.levels; ++k) {
      if (levelScheduled(policy, k, layout.levels, j - 1)) {
        s.origins[size_t(k)] = target[size_t(k)];
        s.lag[size_t(k)] = 0;
      } else {
        ++s.lag[size_t(k)];
      }
    }
    path.push_back(s);
  }
  for (const PathState& p : path)
    for (const Cell& o : p.origins)
      if (std::abs(o.x) > kMaxCell || std::abs(o.y) > kMaxCell || std::abs(o.z) > kMaxCell)
        throw Error("clipmap: a level origin " + describe(o) + " lies beyond 2^30 cells of the world origin; move the " +
                    "camera (or the path) closer, or raise clipmap.voxel-size");
  return path;
}

ViewState pathEndView(const ParamSet& params, const ViewState& view) {
  const int moves = params.getInt("clipmap.path-moves");
  const glm::dvec3 step(params.value("clipmap.path-step.x"), params.value("clipmap.path-step.y"),
                        params.value("clipmap.path-step.z"));
  ViewState moved = view;
  if (moves == 0 || step == glm::dvec3(0.0)) return moved;
  // The end of the path as cameraPath computes the anchor's (in double, then rounded once).
  moved.position = glm::vec3(glm::dvec3(view.position) + double(moves) * step);
  // lookAtRH: column 3 holds (-dot(s, eye), -dot(u, eye), dot(f, eye)) with rows s, u, -f.
  for (int i = 0; i < 3; ++i)
    moved.view[3][i] = -glm::dot(glm::vec3(view.view[0][i], view.view[1][i], view.view[2][i]), moved.position);
  return moved;
}

void PathGBufferStage::declare(StageBuilder& b) const {
  GBufferStage::declare(b);
  for (const auto& p : pathParams()) b.param(p);
}

void PathGBufferStage::execute(StageContext& ctx) {
  const ViewState moved = pathEndView(ctx.params, ctx.view);
  StageContext at{ctx.scene, ctx.gpuScene, ctx.params, ctx.board, ctx.shaders, moved, ctx.stats, ctx.iteration};
  GBufferStage::execute(at);
}

// The uniforms every clipmap shader shares (shaders/clipmap/clipmap.glsl).
void setClipUniforms(GLuint program, const Layout& layout, const std::vector<Cell>& origins) {
  setUniform(program, "u_clipN", layout.n);
  setUniform(program, "u_clipLevels", layout.levels);
  std::vector<int> o(3 * kMaxLevels, 0);
  for (int k = 0; k < layout.levels; ++k)
    for (int i = 0; i < 3; ++i) o[size_t(3 * k + i)] = int(origins[size_t(k)][i]);
  GLint loc = glGetUniformLocation(program, "u_clipOrigin");
  if (loc >= 0) glProgramUniform3iv(program, loc, kMaxLevels, o.data());
}

void dispatchBox(GLuint program, const Box& box) {
  glm::ivec3 lo(box.lo), size(box.hi - box.lo);
  setUniform(program, "u_boxLo", lo);
  setUniform(program, "u_boxSize", size);
  dispatchCompute(size, {4, 4, 4});
}

}  // namespace voxlab::clipmap
