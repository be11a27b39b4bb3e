// The stages that place and update the clip levels: anchor and update (see clipmap.cpp for the
// overview).
#include "techniques/clipmap/stages.h"
#include "techniques/clipmap/stage_helpers.h"
#include "techniques/clipmap/unreached_cells.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstring>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "graph/scene_inputs.h"
#include "scene/gpu_scene.h"
#include "scene/scene.h"

namespace voxlab::clipmap {

// --- Anchor ---------------------------------------------------------------------------------------

// At most 3 exposed slabs per level, each cut into at most 6 boxes by the covered block, plus at
// most 6 boxes of cells that left the covered block.
static constexpr size_t kMaxSlabsPerLevel = 24;
static size_t slabBytes(int levels) { return sizeof(SlabRecord) * kMaxSlabsPerLevel * size_t(levels); }

// The physical texels of 'box' along each axis: one run from its toroidal start, or two where it
// wraps past texel N - 1 (the second from texel 0).
struct AxisRuns {
  int start[2], size[2], count;
};
static std::array<AxisRuns, 3> toroidalRuns(const Box& box, int n) {
  const glm::ivec3 t = toroidal(box.lo, n);
  std::array<AxisRuns, 3> runs;
  for (int i = 0; i < 3; ++i) {
    const int length = int(box.hi[i] - box.lo[i]);
    const int first = std::min(length, n - t[i]);
    runs[size_t(i)] = {{t[i], 0}, {first, length - first}, length > first ? 2 : 1};
  }
  return runs;
}

// Zeroes every face's texels of the cells of 'box' (level k) in the atlas: the resolve pass then
// writes only the cells that hold fragments (an image store costs about as much as a filtered read
// on llvmpipe, and most cells are empty).
static void clearAtlasCells(const Texture& atlas, int n, int faces, int k, const Box& box) {
  const std::array<AxisRuns, 3> r = toroidalRuns(box, n);
  const int b = n + 2;
  for (int face = 0; face < faces; ++face)
    for (int x = 0; x < r[0].count; ++x)
      for (int y = 0; y < r[1].count; ++y)
        for (int z = 0; z < r[2].count; ++z)
          glClearTexSubImage(atlas.id(), 0, face * b + 1 + r[0].start[x], k * b + 1 + r[1].start[y], 1 + r[2].start[z],
                             r[0].size[x], r[1].size[y], r[2].size[z], GL_RGBA, GL_FLOAT, nullptr);
}

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
      const std::array<AxisRuns, 3> runs = toroidalRuns(box, layout.n);
      int pieces = 1;
      for (int i = 0; i < 3; ++i) {
        r.cellLo[i] = int32_t(box.lo[i]);
        r.cellHi[i] = int32_t(box.hi[i]);
        r.physLo[i] = runs[size_t(i)].start[0];
        pieces *= runs[size_t(i)].count;  // two where it wraps past texel N-1
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
  b.alongside({"clip-plan"});
  b.output("clip-slabs", OutputKind::Buffer, Semantic::Points,
           "the boxes of cells the last move voxelizes directly (disjoint exposed slabs; cells that left the covered "
           "block): world box (min, level; max, cells), cell range, the physical texel of its min corner and how "
           "many physical boxes it splits into where it wraps")
      .layout = slabLayout("clip-slabs.count");
  b.alongside({"clip-slabs"});
  b.write("clip-slabs.count");
  b.buffer("clip-slabs", [](const ParamSet& p, const ViewState&) { return slabBytes(p.getInt("clipmap.levels")); });
  b.buffer("clip-levels", [](const ParamSet& p, const ViewState&) { return sizeof(LevelRecord) * size_t(p.getInt("clipmap.levels")); });
  b.buffer("clip-plan", [](const ParamSet& p, const ViewState&) {
    return sizeof(PlanRecord) * size_t(p.getInt("clipmap.levels")) * size_t(p.getInt("clipmap.path-moves") + 1);
  });
}

void AnchorStage::execute(StageContext& ctx) {
  const Layout layout = layoutOf(ctx.params, ctx.scene);
  const auto path = cameraPath(ctx.params, ctx.scene, ctx.view);
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

static bool fillUnreachedOn(const ParamSet& p) { return p.getChoice("clipmap.fill-unreached") == "on"; }

// A word per cell of one level while the fill is on; one word (unused) while it is off.
static size_t fillBytes(const ParamSet& p) {
  const size_t n = size_t(p.getInt("clipmap.resolution"));
  return fillUnreachedOn(p) ? n * n * n * sizeof(uint32_t) : sizeof(uint32_t);
}

// Level k's part of the fill of unreached cells (unreached_cells.h, fill.comp.glsl): reads the
// level's isotropic face back, finds the cells no path of empty cells from the camera reaches
// (level 0 from the camera's cell, coarser levels from what their finer level reached) and has
// the fill shader write them. 'filled' holds the level's filled cells by physical texel across
// moves (a held cell the fill wrote is empty to the search, and emptied where the camera's space
// now reaches it); 'open' takes the finer level's open faces per cell and receives this level's.
// Returns the number of cells filled.
static int64_t fillUnreachedCells(StageContext& ctx, Texture& atlas, const Layout& layout,
                                  const std::vector<Cell>& origins, int k, const LevelPlan& plan,
                                  const std::vector<Box>& direct, const glm::dvec3& camera, int faces,
                                  std::vector<uint8_t>& filled, std::vector<uint8_t>& open) {
  const int n = layout.n, b = n + 2;
  std::vector<float> isotropic(size_t(b) * size_t(b) * size_t(b) * 4);
  glGetTextureSubImage(atlas.id(), 0, 0, k * b, 0, b, b, b, GL_RGBA, GL_FLOAT,
                       GLsizei(isotropic.size() * sizeof(float)), isotropic.data());
  const Cell origin = origins[size_t(k)];
  const size_t count = size_t(n) * size_t(n) * size_t(n);
  auto logicalIndex = [n](glm::ivec3 i) { return logicalCellIndex(i, n); };
  auto cellOf = [n](size_t i) { return logicalCell(i, n); };
  auto physIndex = [&](glm::ivec3 i) { return logicalIndex(toroidal(origin + Cell(i), n)); };
  auto alphaAt = [&](glm::ivec3 i) {
    const glm::ivec3 p = toroidal(origin + Cell(i), n) + glm::ivec3(1);
    return isotropic[((size_t(p.z) * size_t(b) + size_t(p.y)) * size_t(b) + size_t(p.x)) * 4 + 3];
  };
  if (filled.size() != count || plan.full) filled.assign(count, 0);

  UnreachedInput input;
  input.n = n;
  input.occupied.assign(count, 0);
  std::vector<uint8_t> rewritten(count, 0);
  for (size_t i = 0; i < count; ++i) {
    const glm::ivec3 c = cellOf(i);
    const Cell world = origin + Cell(c);
    bool fresh = plan.full || plan.covered.contains(world);
    for (const Box& box : direct) fresh = fresh || box.contains(world);
    rewritten[i] = fresh;
    if (fresh) filled[physIndex(c)] = 0;  // the voxelizer or the filter wrote it this move
    input.occupied[i] = alphaAt(c) > 0.0f && !filled[physIndex(c)];
  }
  if (k == 0) {
    input.seed = glm::ivec3(glm::floor(camera / layout.voxelSize(0)) - glm::dvec3(origin));
  } else if (open.size() == count) {
    input.inherited.assign(count, 0);
    input.openFaces.assign(count, 0);
    const Cell finer = origins[size_t(k - 1)];
    for (size_t i = 0; i < count; ++i) {
      const Cell world = origin + Cell(cellOf(i));
      if (!plan.covered.contains(world)) continue;
      for (int child = 0; child < 8; ++child) {
        const glm::ivec3 offset(child & 1, (child >> 1) & 1, child >> 2);
        const glm::ivec3 f = glm::ivec3(Cell(2) * world + Cell(offset) - finer);
        if (glm::any(glm::lessThan(f, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(f, glm::ivec3(n)))) continue;
        const uint8_t childOpen = open[logicalIndex(f)];
        if (!childOpen) continue;
        input.inherited[i] = 1;
        // The child touches its parent's faces on the sides of its offset: the camera's space
        // leaves the parent through such a face where it leaves the child through it.
        for (int axis = 0; axis < 3; ++axis)
          input.openFaces[i] |= uint8_t(childOpen & (1u << (2 * axis + (offset[axis] == 1 ? 0 : 1))));
      }
    }
  }
  const UnreachedCells found = findUnreachedCells(input);

  std::vector<uint32_t> words(count, 0);
  bool any = false;
  for (size_t i = 0; i < count; ++i) {
    const size_t p = physIndex(cellOf(i));
    if (found.source[i] >= 0) {
      const uint32_t out = found.sourceStep[i] >= 0 ? uint32_t(found.sourceStep[i]) : 7u;
      words[i] = 2u + 8u * uint32_t(found.source[i]) + out;
      filled[p] = 1;
      any = true;
    } else if (filled[p] && !rewritten[i]) {
      words[i] = 1u;  // filled by an earlier move, reached (or next to a wall) now
      filled[p] = 0;
      any = true;
    }
  }
  if (any) {
    Buffer& fill = ctx.board.ensureBuffer("clip-fill", fillBytes(ctx.params));
    fill.upload(words.data(), count * sizeof(uint32_t));
    GLuint program = ctx.shaders.program({"clipmap/fill.comp.glsl"}, atlasFormatDefines(ctx.params));
    setClipUniforms(program, layout, origins);
    setUniform(program, "u_level", k);
    setUniform(program, "u_faces", faces);
    glUseProgram(program);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 14, fill.id());  // CLIPMAP_BINDING_FILL
    glBindImageTexture(0, atlas.id(), 0, GL_TRUE, 0, GL_READ_WRITE, atlasFormat(ctx.params));
    dispatchCompute(glm::ivec3(n), {4, 4, 4});
    glMemoryBarrier(kAllShaderWrites);
  }
  open = found.open;
  return found.filled;
}

void UpdateStage::declare(StageBuilder& b) const {
  b.read(kSceneGeometryInput);  // voxelizes the scene's triangles into the moved slabs
  for (const auto& p : layoutParams()) b.param(p);
  for (const auto& p : pathParams()) b.param(p);
  for (const auto& p : injectParams()) b.param(p);
  b.param(fixedPointParam());
  b.param(atlasFormatParam());
  b.param(ParamDesc::choice("clipmap.fill-unreached", {"on", "off"}, 0,
                            "on: cells no path of empty cells from the camera reaches (behind the walls of a closed room, "
                            "inside closed objects) are filled, opaque, with the light of the nearest wall as the camera's "
                            "side sees it, so a cone running along a wall stops as the wall would stop its rays"));
  b.readView();
  b.read("clip-levels");
  b.read("shadow-map");
  b.read("light");
  b.read(kSceneLightsInput);  // the light's type: the voxelizer is built for it (lightKindDefines)
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
  b.alongside({"clip-counters"});
  b.output("clip-move", OutputKind::Buffer, Semantic::Scalar,
           "per level, the plan of the move this run made (from the origins held before: after a viewer camera "
           "move too): exposed, voxelized directly, changed coverage, refiltered cells and the move d; d = 0 and "
           "all cells exposed for a full build")
      .layout = planLayout();
  b.alongside({"clip-move"});
  b.output("clip-move-boxes", OutputKind::Buffer, Semantic::Points,
           "the boxes of cells this run's move voxelized directly, as clip-slabs (the viewer's clip-counters view "
           "draws them)")
      .layout = slabLayout("clip-move-boxes.count");
  b.alongside({"clip-move-boxes"});
  b.write("clip-move-boxes.count");
  b.buffer("clip-move", [](const ParamSet& p, const ViewState&) { return sizeof(PlanRecord) * size_t(p.getInt("clipmap.levels")); });
  b.buffer("clip-move-boxes", [](const ParamSet& p, const ViewState&) { return slabBytes(p.getInt("clipmap.levels")); });
  b.texture("clip-atlas", [](const ParamSet& p, const ViewState&) { return atlasDesc(p); });
  // One level's accumulators: the levels take turns (each is cleared, voxelized and resolved
  // before the next).
  b.buffer("clip-accumulators", [](const ParamSet& p, const ViewState&) { return accumulatorBytes(p, 1); });
  // What the fill writes into one level: a word per cell (fill.comp.glsl).
  b.write("clip-fill");
  b.buffer("clip-fill", [](const ParamSet& p, const ViewState&) { return fillBytes(p); });
  // The finer level's filled cells for the filter: a word per physical texel.
  b.write("clip-filled");
  b.buffer("clip-filled", [](const ParamSet& p, const ViewState&) { return fillBytes(p); });
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
  const auto path = cameraPath(ctx.params, ctx.scene, ctx.view);
  Texture& atlas = ctx.board.ensureTexture("clip-atlas", atlasDesc(ctx.params));
  Buffer& accum = ctx.board.ensureBuffer("clip-accumulators", accumulatorBytes(ctx.params, 1));
  Buffer& counters = ctx.board.ensureBuffer("clip-counters", countersBytes(layout.levels));
  ctx.board.ensureBuffer("clip-triangle-visit", 4);  // grown by voxelizeEntries
  ctx.board.ensureBuffer("clip-fill", fillBytes(ctx.params));
  ctx.board.ensureBuffer("clip-filled", fillBytes(ctx.params));

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
  const bool fill = fillUnreachedOn(ctx.params);
  appendBytes(key, fill);
  auto light = ctx.board.buffer("light").download();
  key.insert(key.end(), light.begin(), light.end());

  std::vector<Cell> before;
  std::vector<std::vector<uint8_t>> filled(size_t(layout.levels));
  if (ctx.iteration > 0 || (held_ && held_->key == key)) {
    before = ctx.iteration > 0 ? path[size_t(ctx.iteration - 1)].origins : held_->origins;
    if (held_) filled = held_->filled;
  }
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
  GLuint clear = ctx.shaders.program({"clipmap/clear.comp.glsl"}, atlasFormatDefines(ctx.params));
  setClipUniforms(clear, layout, after);
  setAccumulatorUniforms(clear, ctx.params, 1);
  GLuint resolve = ctx.shaders.program({"clipmap/resolve.comp.glsl"}, atlasFormatDefines(ctx.params));
  setClipUniforms(resolve, layout, after);
  setUniform(resolve, "u_faces", faces);
  setAccumulatorUniforms(resolve, ctx.params, 1);
  GLuint filter = ctx.shaders.program({"clipmap/filter.comp.glsl"}, atlasFormatDefines(ctx.params));
  setClipUniforms(filter, layout, after);
  setUniform(filter, "u_faces", faces);

  // Level by level, fine to coarse, each level's work timed on its own (glFinish between the
  // phases; the statistics level<k>_ms and <phase>_ms, which bench reports as medians). Level k's
  // covered block is filtered from level k-1, which is complete by then; a level's direct cells
  // and its covered block are disjoint, so the order of the levels changes no texel.
  int passes = 0, runsReached = 0, trianglesDispatched = 0;
  double phaseMs[5] = {0.0, 0.0, 0.0, 0.0, 0.0};  // clear, voxelize, resolve, filter, fill
  std::vector<uint8_t> open;  // the finer level's open faces per cell (logical), for the fill
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
      passes += voxelizeEntries(ctx, layout, after, entries, 1, order, "clip-triangle-visit", reached, triangles);
      runsReached += reached;
      trianglesDispatched += triangles;
    }
    phase(1);
    // 3. Resolve the sums into the atlas: the cells cleared (a full build's covered block too,
    // which the filter below rewrites), then the occupied ones written.
    for (const Box& box : boxes[size_t(k)]) clearAtlasCells(atlas, n, faces, k, box);
    glUseProgram(resolve);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 12, accum.id());     // CLIPMAP_BINDING_ACCUM
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 13, counters.id());  // CLIPMAP_BINDING_COUNTERS
    glBindImageTexture(0, atlas.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, atlasFormat(ctx.params));
    setUniform(resolve, "u_level", k);
    setSkip(resolve, k);
    for (const Box& box : boxes[size_t(k)]) dispatchBox(resolve, box);
    glMemoryBarrier(kAllShaderWrites);
    phase(2);
    // 4. Refilter the level's covered block from the finer level (its surfaces without the filled
    // space behind them where a cell holds both).
    if (k > 0 && !plans[size_t(k)].covered.empty()) {
      const bool readFilled = fill && filled[size_t(k - 1)].size() == size_t(n) * size_t(n) * size_t(n);
      Buffer& mask = ctx.board.ensureBuffer("clip-filled", fillBytes(ctx.params));
      if (readFilled) {
        const std::vector<uint32_t> words(filled[size_t(k - 1)].begin(), filled[size_t(k - 1)].end());
        mask.upload(words.data(), words.size() * sizeof(uint32_t));
      }
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 15, mask.id());  // CLIPMAP_BINDING_FILLED
      setUniform(filter, "u_readFilled", readFilled ? 1 : 0);
      glUseProgram(filter);
      glBindImageTexture(0, atlas.id(), 0, GL_TRUE, 0, GL_READ_WRITE, atlasFormat(ctx.params));
      setUniform(filter, "u_level", k);
      dispatchBox(filter, plans[size_t(k)].covered);
      glMemoryBarrier(kAllShaderWrites);
    }
    phase(3);
    // 5. Fill the level's unreached cells (after the filter, which takes the finer level's
    // filled cells only into covered cells that hold no surface).
    if (fill) {
      const int64_t count = fillUnreachedCells(ctx, atlas, layout, after, k, plans[size_t(k)], boxes[size_t(k)],
                                               path[size_t(ctx.iteration)].camera, faces, filled[size_t(k)], open);
      ctx.stats["level" + std::to_string(k) + "_filled"] = double(count);
    }
    phase(4);
    ctx.stats["level" + std::to_string(k) + "_ms"] = levelMs;
  }

  // 6. Guard texels of every block.
  auto t = std::chrono::steady_clock::now();
  GLuint guards = ctx.shaders.program({"clipmap/guards.comp.glsl"}, atlasFormatDefines(ctx.params));
  setClipUniforms(guards, layout, after);
  glUseProgram(guards);
  glBindImageTexture(0, atlas.id(), 0, GL_TRUE, 0, GL_READ_WRITE, atlasFormat(ctx.params));
  {
    // One invocation per guard texel (guards.comp.glsl): B^3 - N^3 per block of B = N + 2 a side.
    const glm::ivec3 size = atlas.desc().size;
    const int64_t b = layout.n + 2, blocks = int64_t(size.x / b) * (size.y / b);
    dispatchCompute({int(blocks * (b * b * b - int64_t(layout.n) * layout.n * layout.n)), 1, 1}, {64, 1, 1});
  }
  glMemoryBarrier(kAllShaderWrites);
  glBindImageTexture(0, 0, 0, GL_TRUE, 0, GL_READ_WRITE, atlasFormat(ctx.params));
  const double guardsMs = lap(t);
  const char* phaseNames[5] = {"clear_ms", "voxelize_ms", "resolve_ms", "filter_ms", "fill_ms"};
  for (int i = 0; i < 5; ++i) ctx.stats[phaseNames[i]] = phaseMs[i];
  ctx.stats["guards_ms"] = guardsMs;

  held_ = Held{after, key, fill ? filled : std::vector<std::vector<uint8_t>>(size_t(layout.levels))};
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

}  // namespace voxlab::clipmap
