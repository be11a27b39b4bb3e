#include "techniques/clipmap/stages.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include "common/shared.h"
#include "core/error.h"
#include "core/log.h"
#include "gpu/shader_library.h"
#include "scene/gpu_scene.h"
#include "scene/scene.h"
#include "techniques/common/sky.h"
#include "techniques/common/cone_setup.h"
#include "techniques/vct_grid/cone_layout.h"

namespace voxlab::clipmap {

static constexpr int kMaxLevels = 8;        // CLIPMAP_MAX_LEVELS in shaders/clipmap/clipmap.glsl
static constexpr int kCountersPerLevel = 5; // cleared, pairs, resolved, filtered, guards
static constexpr int64_t kMaxCell = int64_t(1) << 30;  // shaders hold cells in int32
// The per-level counters, then one more: cells whose fragments overflowed the fixed-point sums.
static size_t countersBytes(int levels) { return size_t(4 * (kCountersPerLevel * levels + 1)); }

// --- Parameters and layout ------------------------------------------------------------------------

std::vector<ParamDesc> layoutParams() {
  return {
      ParamDesc::integer("clipmap.levels", 5, 2, kMaxLevels, "clip levels L; level k has voxels 2^k times level 0's", "levels"),
      ParamDesc::integer("clipmap.resolution", 32, 8, 64, "cells N along each axis of every level", "voxels").pow2(),
      ParamDesc::fromScene("clipmap.voxel-size", 1e-4, 100.0,
                           "edge s_0 of a level-0 voxel; scene: the scene's largest extent E times the power of two that lets "
                           "the coarsest level span at least 8 E",
                           "m"),
      ParamDesc::choice("clipmap.faces", {"isotropic", "anisotropic"}, 0,
                        "isotropic: one value per cell; anisotropic: also six directional values, filtered between "
                        "levels front to back (the under operator)"),
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
                            "fraction bits b of the fixed-point radiance sums: steps of 2^-b; a cell holds 2^(32-b) "
                            "fragments before its 32-bit sums can overflow (such cells are counted and reported)",
                            "bits");
}

// The fixed-point uniforms of shaders/clipmap/clipmap.glsl (u_fixedScale, u_maxFragments).
static void setFixedPointUniforms(GLuint program, const ParamSet& params) {
  const int bits = params.getInt("clipmap.fixed-point-bits");
  setUniform(program, "u_fixedScale", float(std::ldexp(1.0, bits)));
  setUniform(program, "u_maxFragments", unsigned(uint64_t(1) << (32 - bits)));
}

// One line on stderr and a statistic when cells may have overflowed their fixed-point sums.
static void reportOverflow(StageContext& ctx, const char* stage, uint32_t cells) {
  ctx.stats["accumulator_overflow_cells"] = cells;
  if (cells == 0) return;
  const int bits = ctx.params.getInt("clipmap.fixed-point-bits");
  log::warn(std::string("clipmap/") + stage + ": " + std::to_string(cells) + " cells received " +
            std::to_string(uint64_t(1) << (32 - bits)) + " fragments or more, so their fixed-point sums may have " +
            "overflowed (clipmap.fixed-point-bits=" + std::to_string(bits) + "); lower clipmap.fixed-point-bits, or " +
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
  d.format = GL_RGBA8;
  d.size = {facesOf(params) * b, params.getInt("clipmap.levels") * b, b};
  return d;
}

static TextureDesc mipsDesc(const ParamSet& params) {
  const int n = params.getInt("clipmap.resolution");
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = GL_RGBA8;
  d.size = {n, n, n};
  d.levels = mipCount(n) + 1;
  d.minFilter = GL_LINEAR_MIPMAP_LINEAR;
  return d;
}

static TextureDesc logicalDesc(const ParamSet& params) {
  const int n = params.getInt("clipmap.resolution");
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = GL_RGBA8;
  d.size = {n, n * params.getInt("clipmap.levels"), n};
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}

static size_t accumulatorBytes(const ParamSet& p) {
  const size_t n = size_t(p.getInt("clipmap.resolution"));
  return 16 * size_t(p.getInt("clipmap.levels")) * n * n * n;
}

std::vector<PathState> cameraPath(const ParamSet& params, const Scene& scene, const glm::vec3& camera) {
  const Layout layout = layoutOf(params, scene);
  const glm::dvec3 step(params.value("clipmap.path-step.x"), params.value("clipmap.path-step.y"),
                        params.value("clipmap.path-step.z"));
  const int moves = params.getInt("clipmap.path-moves");
  const Policy policy = params.getChoice("clipmap.policy") == "priority" ? Policy::Priority : Policy::All;
  std::vector<PathState> path;
  PathState s{snapOrigins(layout, glm::dvec3(camera)), std::vector<int>(size_t(layout.levels), 0)};
  path.push_back(s);
  for (int j = 1; j <= moves; ++j) {
    auto target = snapOrigins(layout, glm::dvec3(camera) + double(j) * step);
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
static void setClipUniforms(GLuint program, const Layout& layout, const std::vector<Cell>& origins) {
  setUniform(program, "u_clipN", layout.n);
  setUniform(program, "u_clipLevels", layout.levels);
  std::vector<int> o(3 * kMaxLevels, 0);
  for (int k = 0; k < layout.levels; ++k)
    for (int i = 0; i < 3; ++i) o[size_t(3 * k + i)] = int(origins[size_t(k)][i]);
  GLint loc = glGetUniformLocation(program, "u_clipOrigin");
  if (loc >= 0) glProgramUniform3iv(program, loc, kMaxLevels, o.data());
}

static void dispatchBox(GLuint program, const Box& box) {
  glm::ivec3 lo(box.lo), size(box.hi - box.lo);
  setUniform(program, "u_boxLo", lo);
  setUniform(program, "u_boxSize", size);
  dispatchCompute(size, {4, 4, 4});
}

static constexpr GLbitfield kAllShaderWrites =
    GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
    GL_BUFFER_UPDATE_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT;

// Spreads the low 21 bits of v to every third bit (bit i to bit 3i).
static uint64_t spreadBits3(uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffull;
  v = (v | v << 16) & 0x1f0000ff0000ffull;
  v = (v | v << 8) & 0x100f00f00f00f00full;
  v = (v | v << 4) & 0x10c30c30c30c30c3ull;
  v = (v | v << 2) & 0x1249249249249249ull;
  return v;
}

TriangleOrder triangleOrder(const Scene& scene) {
  // Runs of 512 triangles: only a first test before each triangle's own (voxelizeEntries).
  constexpr uint32_t kRunTriangles = 512;
  const size_t triangles = scene.triangleCount();
  TriangleOrder order;
  order.triangles.resize(triangles);
  order.lo.resize(triangles);
  order.hi.resize(triangles);
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (uint32_t v : scene.indices) {
    lo = glm::min(lo, scene.positions[v]);
    hi = glm::max(hi, scene.positions[v]);
  }
  // The Morton code of each centroid on a 2^21 lattice over the scene's bounds.
  const glm::dvec3 scale = double((1 << 21) - 1) / glm::max(glm::dvec3(hi) - glm::dvec3(lo), glm::dvec3(1e-30));
  std::vector<uint64_t> code(triangles);
  for (size_t t = 0; t < triangles; ++t) {
    glm::dvec3 c(0.0);
    for (int i = 0; i < 3; ++i) c += glm::dvec3(scene.positions[scene.indices[3 * t + size_t(i)]]);
    const glm::dvec3 q = glm::clamp((c / 3.0 - glm::dvec3(lo)) * scale, glm::dvec3(0.0), glm::dvec3((1 << 21) - 1));
    code[t] = spreadBits3(uint64_t(q.x)) | spreadBits3(uint64_t(q.y)) << 1 | spreadBits3(uint64_t(q.z)) << 2;
  }
  for (const DrawRange& d : scene.draws) {
    const uint32_t first = d.firstIndex / 3, count = d.indexCount / 3;
    auto begin = order.triangles.begin() + first, end = begin + count;
    for (uint32_t t = 0; t < count; ++t) begin[t] = first + t;
    std::stable_sort(begin, end, [&](uint32_t a, uint32_t b) { return code[a] < code[b]; });
    for (uint32_t j = first; j < first + count; ++j) {
      glm::vec3 tlo(1e30f), thi(-1e30f);
      for (int i = 0; i < 3; ++i) {
        const glm::vec3& p = scene.positions[scene.indices[3 * size_t(order.triangles[j]) + size_t(i)]];
        tlo = glm::min(tlo, p);
        thi = glm::max(thi, p);
      }
      order.lo[j] = tlo, order.hi[j] = thi;
    }
    for (uint32_t t = 0; t < count; t += kRunTriangles) {
      TriangleRun c{first + t, std::min(kRunTriangles, count - t), d.material, glm::vec3(1e30f), glm::vec3(-1e30f)};
      for (uint32_t j = c.firstTriangle; j < c.firstTriangle + c.triangles; ++j) {
        c.lo = glm::min(c.lo, order.lo[j]);
        c.hi = glm::max(c.hi, order.hi[j]);
      }
      order.runs.push_back(c);
    }
  }
  return order;
}

const TriangleOrder& TriangleOrderCache::get(const Scene& scene) {
  if (scene_ != &scene || triangles_ != scene.triangleCount()) {
    order_ = triangleOrder(scene);
    scene_ = &scene;
    triangles_ = scene.triangleCount();
  }
  return order_;
}

bool mayReach(const Layout& layout, const Entry& e, const glm::vec3& lo, const glm::vec3& hi) {
  // The shader's cell coordinates are fl(p * c), c = u_cellsPerMetre[k]: p * c is exact in double
  // and rounding to float moves it by at most 2^-24 of itself, so [down, up] holds the shader's.
  const double c = double(float(1.0 / layout.voxelSize(e.level)));
  const glm::dvec3 wl = glm::dvec3(lo) * c, wh = glm::dvec3(hi) * c;
  const glm::dvec3 down = wl - glm::abs(wl) * 0x1p-22 - 1e-30, up = wh + glm::abs(wh) * 0x1p-22 + 1e-30;
  // It visits cells floor(lo) .. floor(hi) inside [box.lo, box.hi) and leaves those in
  // [skip.lo, skip.hi) alone.
  const bool meets = glm::all(glm::greaterThanEqual(up, glm::dvec3(e.box.lo))) &&
                     glm::all(glm::lessThan(down, glm::dvec3(e.box.hi)));
  const bool skipped = !e.skip.empty() && glm::all(glm::greaterThanEqual(down, glm::dvec3(e.skip.lo))) &&
                       glm::all(glm::lessThan(up, glm::dvec3(e.skip.hi)));
  return meets && !skipped;
}

// Voxelizes and injects 'entries' into the accumulators bound at CLIPMAP_BINDING_ACCUM, one pass
// per group of entries (level, box, skip); a group holds at most 60000 / (7 N^2) entries, so no
// invocation's loops pass llvmpipe's limit of 65535 iterations. A triangle is dispatched for a
// group when mayReach holds for one of its entries (a full build's coarse levels, whose covered
// block holds the whole scene, dispatch nothing); the runs' bounds are tested first, so a move
// looks at the triangles of a few runs only.
int voxelizeEntries(StageContext& ctx, const Layout& layout, const std::vector<Cell>& origins,
                    const std::vector<Entry>& entries, const TriangleOrder& order, const std::string& visitList,
                    int& runs, int& triangles) {
  const int n = layout.n;
  const size_t perGroup = std::clamp<size_t>(size_t(60000 / (7 * n * n)), 1, 40);  // CLIPMAP_MAX_ENTRIES
  // Per group, the triangles to dispatch, in order (so grouped by material): one list for the
  // whole call, uploaded once.
  struct Dispatch {
    uint32_t material, first, count;
  };
  struct Group {
    size_t first, count;
    std::vector<Dispatch> dispatches;
  };
  std::vector<Group> groups;
  std::vector<uint32_t> visit;
  runs = 0;
  for (size_t first = 0; first < entries.size(); first += perGroup) {
    Group g{first, std::min(perGroup, entries.size() - first), {}};
    auto reaches = [&](const glm::vec3& lo, const glm::vec3& hi) {
      for (size_t i = 0; i < g.count; ++i)
        if (mayReach(layout, entries[first + i], lo, hi)) return true;
      return false;
    };
    for (const TriangleRun& c : order.runs) {
      if (!reaches(c.lo, c.hi)) continue;
      ++runs;
      for (uint32_t j = c.firstTriangle; j < c.firstTriangle + c.triangles; ++j) {
        if (!reaches(order.lo[j], order.hi[j])) continue;
        if (g.dispatches.empty() || g.dispatches.back().material != c.material)
          g.dispatches.push_back({c.material, uint32_t(visit.size()), 0});
        visit.push_back(order.triangles[j]);
        ++g.dispatches.back().count;
      }
    }
    groups.push_back(std::move(g));
  }
  triangles = int(visit.size());
  if (visit.empty()) return int(groups.size());
  Buffer& visitBuffer = ctx.board.ensureBuffer(visitList, 4 * visit.size());
  visitBuffer.upload(visit.data(), 4 * visit.size());

  GLuint vox = ctx.shaders.program({"clipmap/voxelize.comp.glsl"});
  setClipUniforms(vox, layout, origins);
  setUniform(vox, "u_mode", ctx.params.getChoice("inject.mode") == "uniform" ? 1 : 0);
  setUniform(vox, "u_uniformRadiance", glm::vec3(ctx.params.getFloat("inject.uniform-radiance")));
  setFixedPointUniforms(vox, ctx.params);
  std::vector<float> cellsPerMetre(kMaxLevels, 0.0f), cellSize(kMaxLevels, 0.0f);
  for (int k = 0; k < layout.levels; ++k) {
    cellsPerMetre[size_t(k)] = float(1.0 / layout.voxelSize(k));
    cellSize[size_t(k)] = float(layout.voxelSize(k));
  }
  glProgramUniform1fv(vox, glGetUniformLocation(vox, "u_cellsPerMetre"), kMaxLevels, cellsPerMetre.data());
  glProgramUniform1fv(vox, glGetUniformLocation(vox, "u_cellSize"), kMaxLevels, cellSize.data());
  glUseProgram(vox);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_MATERIALS, ctx.gpuScene.materials().id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_SCENE_VERTICES, ctx.gpuScene.vertices().id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_SCENE_INDICES, ctx.gpuScene.indices().id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_TRIANGLE_LIST, visitBuffer.id());
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  ctx.gpuScene.bindCoverage();
  glBindTextureUnit(2, ctx.board.texture("shadow-map").id());
  const GLint materialLoc = glGetUniformLocation(vox, "u_materialIndex");
  for (const Group& g : groups) {
    if (g.dispatches.empty()) continue;
    std::vector<int> level(g.count);
    std::vector<glm::ivec3> lo(g.count), hi(g.count), skipLo(g.count), skipHi(g.count);
    for (size_t i = 0; i < g.count; ++i) {
      const Entry& e = entries[g.first + i];
      level[i] = e.level;
      lo[i] = glm::ivec3(e.box.lo), hi[i] = glm::ivec3(e.box.hi);
      skipLo[i] = glm::ivec3(e.skip.lo), skipHi[i] = glm::ivec3(e.skip.hi);
    }
    setUniform(vox, "u_entryCount", int(g.count));
    glProgramUniform1iv(vox, glGetUniformLocation(vox, "u_entryLevel"), GLsizei(g.count), level.data());
    glProgramUniform3iv(vox, glGetUniformLocation(vox, "u_entryLo"), GLsizei(g.count), &lo[0].x);
    glProgramUniform3iv(vox, glGetUniformLocation(vox, "u_entryHi"), GLsizei(g.count), &hi[0].x);
    glProgramUniform3iv(vox, glGetUniformLocation(vox, "u_entrySkipLo"), GLsizei(g.count), &skipLo[0].x);
    glProgramUniform3iv(vox, glGetUniformLocation(vox, "u_entrySkipHi"), GLsizei(g.count), &skipHi[0].x);
    for (const Dispatch& d : g.dispatches) {
      glProgramUniform1i(vox, materialLoc, int(d.material));
      ctx.gpuScene.bindMaterialTextures(d.material);
      setUniform(vox, "u_firstTriangle", unsigned(d.first));
      setUniform(vox, "u_triangleCount", unsigned(d.count));
      dispatchCompute({int(d.count), 1, 1}, {64, 1, 1});
    }
  }
  glMemoryBarrier(kAllShaderWrites);
  return int(groups.size());
}

// --- Anchor ---------------------------------------------------------------------------------------

// At most 3 exposed slabs per level, each cut into at most 6 boxes by the covered block, plus at
// most 6 boxes of cells that left the covered block.
static constexpr size_t kMaxSlabsPerLevel = 24;
static size_t slabBytes(int levels) { return sizeof(SlabRecord) * kMaxSlabsPerLevel * size_t(levels); }

// The records of the boxes a move voxelizes directly (its plans from origins 'before', empty
// for a full build), with where each lands in the physical texture.
static std::vector<SlabRecord> slabRecords(const Layout& layout, const std::vector<Cell>& before,
                                           const std::vector<LevelPlan>& plans) {
  std::vector<SlabRecord> slabs;
  for (int k = 0; k < layout.levels; ++k) {
    const double s = layout.voxelSize(k);
    const Box previous = before.empty() ? Box{} : region(before[size_t(k)], layout.n);
    for (const Box& box : plans[size_t(k)].direct) {
      SlabRecord r{};
      r.lo = glm::vec4(glm::vec3(glm::dvec3(box.lo) * s), float(k));
      r.hi = glm::vec4(glm::vec3(glm::dvec3(box.hi) * s), float(box.volume()));
      const glm::ivec3 t = toroidal(box.lo, layout.n);
      int pieces = 1;
      for (int i = 0; i < 3; ++i) {
        r.cellLo[i] = int32_t(box.lo[i]);
        r.cellHi[i] = int32_t(box.hi[i]);
        r.physLo[i] = t[i];
        if (int64_t(t[i]) + (box.hi[i] - box.lo[i]) > layout.n) pieces *= 2;  // wraps past texel N-1
      }
      r.cellLo[3] = previous.contains(box.lo) ? 1 : 0;
      r.physLo[3] = pieces;
      slabs.push_back(r);
    }
  }
  return slabs;
}

static PlanRecord planRecord(uint32_t move, int k, const LevelPlan& p) {
  return {move, uint32_t(k), uint32_t(p.exposedCells), uint32_t(p.directCells), uint32_t(p.coverageChanged),
          uint32_t(p.refilteredCells), {int32_t(p.delta.x), int32_t(p.delta.y), int32_t(p.delta.z)}};
}

static BufferLayout planLayout() {
  BufferLayout plan;
  plan.stride = sizeof(PlanRecord);
  plan.fields = {{"move", FieldType::U32, 0},         {"level", FieldType::U32, 4},   {"exposed", FieldType::U32, 8},
                 {"direct", FieldType::U32, 12},      {"coverage-changed", FieldType::U32, 16},
                 {"refiltered", FieldType::U32, 20},  {"delta.x", FieldType::I32, 24}, {"delta.y", FieldType::I32, 28},
                 {"delta.z", FieldType::I32, 32}};
  return plan;
}

static BufferLayout slabLayout(const std::string& countResource) {
  BufferLayout slabs;
  slabs.stride = sizeof(SlabRecord);
  slabs.fields = {{"min", FieldType::Vec4, 0, FieldRole::Position}, {"max", FieldType::Vec4, 16},
                  {"cell.x", FieldType::I32, 32},  {"cell.y", FieldType::I32, 36},  {"cell.z", FieldType::I32, 40},
                  {"was-inside", FieldType::I32, 44}, {"end.x", FieldType::I32, 48}, {"end.y", FieldType::I32, 52},
                  {"end.z", FieldType::I32, 56},    {"texel.x", FieldType::I32, 64}, {"texel.y", FieldType::I32, 68},
                  {"texel.z", FieldType::I32, 72},  {"physical-boxes", FieldType::I32, 76}};
  slabs.countResource = countResource;
  return slabs;
}

void AnchorStage::declare(StageBuilder& b) const {
  for (const auto& p : layoutParams()) b.param(p);
  for (const auto& p : pathParams()) b.param(p);
  b.readView();
  BufferLayout levels;
  levels.stride = sizeof(LevelRecord);
  levels.fields = {{"min", FieldType::Vec4, 0},       {"max", FieldType::Vec4, 16},     {"origin.x", FieldType::I32, 32},
                   {"origin.y", FieldType::I32, 36},  {"origin.z", FieldType::I32, 40}, {"lag", FieldType::I32, 44},
                   {"offset.x", FieldType::I32, 48},  {"offset.y", FieldType::I32, 52}, {"offset.z", FieldType::I32, 56},
                   {"n", FieldType::I32, 60}};
  b.output("clip-levels", OutputKind::Buffer, kClipLevels,
           "one record per level after the last move: world box (min, level; max, voxel size), origin o_k in cells, "
           "moves since its last update, toroidal offset T_k = o_k mod N")
      .layout = levels;
  b.output("clip-plan", OutputKind::Buffer, Semantic::Scalar,
           "per move and level, the planner's cell counts: exposed (N^3 - prod(N - |d_i|)), voxelized directly, "
           "changed coverage, refiltered; and the move d in cells")
      .layout = planLayout();
  b.output("clip-slabs", OutputKind::Buffer, Semantic::Points,
           "the boxes of cells the last move voxelizes directly (disjoint exposed slabs; cells that left the covered "
           "block): world box (min, level; max, cells), cell range, the physical texel of its min corner and how "
           "many physical boxes it splits into where it wraps")
      .layout = slabLayout("clip-slabs.count");
  b.write("clip-slabs.count");
  b.buffer("clip-slabs", [](const ParamSet& p, const ViewState&) { return slabBytes(p.getInt("clipmap.levels")); });
  b.buffer("clip-levels", [](const ParamSet& p, const ViewState&) { return sizeof(LevelRecord) * size_t(p.getInt("clipmap.levels")); });
  b.buffer("clip-plan", [](const ParamSet& p, const ViewState&) {
    return sizeof(PlanRecord) * size_t(p.getInt("clipmap.levels")) * size_t(p.getInt("clipmap.path-moves") + 1);
  });
}

void AnchorStage::execute(StageContext& ctx) {
  const Layout layout = layoutOf(ctx.params, ctx.scene);
  const auto path = cameraPath(ctx.params, ctx.scene, ctx.view.position);
  std::vector<LevelRecord> levels;
  const PathState& last = path.back();
  for (int k = 0; k < layout.levels; ++k) {
    const Cell& o = last.origins[size_t(k)];
    const double s = layout.voxelSize(k);
    LevelRecord r{};
    r.lo = glm::vec4(glm::vec3(glm::dvec3(o) * s), float(k));
    r.hi = glm::vec4(glm::vec3(glm::dvec3(o + Cell(layout.n)) * s), float(s));
    glm::ivec3 t = toroidal(o, layout.n);
    for (int i = 0; i < 3; ++i) r.origin[i] = int32_t(o[i]), r.offset[i] = t[i];
    r.lag = last.lag[size_t(k)];
    r.n = layout.n;
    levels.push_back(r);
  }
  std::vector<PlanRecord> plan;
  for (size_t j = 0; j < path.size(); ++j) {
    auto plans = planMove(layout, j == 0 ? std::vector<Cell>{} : path[j - 1].origins, path[j].origins);
    for (int k = 0; k < layout.levels; ++k) plan.push_back(planRecord(uint32_t(j), k, plans[size_t(k)]));
  }
  // The slabs of the last move (the full build's: each level's region outside its covered block).
  const std::vector<Cell> previous = path.size() > 1 ? path[path.size() - 2].origins : std::vector<Cell>{};
  const std::vector<SlabRecord> slabs = slabRecords(layout, previous, planMove(layout, previous, last.origins));
  const uint32_t slabCount = uint32_t(std::min(slabs.size(), kMaxSlabsPerLevel * size_t(layout.levels)));
  Buffer& slabBuffer = ctx.board.ensureBuffer("clip-slabs", slabBytes(layout.levels));
  if (slabCount > 0) slabBuffer.upload(slabs.data(), sizeof(SlabRecord) * slabCount);
  ctx.board.ensureBuffer("clip-slabs.count", 4).upload(&slabCount, 4);
  ctx.stats["slabs_last_move"] = slabCount;
  ctx.board.ensureBuffer("clip-levels", sizeof(LevelRecord) * levels.size()).upload(levels.data(), sizeof(LevelRecord) * levels.size());
  ctx.board.ensureBuffer("clip-plan", sizeof(PlanRecord) * plan.size()).upload(plan.data(), sizeof(PlanRecord) * plan.size());
  ctx.stats["levels"] = layout.levels;
  ctx.stats["resolution"] = layout.n;
  ctx.stats["voxel_size_m"] = layout.voxelSize0;
  ctx.stats["coarsest_extent_m"] = layout.voxelSize(layout.levels - 1) * layout.n;
  ctx.stats["moves"] = double(path.size() - 1);
  for (int k = 0; k < layout.levels; ++k) ctx.stats["level" + std::to_string(k) + "_lag"] = last.lag[size_t(k)];
}

// --- Update ---------------------------------------------------------------------------------------

void UpdateStage::declare(StageBuilder& b) const {
  for (const auto& p : layoutParams()) b.param(p);
  for (const auto& p : pathParams()) b.param(p);
  for (const auto& p : injectParams()) b.param(p);
  b.param(fixedPointParam());
  b.readView();
  b.read("clip-levels");
  b.read("shadow-map");
  b.read("light");
  b.write("clip-accumulators");
  b.write("clip-triangle-visit");
  b.output("clip-atlas", OutputKind::Volume3D, kClipAtlas,
           "every level's physical texture: blocks of (N+2)^3 texels with one guard texel per side, faces along x "
           "(isotropic, then +x -x +y -y +z -z), levels along y; cell c at texel c & (N-1)");
  BufferLayout counters;
  counters.stride = 4 * kCountersPerLevel;
  counters.fields = {{"cleared", FieldType::U32, 0},
                     {"pairs", FieldType::U32, 4},
                     {"resolved", FieldType::U32, 8},
                     {"refiltered", FieldType::U32, 12},
                     {"guards", FieldType::U32, 16}};
  b.output("clip-counters", OutputKind::Buffer, kClipCounters,
           "per level, what the last move's shaders wrote, counted by atomics: accumulators cleared, triangle/cell "
           "pairs injected, texels resolved, texels refiltered, guard texels")
      .layout = counters;
  b.output("clip-move", OutputKind::Buffer, Semantic::Scalar,
           "per level, the plan of the move this run made (from the origins held before: after a viewer camera "
           "move too): exposed, voxelized directly, changed coverage, refiltered cells and the move d; d = 0 and "
           "all cells exposed for a full build")
      .layout = planLayout();
  b.output("clip-move-boxes", OutputKind::Buffer, Semantic::Points,
           "the boxes of cells this run's move voxelized directly, as clip-slabs (the viewer's clip-counters view "
           "draws them)")
      .layout = slabLayout("clip-move-boxes.count");
  b.write("clip-move-boxes.count");
  b.buffer("clip-move", [](const ParamSet& p, const ViewState&) { return sizeof(PlanRecord) * size_t(p.getInt("clipmap.levels")); });
  b.buffer("clip-move-boxes", [](const ParamSet& p, const ViewState&) { return slabBytes(p.getInt("clipmap.levels")); });
  b.texture("clip-atlas", [](const ParamSet& p, const ViewState&) { return atlasDesc(p); });
  b.buffer("clip-accumulators", [](const ParamSet& p, const ViewState&) { return accumulatorBytes(p); });
  b.buffer("clip-counters", [](const ParamSet& p, const ViewState&) { return countersBytes(p.getInt("clipmap.levels")); });
  // Sized from the triangles a pass dispatches (4 B each).
  b.buffer("clip-triangle-visit", [](const ParamSet&, const ViewState&) { return size_t(4); }, /*pool=*/true);
}

int UpdateStage::iterations(const ParamSet& params) const { return params.getInt("clipmap.path-moves") + 1; }

template <typename T>
static void appendBytes(std::vector<uint8_t>& key, const T& v) {
  const auto* p = reinterpret_cast<const uint8_t*>(&v);
  key.insert(key.end(), p, p + sizeof(T));
}

void UpdateStage::execute(StageContext& ctx) {
  glFinish();  // time this move alone (bench and the manifest: full build vs one move)
  const auto start = std::chrono::steady_clock::now();
  const Layout layout = layoutOf(ctx.params, ctx.scene);
  const int n = layout.n, faces = facesOf(ctx.params);
  const auto path = cameraPath(ctx.params, ctx.scene, ctx.view.position);
  Texture& atlas = ctx.board.ensureTexture("clip-atlas", atlasDesc(ctx.params));
  Buffer& accum = ctx.board.ensureBuffer("clip-accumulators", accumulatorBytes(ctx.params));
  Buffer& counters = ctx.board.ensureBuffer("clip-counters", countersBytes(layout.levels));
  ctx.board.ensureBuffer("clip-triangle-visit", 4);  // grown by voxelizeEntries

  // What the held texels were built from: the same atlas, layout, scene, injection and light.
  std::vector<uint8_t> key;
  appendBytes(key, layout.n);
  appendBytes(key, layout.levels);
  appendBytes(key, layout.voxelSize0);
  appendBytes(key, faces);
  appendBytes(key, atlas.id());
  appendBytes(key, accum.id());
  appendBytes(key, &ctx.scene);
  appendBytes(key, ctx.scene.triangleCount());
  appendBytes(key, ctx.params.getInt("inject.mode"));
  appendBytes(key, ctx.params.getFloat("inject.uniform-radiance"));
  appendBytes(key, ctx.params.getInt("clipmap.fixed-point-bits"));
  auto light = ctx.board.buffer("light").download();
  key.insert(key.end(), light.begin(), light.end());

  std::vector<Cell> before;
  if (ctx.iteration > 0)
    before = path[size_t(ctx.iteration - 1)].origins;
  else if (held_ && held_->key == key)
    before = held_->origins;
  held_.reset();
  const std::vector<Cell>& after = path[size_t(ctx.iteration)].origins;
  const auto plans = planMove(layout, before, after);
  // What each level's shaders visit: the planner's direct boxes, or for a full build the whole
  // region in one box with the covered block skipped (one pass over the triangles per level, not
  // six).
  std::vector<std::vector<Box>> boxes(size_t(layout.levels));
  std::vector<Box> skips(size_t(layout.levels));
  for (int k = 0; k < layout.levels; ++k) {
    const LevelPlan& p = plans[size_t(k)];
    boxes[size_t(k)] = p.full ? std::vector<Box>{region(p.origin, n)} : p.direct;
    if (p.full) skips[size_t(k)] = p.covered;
  }
  auto setSkip = [&](GLuint program, int k) {
    setUniform(program, "u_skipLo", glm::ivec3(skips[size_t(k)].lo));
    setUniform(program, "u_skipHi", glm::ivec3(skips[size_t(k)].hi));
  };

  std::vector<uint32_t> zero(size_t(kCountersPerLevel * layout.levels + 1), 0);
  counters.upload(zero.data(), zero.size() * 4);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 12, accum.id());     // CLIPMAP_BINDING_ACCUM
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 13, counters.id());  // CLIPMAP_BINDING_COUNTERS

  const TriangleOrder& order = order_.get(ctx.scene);
  GLuint clear = ctx.shaders.program({"clipmap/clear.comp.glsl"});
  setClipUniforms(clear, layout, after);
  GLuint resolve = ctx.shaders.program({"clipmap/resolve.comp.glsl"});
  setClipUniforms(resolve, layout, after);
  setUniform(resolve, "u_faces", faces);
  setFixedPointUniforms(resolve, ctx.params);
  GLuint filter = ctx.shaders.program({"clipmap/filter.comp.glsl"});
  setClipUniforms(filter, layout, after);
  setUniform(filter, "u_faces", faces);

  // Level by level, fine to coarse, each level's work timed on its own (glFinish between the
  // phases; the statistics level<k>_ms and <phase>_ms, which bench reports as medians). Level k's
  // covered block is filtered from level k-1, which is complete by then; a level's direct cells
  // and its covered block are disjoint, so the order of the levels changes no texel.
  int passes = 0, runsReached = 0, trianglesDispatched = 0;
  double phaseMs[4] = {0.0, 0.0, 0.0, 0.0};  // clear, voxelize, resolve, filter
  auto lap = [](std::chrono::steady_clock::time_point& t) {
    glFinish();
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - t).count();
    t = now;
    return ms;
  };
  for (int k = 0; k < layout.levels; ++k) {
    auto t = std::chrono::steady_clock::now();
    double levelMs = 0.0;
    auto phase = [&](int i) {
      const double ms = lap(t);
      phaseMs[i] += ms;
      levelMs += ms;
    };
    // 1. Clear the accumulators of the level's cells to voxelize.
    glUseProgram(clear);
    setUniform(clear, "u_level", k);
    setSkip(clear, k);
    for (const Box& box : boxes[size_t(k)]) dispatchBox(clear, box);
    glMemoryBarrier(kAllShaderWrites);
    phase(0);
    // 2. Voxelize and inject them.
    std::vector<Entry> entries;
    for (const Box& box : boxes[size_t(k)]) entries.push_back({k, box, skips[size_t(k)]});
    if (!entries.empty()) {
      int reached = 0, triangles = 0;
      passes += voxelizeEntries(ctx, layout, after, entries, order, "clip-triangle-visit", reached, triangles);
      runsReached += reached;
      trianglesDispatched += triangles;
    }
    phase(1);
    // 3. Resolve the sums into the atlas.
    glUseProgram(resolve);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 12, accum.id());     // CLIPMAP_BINDING_ACCUM
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 13, counters.id());  // CLIPMAP_BINDING_COUNTERS
    glBindImageTexture(0, atlas.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA8);
    setUniform(resolve, "u_level", k);
    setSkip(resolve, k);
    for (const Box& box : boxes[size_t(k)]) dispatchBox(resolve, box);
    glMemoryBarrier(kAllShaderWrites);
    phase(2);
    // 4. Refilter the level's covered block from the finer level.
    if (k > 0 && !plans[size_t(k)].covered.empty()) {
      glUseProgram(filter);
      glBindImageTexture(0, atlas.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA8);
      setUniform(filter, "u_level", k);
      dispatchBox(filter, plans[size_t(k)].covered);
      glMemoryBarrier(kAllShaderWrites);
    }
    phase(3);
    ctx.stats["level" + std::to_string(k) + "_ms"] = levelMs;
  }

  // 5. Guard texels of every block.
  auto t = std::chrono::steady_clock::now();
  GLuint guards = ctx.shaders.program({"clipmap/guards.comp.glsl"});
  setClipUniforms(guards, layout, after);
  glUseProgram(guards);
  glBindImageTexture(0, atlas.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA8);
  dispatchCompute(atlas.desc().size, {4, 4, 4});
  glMemoryBarrier(kAllShaderWrites);
  glBindImageTexture(0, 0, 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA8);
  const double guardsMs = lap(t);
  const char* phaseNames[4] = {"clear_ms", "voxelize_ms", "resolve_ms", "filter_ms"};
  for (int i = 0; i < 4; ++i) ctx.stats[phaseNames[i]] = phaseMs[i];
  ctx.stats["guards_ms"] = guardsMs;

  held_ = Held{after, key};
  {
    std::vector<PlanRecord> move;
    for (int k = 0; k < layout.levels; ++k) move.push_back(planRecord(uint32_t(ctx.iteration), k, plans[size_t(k)]));
    ctx.board.ensureBuffer("clip-move", sizeof(PlanRecord) * move.size()).upload(move.data(), sizeof(PlanRecord) * move.size());
    const std::vector<SlabRecord> slabs = slabRecords(layout, before, plans);
    const uint32_t count = uint32_t(std::min(slabs.size(), kMaxSlabsPerLevel * size_t(layout.levels)));
    Buffer& boxes = ctx.board.ensureBuffer("clip-move-boxes", slabBytes(layout.levels));
    if (count > 0) boxes.upload(slabs.data(), sizeof(SlabRecord) * count);
    ctx.board.ensureBuffer("clip-move-boxes.count", 4).upload(&count, 4);
  }

  std::vector<uint32_t> counted(zero.size());
  auto bytes = counters.download(counted.size() * 4);
  std::memcpy(counted.data(), bytes.data(), counted.size() * 4);
  double written = 0.0, exposed = 0.0;
  for (int k = 0; k < layout.levels; ++k) {
    const LevelPlan& p = plans[size_t(k)];
    const std::string l = "level" + std::to_string(k) + "_";
    const uint32_t* c = &counted[size_t(kCountersPerLevel * k)];
    ctx.stats[l + "exposed"] = double(p.exposedCells);
    ctx.stats[l + "planned_direct"] = double(p.directCells);
    ctx.stats[l + "coverage_changed"] = double(p.coverageChanged);
    ctx.stats[l + "cleared"] = c[0];
    ctx.stats[l + "pairs"] = c[1];
    ctx.stats[l + "resolved"] = c[2];
    ctx.stats[l + "refiltered"] = c[3];
    written += double(c[2]) + double(c[3]);
    exposed += double(p.exposedCells);
  }
  glFinish();
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (ctx.iteration < 8) ctx.stats["move" + std::to_string(ctx.iteration) + "_ms"] = ms;
  ctx.stats["last_move_ms"] = ms;
  ctx.stats["triangle_passes"] = passes;
  ctx.stats["triangle_runs_reached"] = runsReached;
  ctx.stats["triangles_dispatched"] = trianglesDispatched;
  ctx.stats["triangle_runs"] = double(order.runs.size());
  reportOverflow(ctx, "update", counted.back());
  ctx.stats["move"] = ctx.iteration;
  ctx.stats["full_build"] = before.empty() ? 1 : 0;
  ctx.stats["cells_exposed"] = exposed;
  ctx.stats["texels_written"] = written;
  ctx.stats["cells_total"] = double(layout.levels) * n * n * n;
  ctx.stats["bytes"] = double(atlas.byteSize()) + double(accum.size());
}

// --- Mips -----------------------------------------------------------------------------------------

void MipsStage::declare(StageBuilder& b) const {
  for (const auto& p : layoutParams()) b.param(p);
  for (const auto& p : pathParams()) b.param(p);
  b.readView();
  b.read("clip-atlas");
  b.output("clip-mips", OutputKind::Volume3D, Semantic::Color,
           "the coarsest level in logical order (mip 0: texel j = cell o_{L-1} + j) and its mips down to 4^3, each "
           "covering the same volume");
  b.output("clip-logical", OutputKind::Volume3D, Semantic::Color,
           "every level's isotropic values unrolled into logical order, levels along y: texel (x, k N + y, z) = cell "
           "o_k + (x, y, z) of level k (compare with clip-atlas: the same data, cut at the physical seam)");
  b.texture("clip-mips", [](const ParamSet& p, const ViewState&) { return mipsDesc(p); });
  b.texture("clip-logical", [](const ParamSet& p, const ViewState&) { return logicalDesc(p); });
}

void MipsStage::execute(StageContext& ctx) {
  const Layout layout = layoutOf(ctx.params, ctx.scene);
  const auto path = cameraPath(ctx.params, ctx.scene, ctx.view.position);
  const auto& origins = path.back().origins;
  Texture& atlas = ctx.board.texture("clip-atlas");
  Texture& mips = ctx.board.ensureTexture("clip-mips", mipsDesc(ctx.params));
  const int last = layout.levels - 1;
  const double s = layout.voxelSize(last);
  const Cell& o = origins[size_t(last)];
  ctx.board.place("clip-mips", WorldBox{glm::vec3(glm::dvec3(o) * s), glm::vec3(glm::dvec3(o + Cell(layout.n)) * s)});
  GLuint program = ctx.shaders.program({"clipmap/mips.comp.glsl"});
  setClipUniforms(program, layout, origins);
  glUseProgram(program);
  glBindImageTexture(0, atlas.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA8);
  for (int m = 0; m < mips.levels(); ++m) {
    setUniform(program, "u_mode", m == 0 ? 0 : 1);
    glBindImageTexture(1, mips.id(), std::max(m - 1, 0), GL_TRUE, 0, GL_READ_ONLY, GL_RGBA8);
    glBindImageTexture(2, mips.id(), m, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA8);
    dispatchCompute(mips.levelSize(m), {4, 4, 4});
    glMemoryBarrier(kAllShaderWrites);
  }
  Texture& logical = ctx.board.ensureTexture("clip-logical", logicalDesc(ctx.params));
  GLuint unroll = ctx.shaders.program({"clipmap/unroll.comp.glsl"});
  setClipUniforms(unroll, layout, origins);
  setUniform(unroll, "u_face", 0);
  glUseProgram(unroll);
  glBindImageTexture(0, atlas.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA8);
  glBindImageTexture(1, logical.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA8);
  dispatchCompute(logical.desc().size, {4, 4, 4});
  glMemoryBarrier(kAllShaderWrites);
  for (int unit = 0; unit < 3; ++unit) glBindImageTexture(GLuint(unit), 0, 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA8);
  ctx.stats["mips"] = mips.levels() - 1;
  ctx.stats["bytes"] = double(mips.byteSize()) + double(logical.byteSize());
}

// --- Covered cells: direct versus filtered ----------------------------------------------------------

static bool compareOn(const ParamSet& p) { return p.getChoice("clipmap.compare-covered") == "on"; }

static TextureDesc compareDesc(const ParamSet& p) {
  if (!compareOn(p)) {  // a placeholder texel
    TextureDesc d;
    d.target = GL_TEXTURE_3D;
    d.size = {1, 1, 1};
    return d;
  }
  return logicalDesc(p);
}

void CoveredCompareStage::declare(StageBuilder& b) const {
  for (const auto& p : layoutParams()) b.param(p);
  for (const auto& p : pathParams()) b.param(p);
  for (const auto& p : injectParams()) b.param(p);
  b.param(fixedPointParam());
  b.param(ParamDesc::choice("clipmap.compare-covered", {"off", "on"}, 0,
                            "on: voxelize the covered blocks directly as well, to compare with their filtered content"));
  b.readView();
  b.read("clip-atlas");
  b.read("shadow-map");
  b.read("light");
  b.write("covered-accumulators");
  b.write("covered-counters");
  b.write("covered-triangle-visit");
  b.output("covered-direct", OutputKind::Volume3D, Semantic::Color,
           "covered cells' own voxelization Direct_k in logical order (levels along y, as clip-logical); 0 elsewhere")
      .placeholderUnless = "clipmap.compare-covered=on";
  b.output("covered-difference", OutputKind::Volume3D, Semantic::Color,
           "|Direct_k - F(level k-1)| per covered cell: the change when the cell leaves the covered block (popping)")
      .placeholderUnless = "clipmap.compare-covered=on";
  b.texture("covered-direct", [](const ParamSet& p, const ViewState&) { return compareDesc(p); });
  b.texture("covered-difference", [](const ParamSet& p, const ViewState&) { return compareDesc(p); });
  b.buffer("covered-accumulators", [](const ParamSet& p, const ViewState&) {
    return compareOn(p) ? accumulatorBytes(p) : size_t(16);
  });
  b.buffer("covered-counters", [](const ParamSet& p, const ViewState&) { return countersBytes(p.getInt("clipmap.levels")); });
  b.buffer("covered-triangle-visit", [](const ParamSet&, const ViewState&) { return size_t(4); }, /*pool=*/true);
}

void CoveredCompareStage::execute(StageContext& ctx) {
  Texture& direct = ctx.board.ensureTexture("covered-direct", compareDesc(ctx.params));
  Texture& difference = ctx.board.ensureTexture("covered-difference", compareDesc(ctx.params));
  Buffer& counters = ctx.board.ensureBuffer("covered-counters", countersBytes(ctx.params.getInt("clipmap.levels")));
  const bool on = compareOn(ctx.params);
  Buffer& accum = ctx.board.ensureBuffer("covered-accumulators", on ? accumulatorBytes(ctx.params) : size_t(16));
  ctx.board.ensureBuffer("covered-triangle-visit", 4);  // grown by voxelizeEntries
  if (!on) {
    const uint8_t zero[4] = {0, 0, 0, 0};
    glClearTexImage(direct.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, zero);
    glClearTexImage(difference.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, zero);
    return;
  }
  const Layout layout = layoutOf(ctx.params, ctx.scene);
  const auto origins = cameraPath(ctx.params, ctx.scene, ctx.view.position).back().origins;
  std::vector<uint32_t> zero(countersBytes(layout.levels) / 4, 0);
  counters.upload(zero.data(), zero.size() * 4);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 12, accum.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 13, counters.id());
  std::vector<Entry> entries;
  std::vector<glm::ivec3> lo(kMaxLevels, glm::ivec3(0)), hi(kMaxLevels, glm::ivec3(0));
  GLuint clear = ctx.shaders.program({"clipmap/clear.comp.glsl"});
  setClipUniforms(clear, layout, origins);
  setUniform(clear, "u_skipLo", glm::ivec3(0));
  setUniform(clear, "u_skipHi", glm::ivec3(0));
  glUseProgram(clear);
  int64_t cells = 0;
  for (int k = 1; k < layout.levels; ++k) {
    const Box covered = coveredBlock(origins, k, layout.n);
    lo[size_t(k)] = glm::ivec3(covered.lo), hi[size_t(k)] = glm::ivec3(covered.hi);
    if (covered.empty()) continue;
    setUniform(clear, "u_level", k);
    dispatchBox(clear, covered);
    entries.push_back({k, covered, Box{}});
    cells += covered.volume();
  }
  glMemoryBarrier(kAllShaderWrites);
  int reached = 0, triangles = 0;
  voxelizeEntries(ctx, layout, origins, entries, order_.get(ctx.scene), "covered-triangle-visit", reached, triangles);
  GLuint program = ctx.shaders.program({"clipmap/covered_compare.comp.glsl"});
  setClipUniforms(program, layout, origins);
  glProgramUniform3iv(program, glGetUniformLocation(program, "u_coveredLo"), kMaxLevels, &lo[0].x);
  glProgramUniform3iv(program, glGetUniformLocation(program, "u_coveredHi"), kMaxLevels, &hi[0].x);
  setFixedPointUniforms(program, ctx.params);
  glUseProgram(program);
  glBindImageTexture(0, ctx.board.texture("clip-atlas").id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA8);
  glBindImageTexture(1, direct.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA8);
  glBindImageTexture(2, difference.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA8);
  dispatchCompute(direct.desc().size, {4, 4, 4});
  glMemoryBarrier(kAllShaderWrites);
  for (int unit = 0; unit < 3; ++unit) glBindImageTexture(GLuint(unit), 0, 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA8);
  ctx.stats["covered_cells"] = double(cells);
  std::vector<uint32_t> counted(zero.size());
  auto bytes = counters.download(counted.size() * 4);
  std::memcpy(counted.data(), bytes.data(), counted.size() * 4);
  reportOverflow(ctx, "covered-compare", counted.back());
}

// --- Cone tracing ---------------------------------------------------------------------------------

// Distances in the coarsest level's edge, the start offset in voxels of the finest level there;
// no soft-shadow cone.
static ConeDefaults coneDefaults() {
  ConeDefaults d;
  d.aperture = 60.0;
  d.apertureHelp = "full opening angle of each diffuse cone";
  d.startOffsetHelp = "cones start this far from the surface along its normal, in voxels of the finest level there";
  d.lodBiasHelp = "level = log2(diameter / s_0) + bias, at least the finest level holding the sample";
  d.maxDistance = 0.5;
  d.maxDistanceLimit = 1.0;
  d.maxDistanceHelp = "longest cone, as a fraction of the coarsest level's edge";
  d.aoRange = 0.125;
  d.aoRangeLimit = 1.0;
  d.aoRangeHelp = "ambient occlusion counts occluders up to this distance, as a fraction of the coarsest level's edge";
  d.softShadowCone = false;
  return d;
}

static TextureDesc screenDesc(const ViewState& view, GLenum format) {
  TextureDesc d;
  d.format = format;
  d.size = {view.width, view.height, 1};
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}

static ParamDesc traceResolutionParam() {
  return ParamDesc::choice("cone.resolution", {"half", "full"}, 0,
                           "trace cones for every pixel (full) or every 2x2 block (half, 4x cheaper; composite "
                           "upsamples along surfaces)");
}

static int traceScale(const ParamSet& params) { return params.getChoice("cone.resolution") == "half" ? 2 : 1; }

static TextureDesc tracedDesc(const ViewState& view, const ParamSet& params, GLenum format) {
  const int s = traceScale(params);
  TextureDesc d = screenDesc(view, format);
  d.size = {(view.width + s - 1) / s, (view.height + s - 1) / s, 1};
  return d;
}

// The transition band: within this many cells of the border of the finest level that holds a
// sample, the level read ramps up to the next level, so a sample crossing the border changes
// level continuously instead of jumping (0: off, the finest level's whole region is used).
static ParamDesc levelBandParam() {
  return ParamDesc::real("clipmap.transition-band", 0.0, 0.0, 8.0,
                         "within this many cells of the border of the finest level holding a sample, the level read "
                         "ramps linearly to the next level (0 = off)",
                         "cells");
}

void ConeTraceStage::declare(StageBuilder& b) const {
  for (const auto& p : layoutParams()) b.param(p);
  for (const auto& p : pathParams()) b.param(p);
  b.param(levelBandParam());
  b.param(traceResolutionParam());
  declareConeParams(b, coneDefaults());
  declareSky(b);
  b.readView();
  b.read("clip-atlas");
  b.read("clip-mips");
  b.read("position");
  b.read("normal");
  b.read("albedo");
  b.read("light");
  b.output("indirect-diffuse", OutputKind::Image2D, Semantic::RadianceHDR,
           "outgoing indirect diffuse radiance: albedo * weighted sum of the diffuse cones")
      .referenceMode = "indirect-1";
  b.output("indirect-specular", OutputKind::Image2D, Semantic::RadianceHDR, "radiance gathered by the specular cone");
  b.output("ambient-occlusion", OutputKind::Image2D, Semantic::Fraction,
           "cosine-weighted visible fraction within ao.range (1 = open)");
  b.output("level-used", OutputKind::Image2D, Semantic::Scalar,
           "per pixel, the finest clip level whose region holds the surface point (-1: outside every level, or sky)");
  coneSamplesOutput(b, "every sample of the probed pixel's cones: centre+diameter, accumulated radiance+opacity, "
                       "cone/distance/level read (floor: the finer level, fraction: the next level's weight)/alpha");
  const std::pair<const char*, GLenum> traced[] = {{"indirect-diffuse", GL_RGBA16F}, {"indirect-specular", GL_RGBA16F},
                                                   {"ambient-occlusion", GL_R16F}, {"level-used", GL_R16F}};
  for (const auto& [name, format] : traced)
    b.texture(name, [format = format](const ParamSet& p, const ViewState& v) { return tracedDesc(v, p, format); });
}

void ConeTraceStage::execute(StageContext& ctx) {
  const Layout layout = layoutOf(ctx.params, ctx.scene);
  const auto path = cameraPath(ctx.params, ctx.scene, ctx.view.position);
  const auto& origins = path.back().origins;
  Texture& indirect = ctx.board.ensureTexture("indirect-diffuse", tracedDesc(ctx.view, ctx.params, GL_RGBA16F));
  Texture& specular = ctx.board.ensureTexture("indirect-specular", tracedDesc(ctx.view, ctx.params, GL_RGBA16F));
  Texture& ao = ctx.board.ensureTexture("ambient-occlusion", tracedDesc(ctx.view, ctx.params, GL_R16F));
  Texture& level = ctx.board.ensureTexture("level-used", tracedDesc(ctx.view, ctx.params, GL_R16F));
  Buffer& samples = ctx.board.ensureBuffer("cone-samples", coneSamplesBytes());
  Buffer& sampleCount = ctx.board.ensureBuffer("cone-samples.count", 4);
  const uint32_t zero = 0;
  sampleCount.upload(&zero, 4);

  GLuint program = ctx.shaders.program({"clipmap/cone_trace.comp.glsl"});
  setClipUniforms(program, layout, origins);
  std::vector<glm::vec3> mins(kMaxLevels, glm::vec3(0.0f)), offsets(kMaxLevels, glm::vec3(0.0f));
  for (int k = 0; k < layout.levels; ++k) {
    mins[size_t(k)] = glm::vec3(glm::dvec3(origins[size_t(k)]) * layout.voxelSize(k));
    offsets[size_t(k)] = glm::vec3(toroidal(origins[size_t(k)], layout.n));
  }
  glProgramUniform3fv(program, glGetUniformLocation(program, "u_levelMin"), kMaxLevels, &mins[0].x);
  glProgramUniform3fv(program, glGetUniformLocation(program, "u_levelToroidal"), kMaxLevels, &offsets[0].x);
  const float coarsestEdge = float(layout.voxelSize(layout.levels - 1) * layout.n);
  setUniform(program, "u_voxelSize0", float(layout.voxelSize0));
  setUniform(program, "u_faces", facesOf(ctx.params));
  setUniform(program, "u_levelBand", ctx.params.getFloat("clipmap.transition-band"));
  setUniform(program, "u_mipLevels", mipCount(layout.n));
  const glm::ivec3 traced = indirect.desc().size;
  // The start offset is in voxels of the finest level holding the surface (the shader scales it).
  // The camera at the end of the path (the G-buffer's), for the specular cone's view direction.
  const glm::ivec2 probe = setConeUniforms(program, ctx.params, pathEndView(ctx.params, ctx.view), 1.0f, coarsestEdge,
                                           glm::ivec2(traced), traceScale(ctx.params));
  setSkyUniforms(program, ctx.params, ctx.scene);
  glUseProgram(program);
  glBindTextureUnit(0, ctx.board.texture("clip-atlas").id());
  glBindTextureUnit(4, ctx.board.texture("clip-mips").id());
  glBindTextureUnit(1, ctx.board.texture("position").id());
  glBindTextureUnit(2, ctx.board.texture("normal").id());
  glBindTextureUnit(3, ctx.board.texture("albedo").id());
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_CONE_SAMPLES, samples.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_CONE_SAMPLE_COUNT, sampleCount.id());
  glBindImageTexture(0, indirect.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(1, specular.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(2, ao.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R16F);
  glBindImageTexture(3, level.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R16F);
  dispatchCompute({traced.x, traced.y, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  ctx.stats["diffuse_cones"] = double(ctx.params.getInt("cone.count"));
  ctx.stats["traced_pixels"] = double(traced.x) * traced.y;
  ctx.stats["probe_x"] = probe.x;
  ctx.stats["probe_y_from_top"] = traced.y - 1 - probe.y;
}

// --- Composite ------------------------------------------------------------------------------------

void CompositeStage::declare(StageBuilder& b) const {
  for (const auto& p : layoutParams()) b.param(p);
  b.param(traceResolutionParam());
  b.param(ParamDesc::real("composite.exposure", 1.0, 0.01, 64.0, "scale applied before tonemapping"));
  b.param(ParamDesc::real("composite.indirect", 1.0, 0.0, 4.0, "weight of the indirect diffuse term (1 = physical)"));
  b.param(ParamDesc::real("composite.specular", 0.04, 0.0, 1.0,
                          "weight of the indirect specular term (0.04 = a dielectric's reflectance at normal incidence)"));
  declareSky(b);  // the background
  for (const char* r : {"position", "normal", "albedo", "emission", "indirect-diffuse", "indirect-specular",
                        "ambient-occlusion", "shadow-map", "light"})
    b.read(r);
  b.output("direct", OutputKind::Image2D, Semantic::RadianceHDR, "direct light plus emission").referenceMode = "direct";
  b.output("combined", OutputKind::Image2D, Semantic::RadianceHDR, "direct + indirect diffuse + specular, linear radiance")
      .referenceMode = "full";
  b.output("final", OutputKind::Image2D, Semantic::Color, "the tonemapped image: x / (1 + x) of exposure * combined");
  const std::pair<const char*, GLenum> images[] = {{"direct", GL_RGBA16F}, {"combined", GL_RGBA16F}, {"final", GL_RGBA8}};
  for (const auto& [name, format] : images)
    b.texture(name, [format = format](const ParamSet&, const ViewState& v) { return screenDesc(v, format); });
}

void CompositeStage::execute(StageContext& ctx) {
  Texture& direct = ctx.board.ensureTexture("direct", screenDesc(ctx.view, GL_RGBA16F));
  Texture& combined = ctx.board.ensureTexture("combined", screenDesc(ctx.view, GL_RGBA16F));
  Texture& final = ctx.board.ensureTexture("final", screenDesc(ctx.view, GL_RGBA8));
  // vct-grid's composite shader: the same terms, and its edge-aware upsampling of half-resolution
  // cone results (samples more than two level-0 voxels off the pixel's plane get no weight).
  GLuint program = ctx.shaders.program({"vct_grid/composite.comp.glsl"});
  setUniform(program, "u_shadowSource", 0);
  setUniform(program, "u_traceScale", traceScale(ctx.params));
  setUniform(program, "u_edgeDistance", float(2.0 * layoutOf(ctx.params, ctx.scene).voxelSize0));
  setUniform(program, "u_specularWeight", ctx.params.getFloat("composite.specular"));
  setUniform(program, "u_indirectWeight", ctx.params.getFloat("composite.indirect"));
  setUniform(program, "u_exposure", ctx.params.getFloat("composite.exposure"));
  setSkyUniforms(program, ctx.params, ctx.scene);
  glUseProgram(program);
  const std::pair<int, const char*> inputs[] = {{1, "position"}, {2, "normal"}, {3, "albedo"}, {4, "emission"},
                                                {5, "indirect-diffuse"}, {6, "indirect-specular"},
                                                {7, "ambient-occlusion"},  // the soft-shadow slot: unused (u_shadowSource 0)
                                                {8, "shadow-map"}};
  for (const auto& [unit, name] : inputs) glBindTextureUnit(GLuint(unit), ctx.board.texture(name).id());
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  glBindImageTexture(0, direct.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(1, combined.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(2, final.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA8);
  dispatchCompute({ctx.view.width, ctx.view.height, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
}

}  // namespace voxlab::clipmap
