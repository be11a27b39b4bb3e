// The scene's triangles in Morton order and the voxelizer that injects boxes of cells from them,
// shared by the update and covered-compare stages (see clipmap.cpp for the overview).
#include "techniques/clipmap/stages.h"
#include "techniques/clipmap/stage_helpers.h"

#include <algorithm>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "scene/gpu_scene.h"
#include "scene/scene.h"
#include "techniques/common/light_stage.h"

namespace voxlab::clipmap {

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
                    const std::vector<Entry>& entries, int accumulatorLevels, const TriangleOrder& order,
                    const std::string& visitList, int& runs, int& triangles) {
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

  GLuint vox = ctx.shaders.program({"clipmap/voxelize.comp.glsl"}, lightKindDefines(ctx.scene));
  setClipUniforms(vox, layout, origins);
  setUniform(vox, "u_mode", ctx.params.getChoice("inject.mode") == "uniform" ? 1 : 0);
  setUniform(vox, "u_uniformRadiance", glm::vec3(ctx.params.getFloat("inject.uniform-radiance")));
  setAccumulatorUniforms(vox, ctx.params, accumulatorLevels);
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

}  // namespace voxlab::clipmap
