// The stages of the clipmap technique (see clipmap.cpp for the overview).
#pragma once
#include <optional>
#include <vector>

#include "graph/stage.h"
#include "techniques/clipmap/clipmap_math.h"
#include "techniques/common/composite_stage.h"
#include "techniques/common/gbuffer_stage.h"

namespace voxlab::clipmap {

// The records of "clip-levels" (one per level, after the last move), for its visualiser
// (src/techniques/clipmap/views/clip_levels.cpp).
inline constexpr Semantic kClipLevels{"clip-levels"};
// The atlas of every level's physical texture, shown by its own view
// (src/techniques/clipmap/views/clip_atlas.cpp: a level's physical texture with the logical origin and
// the physical seam, a hover readout texel -> world cell, unrolled into logical order on request);
// its texels look like the Color semantic's.
inline constexpr Semantic kClipAtlas{"clip-atlas"};
struct LevelRecord {
  glm::vec4 lo;  // world min corner, w = level
  glm::vec4 hi;  // world max corner, w = voxel size
  int32_t origin[3];
  int32_t lag;        // moves since the level was last updated (clipmap.policy=priority)
  int32_t offset[3];  // toroidal offset T_k = o_k mod N: the physical texel of the min corner
  int32_t n;
};
static_assert(sizeof(LevelRecord) == 64, "LevelRecord layout");

// One box of cells the last move voxelizes directly (exposed slabs, cells that left the covered
// block), with where it lands in the physical texture.
struct SlabRecord {
  glm::vec4 lo;  // world min corner, w = level
  glm::vec4 hi;  // world max corner, w = cells in the box
  int32_t cellLo[4];  // w: 1 = inside the level's old region (coverage change), 0 = newly exposed
  int32_t cellHi[4];  // w: unused
  int32_t physLo[4];  // the physical texel of cellLo; w = physical boxes after wrapping (1..8)
};
static_assert(sizeof(SlabRecord) == 80, "SlabRecord layout");
// Per move and level, the planner's counts (clip-plan).
struct PlanRecord {
  uint32_t move, level, exposed, direct, coverageChanged, refiltered;
  int32_t delta[3];
};
static_assert(sizeof(PlanRecord) == 36, "PlanRecord layout");

// The last move's counters (clip-counters, one record per level), for its view
// (src/techniques/clipmap/views/clip_move.cpp): what the shaders wrote, counted by atomics.
inline constexpr Semantic kClipCounters{"clip-counters"};
struct CounterRecord {
  uint32_t cleared, pairs, resolved, refiltered, guards;
};
static_assert(sizeof(CounterRecord) == 20, "CounterRecord layout");

// The layout the parameters ask for: clipmap.levels, clipmap.resolution and clipmap.voxel-size
// ("scene": the scene's largest extent E times the power of two that lets the coarsest level span
// at least 8 E, so a scene in other units gets the same lattice relative to its geometry; the
// exactness tests set power-of-two sizes in metres, for which p / s_k is exact in float).
Layout layoutOf(const ParamSet& params, const Scene& scene);
// Faces per cell in the atlas: 1 (isotropic) or 7 (isotropic + the six directions).
int facesOf(const ParamSet& params);
// The atlas: blocks of (N+2)^3 texels (one guard texel per side), faces along x, levels along y.
TextureDesc atlasDesc(const ParamSet& params);
// clipmap.format: the atlas's (and the mips' and unrolled levels') texel format, RGBA16F by
// default; the define that builds an image-writing program for it (shaders/clipmap/clipmap.glsl).
ParamDesc atlasFormatParam();
GLenum atlasFormat(const ParamSet& params);
std::string atlasFormatDefines(const ParamSet& params);
// Mips of the coarsest level beyond it, in logical order: log2(N) - 2 of them (the chain stops at 4^3),
// so at least one for every N clipmap.resolution allows (8 and up): the cone tracer relies on it.
int mipCount(int n);

// The anchor along the camera path: move j (0 = the start) puts it at the camera position plus
// j * clipmap.path-step, each level's centre led clipmap.look-ahead of its extent along the view
// direction; the origins of each move follow the update policy (a level not scheduled keeps its
// origin). Shared by the anchor and update stages, so both see one path.
struct PathState {
  std::vector<Cell> origins;
  std::vector<int> lag;  // moves since each level was last updated
  glm::dvec3 camera{0.0};  // the camera at this move (metres)
};
std::vector<PathState> cameraPath(const ParamSet& params, const Scene& scene, const ViewState& view);
// The camera at the end of the path: the view given (the path's start P, --look-from or the
// viewer's camera) moved to P + clipmap.path-moves * clipmap.path-step with its orientation kept.
// The translation is recomputed from the rotation rows as glm::lookAtRH does (-dot(row, eye)),
// so a path ending at P + K D gives the same matrix, bit for bit, as a camera placed there when
// the two cameras' rotations are equal (tested: ClipmapGpu.PathImagesEqualScratch).
ViewState pathEndView(const ParamSet& params, const ViewState& view);
std::vector<ParamDesc> layoutParams();
std::vector<ParamDesc> pathParams();
std::vector<ParamDesc> injectParams();
// clipmap.fixed-point-bits: the precision of the accumulated radiance against the fragments a
// cell holds before its sums can overflow (declared by every stage that voxelizes).
ParamDesc fixedPointParam();  // inject.mode, inject.uniform-radiance (as vct-grid's)

// The scene's triangles in the order the voxelizer considers them, cut into runs of at most 512
// of one draw range with their world bounds. Within each draw range the triangles are sorted by
// the Morton code of their centroid (ties in scene order), so a run holds neighbouring triangles
// and its bounds are tight (in scene order a run could span the whole building). The voxelizer's
// sums are integer atomics, so the order changes no texel.
struct TriangleRun {
  uint32_t firstTriangle, triangles, material;  // firstTriangle indexes TriangleOrder::triangles
  glm::vec3 lo, hi;
};
struct TriangleOrder {
  std::vector<uint32_t> triangles;  // the scene's triangle indices, in Morton order per draw range
  std::vector<glm::vec3> lo, hi;    // each one's world bounds, in the same order
  std::vector<TriangleRun> runs;
};
TriangleOrder triangleOrder(const Scene& scene);
// A stage's copy of the scene's triangle order (CPU), computed once per scene (and again after
// forget(): an animation moved the scene's triangles).
class TriangleOrderCache {
 public:
  const TriangleOrder& get(const Scene& scene);
  void forget() { scene_ = nullptr; }

 private:
  TriangleOrder order_;
  const Scene* scene_ = nullptr;
  size_t triangles_ = 0;
};

// One box of cells of one level to voxelize, minus a box to skip (a full build's covered block).
struct Entry {
  int level;
  Box box, skip;
};
// Whether a triangle with world bounds [lo, hi] can pass the voxelize shader's own bounds test for
// 'e': whether the cells its bounds span, as the shader computes them (fl(p * (1 / s_k)), bounded
// from both sides for the rounding), meet e.box outside e.skip. A superset of the triangles that
// give the entry a pair, so a pass over the triangles it accepts writes what a pass over all does.
bool mayReach(const Layout& layout, const Entry& e, const glm::vec3& lo, const glm::vec3& hi);
// Voxelizes and injects the entries into the accumulators bound at binding 12 (counting pairs in
// the counters at 13). The triangles that can reach an entry (mayReach on the CPU: first the runs'
// bounds, then each triangle's) are listed in the blackboard buffer 'visitList' (uint per triangle,
// one writer per stage) and only those are dispatched, one dispatch per material. Returns the
// passes over the triangles; 'runs' receives the runs that reach an entry, 'triangles' the
// triangles dispatched. 'accumulatorLevels': the levels the bound accumulators hold (1: the levels
// take turns, every entry then of one level; clipmap.levels: one each).
int voxelizeEntries(StageContext& ctx, const Layout& layout, const std::vector<Cell>& origins,
                    const std::vector<Entry>& entries, int accumulatorLevels, const TriangleOrder& order,
                    const std::string& visitList, int& runs, int& triangles);

class AnchorStage : public Stage {
 public:
  const char* id() const override { return "anchor"; }
  const char* title() const override { return "Snap the clip levels to the camera"; }
  const char* summary() const override {
    return "Per level, snap the origin to the next level's voxel around the anchor (the camera plus the path's "
           "moves, led clipmap.look-ahead of the level's extent along the view direction) and plan each move: the disjoint slabs of newly exposed cells, the cells whose coverage by the "
           "finer level changed, the covered blocks to refilter.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

// The shared G-buffer stage rendered from the end of the camera path (pathEndView): the same
// stage id, outputs and shader; it also declares the path parameters, so a path change makes it
// stale. No shared code knows about the path.
class PathGBufferStage : public GBufferStage {
 public:
  const char* title() const override { return "G-buffer from the camera at the end of the path"; }
  const char* summary() const override {
    return "Rasterize the visible surface per pixel from the camera moved along the path (P + K D): position, "
           "normal, albedo, emission and depth.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class UpdateStage : public Stage {
 public:
  const char* id() const override { return "update"; }
  const char* title() const override { return "Update the clip levels, one camera move per iteration"; }
  const char* summary() const override {
    return "Iteration 0 builds every level around the start; each further iteration moves the camera one path "
           "step and only clears, voxelizes and lights the cells the move exposed (toroidal addresses: nothing "
           "else moves), refilters the covered blocks from the finer level, fills the cells the camera's space does "
           "not reach (behind closed walls) and refreshes the guard texels.";
  }
  void declare(StageBuilder& b) const override;
  int iterations(const ParamSet& params) const override;
  void execute(StageContext& ctx) override;
  void forgetHeldResults() override {  // the next run is a full build, of triangles read again
    held_.reset();
    order_.forget();
  }

 private:
  // The origins the atlas holds after the last execution, and what they were built from: a later
  // run (the viewer's camera moved) updates incrementally from them when nothing else changed.
  struct Held {
    std::vector<Cell> origins;
    std::vector<uint8_t> key;
    std::vector<std::vector<uint8_t>> filled;  // per level, by physical texel: cells the fill wrote
  };
  std::optional<Held> held_;
  TriangleOrderCache order_;
};

class MipsStage : public Stage {
 public:
  const char* id() const override { return "mips"; }
  const char* title() const override { return "Mip the coarsest level"; }
  const char* summary() const override {
    return "Unroll the coarsest clip level into logical order and average it down to 4^3: the only level with "
           "a mip chain, each mip covering the same volume. Also unroll every level for display (clip-logical).";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class CoveredCompareStage : public Stage {
 public:
  const char* id() const override { return "covered-compare"; }
  const char* title() const override { return "Direct versus filtered content of covered cells"; }
  const char* summary() const override {
    return "With clipmap.compare-covered=on, voxelize the covered blocks directly too and show, per covered "
           "cell, its own voxels beside what the finer level filters into it, and their difference: what a cell "
           "switches to when it leaves the covered block (the source of popping).";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
  void forgetHeldResults() override { order_.forget(); }

 private:
  TriangleOrderCache order_;
};

class ConeTraceStage : public Stage {
 public:
  const char* id() const override { return "cone-trace"; }
  const char* title() const override { return "Trace cones across the clip levels"; }
  const char* summary() const override {
    return "Per pixel, march diffuse cones and a specular cone; each sample reads the finest level whose region "
           "holds its footprint (or coarser, as the cone widens), blending two levels, and ends outside the "
           "coarsest region.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

// The terms of this technique's composite (techniques/common/composite_stage.h).
CompositeTerms compositeTerms();

}  // namespace voxlab::clipmap
