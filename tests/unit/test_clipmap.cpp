// clipmap checks (../shared/guide/techniques/clipmap.md section 5):
//  - CPU, exact: floor division and non-negative modulo against their definitions (C++ '/' and
//    '%' truncate); the toroidal address is a bijection of every region onto [0,N)^3 and its
//    inverse round-trips, for negative and large origins; snapping and nesting invariants; the
//    disjoint slabs of a move hold exactly N^3 - prod(N - |d_i|) cells and are the set R' \ R;
//    the planner's direct set equals its definition cell by cell; a CPU model of the whole
//    clipmap updated by the planner along camera paths equals a full build after every move
//    (both policies: priority converges within 2^(L-1) moves of the camera stopping); the
//    voxelizer's triangle order is a permutation per draw range with tight runs, and the triangles
//    a pass dispatches (mayReach) include every one the shader's bounds test keeps;
//  - GPU: the GLSL toroidal address equals the C++ one (a compute shader writes the map); the
//    atlas after a camera path equals, bit for bit, the atlas built from scratch at the end of
//    the path (every level, face and guard texel; the CPU model's path types, both policies);
//    so do the G-buffer, cone tracing and composite (the camera follows the path); the shaders'
//    atomic counters equal the planner's counts and a small move writes far fewer than N^3
//    texels; an L-shaped object lands in the expected world cells after +-x/y/z moves.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <random>
#include <set>

#include "run/bench_runs.h"
#include "run/reference_error.h"
#include "reference/cpu_voxelizer.h"
#include "reference/image_io.h"
#include "core/paths.h"
#include "scene/scene.h"
#include "capture/capture.h"
#include "common/shared.h"
#include "gpu/shader_library.h"
#include "graph/step_cursor.h"
#include "graph/technique.h"
#include "techniques/clipmap/clipmap_math.h"
#include "techniques/clipmap/stages.h"
#include "test_support.h"

namespace voxlab {
namespace {

using namespace clipmap;
using clipmap::LevelRecord;

TEST(ClipmapMath, FloorDivAndModPosMatchTheirDefinitions) {
  for (int64_t b : {1, 2, 8, 32, 64})
    for (int64_t a = -300; a <= 300; ++a) {
      const int64_t q = floorDiv(a, b), r = modPos(a, b);
      EXPECT_LE(q * b, a);
      EXPECT_GT((q + 1) * b, a);
      EXPECT_EQ(a, q * b + r);
      EXPECT_GE(r, 0);
      EXPECT_LT(r, b);
    }
  // The truncating operators differ exactly here: the bug these helpers exist for.
  EXPECT_EQ(-3 % 8, -3);
  EXPECT_EQ(modPos(-3, 8), 5);
  EXPECT_EQ(-3 / 8, 0);
  EXPECT_EQ(floorDiv(-3, 8), -1);
}

TEST(ClipmapMath, ToroidalAddressIsABijectionForAnyOrigin) {
  std::mt19937_64 rng(14);
  std::vector<Cell> origins = {Cell(0), Cell(-3, 5, -8), Cell(-(int64_t(1) << 30), (int64_t(1) << 30) - 1, 12345678)};
  for (int i = 0; i < 20; ++i) {
    std::uniform_int_distribution<int64_t> d(-(int64_t(1) << 30), int64_t(1) << 30);
    origins.push_back(Cell(d(rng), d(rng), d(rng)));
  }
  for (int n : {8, 16}) {
    for (const Cell& o : origins) {
      std::set<int> seen;
      for (int64_t z = 0; z < n; ++z)
        for (int64_t y = 0; y < n; ++y)
          for (int64_t x = 0; x < n; ++x) {
            const Cell c = o + Cell(x, y, z);
            const glm::ivec3 t = toroidal(c, n);
            ASSERT_TRUE(t.x >= 0 && t.y >= 0 && t.z >= 0 && t.x < n && t.y < n && t.z < n);
            EXPECT_EQ(t.x, int(modPos(c.x, n)));
            seen.insert((t.z * n + t.y) * n + t.x);
            EXPECT_EQ(cellAtTexel(t, o, n), c) << "inverse of " << describe(c) << " with origin " << describe(o);
            // After a move the texel of a cell still in the region is unchanged: it never depended on o.
            const Cell moved = o + Cell(3, -2, 1);
            if (region(moved, n).contains(c)) EXPECT_EQ(cellAtTexel(t, moved, n), c);
          }
      EXPECT_EQ(seen.size(), size_t(n) * n * n) << "origin " << describe(o);
    }
  }
  // The worked 1-D example of the note (N = 8, o = -3): cells -3..4 at physical 5, 6, 7, 0, ..., 4.
  const int expected[8] = {5, 6, 7, 0, 1, 2, 3, 4};
  for (int i = 0; i < 8; ++i) EXPECT_EQ(toroidal(Cell(-3 + i, 0, 0), 8).x, expected[i]);
}

std::vector<glm::dvec3> testAnchors() {
  std::vector<glm::dvec3> anchors = {{0, 0, 0}, {-0.01, 0.3, 1.7}, {1e5, -1e5, 3.3}, {1e7 + 0.123, -2.5e6, 7e6}};
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-50.0, 50.0);
  for (int i = 0; i < 50; ++i) anchors.push_back({u(rng), u(rng), u(rng)});
  return anchors;
}

TEST(ClipmapMath, SnappingAndNestingInvariants) {
  for (int levels : {3, 5})
    for (int n : {8, 16, 32})
      for (const glm::dvec3& a : testAnchors()) {
        Layout layout{levels, n, 0.0625};
        auto o = snapOrigins(layout, a);
        for (int k = 0; k < levels; ++k)
          for (int i = 0; i < 3; ++i) {
            const int64_t ok = o[size_t(k)][i];
            EXPECT_EQ(modPos(ok, 2), 0) << "origins are even";
            // The anchor's cell lies in [o + N/2, o + N/2 + 2): centred within 2 voxels.
            const int64_t cell = int64_t(std::floor(a[i] / layout.voxelSize(k)));
            EXPECT_GE(cell, ok + n / 2);
            EXPECT_LT(cell, ok + n / 2 + 2);
            if (k + 1 < levels) {
              const int64_t next = o[size_t(k + 1)][i];
              EXPECT_GE(ok, 2 * next);
              EXPECT_LE(ok + n, 2 * next + 2 * n);
              // Margin of at least N/4 - 1 coarse cells on both sides.
              EXPECT_GE(ok / 2 - next, n / 4 - 1);
              EXPECT_GE(next + n - (ok + n) / 2, n / 4 - 1);
            }
          }
        // Level k's covered block is exactly the finer region's projection: N/2 cells per axis.
        for (int k = 1; k < levels; ++k) EXPECT_EQ(coveredBlock(o, k, n).volume(), int64_t(n / 2) * (n / 2) * (n / 2));
      }
}

// Levels led ahead of the camera (clipmap.look-ahead) along a direction with every component up
// to 1/4 of the extent: level k is centred within 2 voxels of a + lead N s_k, origins stay even,
// and the margin between level k-1 and level k shrinks by at most ceil(|lead_i| N / 2) coarse
// cells, so level k-1 stays inside level k (its covered block the whole projection) down to
// N = 8. A lead of 3/4 leaves levels sticking out (checked last), so the nesting check is not
// vacuous.
TEST(ClipmapMath, LedLevelsStillNest) {
  const std::vector<glm::dvec3> leads = {{0.25, 0.0, 0.0}, {0.0, -0.25, 0.0}, {0.14, -0.1, 0.17}, {-0.25, 0.25, -0.25}};
  for (int levels : {3, 5})
    for (int n : {8, 16, 32})
      for (const glm::dvec3& lead : leads)
        for (const glm::dvec3& a : testAnchors()) {
          Layout layout{levels, n, 0.0625};
          auto o = snapOrigins(layout, a, lead);
          for (int k = 0; k < levels; ++k)
            for (int i = 0; i < 3; ++i) {
              const int64_t ok = o[size_t(k)][i];
              EXPECT_EQ(modPos(ok, 2), 0) << "origins are even";
              const double centre = a[i] + lead[i] * n * layout.voxelSize(k);
              const int64_t cell = int64_t(std::floor(centre / layout.voxelSize(k)));
              EXPECT_GE(cell, ok + n / 2);
              EXPECT_LT(cell, ok + n / 2 + 2);
              if (k + 1 < levels) {
                const int64_t next = o[size_t(k + 1)][i];
                const int64_t margin = n / 4 - 1 - int64_t(std::ceil(std::abs(lead[i]) * n / 2));
                EXPECT_GE(ok / 2 - next, margin);
                EXPECT_GE(next + n - (ok + n) / 2, margin);
              }
            }
          for (int k = 1; k < levels; ++k) EXPECT_EQ(coveredBlock(o, k, n).volume(), int64_t(n / 2) * (n / 2) * (n / 2));
        }
  Layout small{5, 8, 0.0625};
  int stickingOut = 0;
  for (const glm::dvec3& a : testAnchors()) {
    auto tooFar = snapOrigins(small, a, glm::dvec3(0.75, 0.0, 0.0));
    for (int k = 1; k < small.levels; ++k) stickingOut += coveredBlock(tooFar, k, 8).volume() < 4 * 4 * 4 ? 1 : 0;
  }
  EXPECT_GT(stickingOut, 0) << "a lead of 3/4 at N = 8 leaves some level sticking out of the next";
  Layout layout{5, 32, 0.0625};
  // No lead is the camera-centred snapping.
  EXPECT_EQ(snapOrigins(layout, glm::dvec3(1.3, -2.0, 7.1), glm::dvec3(0.0)), snapOrigins(layout, glm::dvec3(1.3, -2.0, 7.1)));
}

std::set<std::tuple<int64_t, int64_t, int64_t>> cellsOf(const std::vector<Box>& boxes, bool& disjoint) {
  std::set<std::tuple<int64_t, int64_t, int64_t>> s;
  disjoint = true;
  for (const Box& b : boxes)
    for (int64_t z = b.lo.z; z < b.hi.z; ++z)
      for (int64_t y = b.lo.y; y < b.hi.y; ++y)
        for (int64_t x = b.lo.x; x < b.hi.x; ++x)
          if (!s.insert({x, y, z}).second) disjoint = false;
  return s;
}

TEST(ClipmapMath, SlabsAreDisjointAndHoldExactlyTheExposedCells) {
  const int n = 16;
  const std::vector<int64_t> steps = {0, 1, -1, 2, -2, n / 2 - 2, -(n / 2 - 2), n - 2, n, n + 5, -(n + 5)};
  for (int64_t dx : steps)
    for (int64_t dy : {int64_t(0), int64_t(2), int64_t(-(n - 2))})
      for (int64_t dz : {int64_t(0), int64_t(-2), int64_t(n / 2 - 2)}) {
        const Cell o(-5, 7, -1234), d(dx, dy, dz);
        const Box before = region(o, n), after = region(o + d, n);
        bool disjoint = false;
        auto slabs = subtract(after, before);
        auto cells = cellsOf(slabs, disjoint);
        EXPECT_TRUE(disjoint);
        int64_t expected = int64_t(n) * n * n;
        int64_t kept = 1;
        for (int i = 0; i < 3; ++i) kept *= std::max<int64_t>(0, n - std::abs(d[i]));
        expected -= kept;
        EXPECT_EQ(int64_t(cells.size()), expected) << "d = " << describe(d);
        for (const auto& [x, y, z] : cells) {
          EXPECT_TRUE(after.contains(Cell(x, y, z)));
          EXPECT_FALSE(before.contains(Cell(x, y, z)));
        }
      }
  // The note's example: N = 64, d = (2, 0, 0) exposes 8192 cells, 1/32 of the level.
  int64_t total = 0;
  for (const Box& b : subtract(region(Cell(2, 0, 0), 64), region(Cell(0), 64))) total += b.volume();
  EXPECT_EQ(total, 8192);
}

// Brute force of the planner's direct set: cells of R' outside the new covered block that were
// not in R, or were in the old covered block (they held filtered values).
TEST(ClipmapMath, PlannerDirectSetMatchesItsDefinition) {
  Layout layout{4, 8, 0.25};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-20.0, 20.0), step(-3.0, 3.0);
  glm::dvec3 a(u(rng), u(rng), u(rng));
  auto before = snapOrigins(layout, a);
  for (int move = 0; move < 40; ++move) {
    a += glm::dvec3(step(rng), step(rng), step(rng)) * (move % 5 == 0 ? 4.0 : 1.0);
    auto after = snapOrigins(layout, a);
    auto plans = planMove(layout, before, after);
    for (int k = 0; k < layout.levels; ++k) {
      bool disjoint = false;
      auto direct = cellsOf(plans[size_t(k)].direct, disjoint);
      EXPECT_TRUE(disjoint);
      const Box r = region(before[size_t(k)], layout.n), r2 = region(after[size_t(k)], layout.n);
      const Box b = coveredBlock(before, k, layout.n), b2 = coveredBlock(after, k, layout.n);
      int64_t expected = 0, changed = 0;
      for (int64_t z = r2.lo.z; z < r2.hi.z; ++z)
        for (int64_t y = r2.lo.y; y < r2.hi.y; ++y)
          for (int64_t x = r2.lo.x; x < r2.hi.x; ++x) {
            const Cell c(x, y, z);
            const bool want = !b2.contains(c) && (!r.contains(c) || b.contains(c));
            if (want) ++expected;
            EXPECT_EQ(direct.count({x, y, z}) != 0, want) << "level " << k << " cell " << describe(c);
            if (r.contains(c) && b.contains(c) != b2.contains(c)) ++changed;
          }
      EXPECT_EQ(plans[size_t(k)].directCells, expected);
      EXPECT_EQ(plans[size_t(k)].coverageChanged, changed);
    }
    before = after;
  }
}

// A CPU model of the clipmap's logical content: Direct_k(c) is a hash of (k, c), a covered cell
// holds an order-dependent hash of its 8 children's texels. Updating it with the planner along a
// path must give, texel for texel, the full build at the final origins.
struct ModelClipmap {
  Layout layout;
  std::vector<std::vector<uint64_t>> texels;
  explicit ModelClipmap(const Layout& l) : layout(l), texels(size_t(l.levels), std::vector<uint64_t>(size_t(l.n) * l.n * l.n, 0)) {}
  static uint64_t mix(uint64_t h) {
    h += 0x9e3779b97f4a7c15ull;
    h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ull;
    h = (h ^ (h >> 27)) * 0x94d049bb133111ebull;
    return h ^ (h >> 31);
  }
  static uint64_t direct(int k, const Cell& c) {
    return mix(mix(mix(mix(uint64_t(k)) ^ uint64_t(c.x)) ^ uint64_t(c.y)) ^ uint64_t(c.z));
  }
  uint64_t& at(int k, const Cell& c) {
    glm::ivec3 t = toroidal(c, layout.n);
    return texels[size_t(k)][(size_t(t.z) * layout.n + size_t(t.y)) * layout.n + size_t(t.x)];
  }
  uint64_t filtered(int k, const Cell& c) {
    uint64_t h = 0;
    for (int i = 0; i < 8; ++i) h = mix(h ^ at(k - 1, Cell(2) * c + Cell(i & 1, (i >> 1) & 1, i >> 2)));
    return h;
  }
  template <typename F>
  static void forCells(const Box& b, F f) {
    for (int64_t z = b.lo.z; z < b.hi.z; ++z)
      for (int64_t y = b.lo.y; y < b.hi.y; ++y)
        for (int64_t x = b.lo.x; x < b.hi.x; ++x) f(Cell(x, y, z));
  }
  // Applies a plan as the update stage does: direct boxes, then covered blocks fine to coarse.
  int64_t apply(const std::vector<LevelPlan>& plans) {
    int64_t written = 0;
    for (int k = 0; k < layout.levels; ++k)
      for (const Box& b : plans[size_t(k)].direct) forCells(b, [&](const Cell& c) { at(k, c) = direct(k, c); ++written; });
    for (int k = 1; k < layout.levels; ++k)
      forCells(plans[size_t(k)].covered, [&](const Cell& c) { at(k, c) = filtered(k, c); ++written; });
    return written;
  }
};

void expectIncrementalEqualsFull(const Layout& layout, glm::dvec3 start, const std::vector<glm::dvec3>& moves,
                                 Policy policy, const std::string& what) {
  ModelClipmap incremental(layout);
  std::vector<Cell> origins = snapOrigins(layout, start);
  incremental.apply(planMove(layout, {}, origins));
  glm::dvec3 a = start;
  for (size_t j = 0; j < moves.size(); ++j) {
    a += moves[j];
    auto target = snapOrigins(layout, a);
    std::vector<Cell> next = origins;
    for (int k = 0; k < layout.levels; ++k)
      if (levelScheduled(policy, k, layout.levels, int64_t(j))) next[size_t(k)] = target[size_t(k)];
    auto plans = planMove(layout, origins, next);
    const int64_t written = incremental.apply(plans);
    origins = next;
    ModelClipmap full(layout);
    full.apply(planMove(layout, {}, origins));
    for (int k = 0; k < layout.levels; ++k)
      ASSERT_EQ(incremental.texels[size_t(k)], full.texels[size_t(k)])
          << what << ": level " << k << " differs from the full build after move " << j;
    // Cost: every exposed cell is written, and a small move writes far fewer than the whole clipmap.
    int64_t exposed = 0;
    for (const auto& p : plans) exposed += p.exposedCells;
    EXPECT_GE(written, exposed - int64_t(layout.levels) * (layout.n / 2) * (layout.n / 2) * (layout.n / 2));
  }
}

TEST(ClipmapMath, IncrementalEqualsFullAlongPaths) {
  for (int n : {8, 16}) {
    Layout layout{4, n, 0.5};
    const double s = layout.voxelSize0;
    const std::vector<std::pair<std::string, glm::dvec3>> steps = {
        {"no snap", {0.4 * s, 0, 0}},         {"+2 voxels", {2 * s, 0, 0}},
        {"-2 voxels y", {0, -2 * s, 0}},      {"N/2-2 z", {0, 0, (n / 2 - 2) * s}},
        {"N-2", {(n - 2) * s, 0, 0}},         {"N", {0, -n * s, 0}},
        {"N+5", {0, 0, (n + 5) * s}},         {"diagonal", {2 * s, -2 * s, 6 * s}},
        {"coarse only", {0.9 * s, 0.9 * s, 0}}, {"jitter", {-1.3 * s, 0.7 * s, 1.9 * s}}};
    for (const glm::dvec3& start : {glm::dvec3(0.1, 0.2, 0.3), glm::dvec3(1e5, -1e5, 1e5 + 0.77)})
      for (const auto& [name, step] : steps) {
        std::vector<glm::dvec3> moves(6, step);
        if (name == "jitter")
          for (size_t i = 0; i < moves.size(); ++i) moves[i] *= (i % 2 == 0 ? 1.0 : -1.0);
        expectIncrementalEqualsFull(layout, start, moves, Policy::All, name + " N=" + std::to_string(n));
      }
  }
}

TEST(ClipmapMath, PriorityPolicyUpdatesOneLevelPerMoveAndConverges) {
  const int levels = 6;
  // compix's schedule for L = 6 over 32 moves: L0 16x, L1 8x, L2 4x, L3 2x, L4 once, L5 once.
  std::vector<int> count(levels, 0);
  for (int64_t move = 0; move < 32; ++move) {
    int scheduled = 0;
    for (int k = 0; k < levels; ++k)
      if (levelScheduled(Policy::Priority, k, levels, move)) ++scheduled, ++count[size_t(k)];
    EXPECT_EQ(scheduled, 1) << "move " << move;
  }
  EXPECT_EQ(count, (std::vector<int>{16, 8, 4, 2, 1, 1}));
  // Moving then stopping: the incremental model equals the full build once every level has had its turn.
  Layout layout{4, 8, 0.5};
  std::vector<glm::dvec3> moves(5, glm::dvec3(1.1, -0.6, 0.3));
  moves.resize(moves.size() + (size_t(1) << (layout.levels - 1)), glm::dvec3(0.0));
  ModelClipmap incremental(layout);
  glm::dvec3 a(0.3, 0.1, -0.2);
  std::vector<Cell> origins = snapOrigins(layout, a);
  incremental.apply(planMove(layout, {}, origins));
  for (size_t j = 0; j < moves.size(); ++j) {
    a += moves[j];
    auto target = snapOrigins(layout, a);
    std::vector<Cell> next = origins;
    for (int k = 0; k < layout.levels; ++k)
      if (levelScheduled(Policy::Priority, k, layout.levels, int64_t(j))) next[size_t(k)] = target[size_t(k)];
    incremental.apply(planMove(layout, origins, next));
    origins = next;
  }
  EXPECT_EQ(origins, snapOrigins(layout, a)) << "every level caught up with the camera";
  ModelClipmap full(layout);
  full.apply(planMove(layout, {}, origins));
  for (int k = 0; k < layout.levels; ++k) EXPECT_EQ(incremental.texels[size_t(k)], full.texels[size_t(k)]) << "level " << k;
}

// --- The voxelizer's triangle order and culling ----------------------------------------------------

// A 64 x 64 grid of quads in the plane y = 0 (8,192 triangles), listed in a shuffled order, in two
// draw ranges of 4,096 triangles (materials 0 and 1): the order keeps each triangle in its range,
// visits each once, and its runs hold at most 512 triangles of one range with bounds that contain
// theirs; sorted by Morton code, the runs cover far less of the plane than runs cut from the
// shuffled order.
TEST(ClipmapTriangles, OrderIsAPermutationOfEachDrawRangeWithTightRuns) {
  Scene scene;
  const int q = 64;
  for (int j = 0; j <= q; ++j)
    for (int i = 0; i <= q; ++i) scene.positions.push_back({0.25f * float(i), 0.0f, 0.25f * float(j)});
  std::vector<std::array<uint32_t, 3>> tris;
  for (int j = 0; j < q; ++j)
    for (int i = 0; i < q; ++i) {
      const uint32_t a = uint32_t(j * (q + 1) + i), b = a + 1, c = a + uint32_t(q + 1), d = c + 1;
      tris.push_back({a, b, d});
      tris.push_back({a, d, c});
    }
  std::mt19937 rng(7);
  std::shuffle(tris.begin(), tris.end(), rng);
  for (const auto& t : tris) scene.indices.insert(scene.indices.end(), t.begin(), t.end());
  const uint32_t half = 4096;
  scene.draws = {{0, 3 * half, 0}, {3 * half, 3 * half, 1}};
  const TriangleOrder order = triangleOrder(scene);

  ASSERT_EQ(order.triangles.size(), tris.size());
  ASSERT_EQ(order.lo.size(), tris.size());
  std::vector<int> seen(tris.size(), 0);
  for (size_t j = 0; j < order.triangles.size(); ++j) {
    const uint32_t t = order.triangles[j];
    ASSERT_LT(t, tris.size());
    ++seen[t];
    EXPECT_EQ(t < half, j < half) << "triangle " << t << " left its draw range";
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (int i = 0; i < 3; ++i) {
      lo = glm::min(lo, scene.positions[scene.indices[3 * t + uint32_t(i)]]);
      hi = glm::max(hi, scene.positions[scene.indices[3 * t + uint32_t(i)]]);
    }
    EXPECT_EQ(order.lo[j], lo);
    EXPECT_EQ(order.hi[j], hi);
  }
  for (int n : seen) EXPECT_EQ(n, 1);

  uint32_t next = 0;
  double sortedArea = 0.0;
  for (const TriangleRun& r : order.runs) {
    EXPECT_EQ(r.firstTriangle, next);
    EXPECT_LE(r.triangles, 512u);
    EXPECT_EQ(r.material, r.firstTriangle < half ? 0u : 1u);
    EXPECT_EQ(r.firstTriangle < half, r.firstTriangle + r.triangles <= half) << "a run crosses draw ranges";
    for (uint32_t j = r.firstTriangle; j < r.firstTriangle + r.triangles; ++j) {
      EXPECT_TRUE(glm::all(glm::lessThanEqual(r.lo, order.lo[j])) && glm::all(glm::greaterThanEqual(r.hi, order.hi[j])));
    }
    next += r.triangles;
    sortedArea += double(r.hi.x - r.lo.x) * double(r.hi.z - r.lo.z);
  }
  EXPECT_EQ(next, tris.size());
  EXPECT_EQ(order.runs.size(), 16u);  // 8 runs of 512 per range
  // In the shuffled order each run of 512 triangles spans the whole plane (16 runs x 16 m x 16 m
  // = 4,096 m^2, measured). Sorted, a run holds an eighth of the plane, and its bounds about a
  // quarter where the Morton curve crosses a quadrant: 898 m^2 in all (0.22, measured); 0.4
  // leaves room for another space-filling order and fails any order that ignores position.
  double shuffledArea = 0.0;
  for (uint32_t first = 0; first < tris.size(); first += 512) {
    const uint32_t last = std::min<uint32_t>(first + 512, first < half ? half : uint32_t(tris.size()));
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (uint32_t i = 3 * first; i < 3 * last; ++i) {
      lo = glm::min(lo, scene.positions[scene.indices[i]]);
      hi = glm::max(hi, scene.positions[scene.indices[i]]);
    }
    shuffledArea += double(hi.x - lo.x) * double(hi.z - lo.z);
  }
  EXPECT_LT(sortedArea, 0.4 * shuffledArea) << "sorted " << sortedArea << " m^2, shuffled " << shuffledArea;
}

// mayReach accepts every triangle the voxelize shader does not turn away at its bounds test (the
// shader's rule emulated in float: cells floor(p * c), c = float(1 / s_k), clamped to the box,
// not all in the skip box), for vertices on and around cell boundaries near the origin and 1e5 m
// away, with cell sizes that are powers of two and ones that are not (p * c rounds); and what
// else it accepts has a bound within rounding of a cell boundary.
TEST(ClipmapTriangles, CullingKeepsEveryTriangleTheShaderVisits) {
  auto shaderVisits = [](const Layout& layout, const Entry& e, const glm::vec3 (&p)[3]) {
    const float c = float(1.0 / layout.voxelSize(e.level));
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const glm::vec3& v : p) {
      const glm::vec3 w = v * c;
      lo = glm::min(lo, w);
      hi = glm::max(hi, w);
    }
    const Cell bLo = glm::max(Cell(glm::floor(glm::dvec3(lo))), e.box.lo);
    const Cell bHi = glm::min(Cell(glm::floor(glm::dvec3(hi))), e.box.hi - Cell(1));
    if (glm::any(glm::greaterThan(bLo, bHi))) return false;
    return e.skip.empty() || !(glm::all(glm::greaterThanEqual(bLo, e.skip.lo)) && glm::all(glm::lessThan(bHi, e.skip.hi)));
  };
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> small(-3, 3), pick(0, 3);
  std::uniform_real_distribution<double> jitter(-1.0, 1.0);
  int visited = 0, accepted = 0, cases = 0;
  for (double s0 : {0.015625, 0.05, 0.3})
    for (double far : {0.0, 1e5}) {
      const Layout layout{5, 16, s0};
      for (int trial = 0; trial < 4000; ++trial) {
        Entry e;
        e.level = trial % 5;
        const double s = layout.voxelSize(e.level);
        const Cell base = Cell(glm::floor(glm::dvec3(far, -0.5 * far, 0.25 * far) / s));
        e.box.lo = base + Cell(small(rng), small(rng), small(rng));
        e.box.hi = e.box.lo + Cell(1 + pick(rng), 1 + pick(rng), 16);
        if (trial % 3 == 0) e.skip = {e.box.lo + Cell(1), e.box.hi + Cell(2)};
        // Vertices on cell corners of the box, a cell around, exactly or nudged by a few ulps or
        // by up to a tenth of a cell.
        glm::vec3 p[3];
        for (glm::vec3& v : p) {
          const glm::dvec3 cell(e.box.lo + Cell(small(rng), small(rng), small(rng)));
          glm::dvec3 m = cell * s;
          if (pick(rng) == 1) m += glm::dvec3(jitter(rng), jitter(rng), jitter(rng)) * (0.1 * s);
          v = glm::vec3(m);
          if (pick(rng) == 2)
            for (int i = 0; i < 3; ++i) v[i] = std::nextafter(v[i], jitter(rng) < 0.0 ? -1e30f : 1e30f);
        }
        const glm::vec3 lo = glm::min(p[0], glm::min(p[1], p[2])), hi = glm::max(p[0], glm::max(p[1], p[2]));
        const bool visits = shaderVisits(layout, e, p), may = mayReach(layout, e, lo, hi);
        ++cases;
        visited += visits;
        accepted += may;
        EXPECT_TRUE(!visits || may) << "s0 " << s0 << " level " << e.level << " far " << far << " trial " << trial;
        if (may && !visits) {
          // Only where a bound's cell coordinate lies within its rounding of a cell boundary.
          const double c = double(float(1.0 / s));
          bool nearBoundary = false;
          for (const glm::vec3& b : {lo, hi})
            for (int i = 0; i < 3; ++i) {
              const double w = double(b[i]) * c;
              nearBoundary = nearBoundary || std::abs(w - std::round(w)) <= std::abs(w) * 0x1p-21 + 1e-30;
            }
          EXPECT_TRUE(nearBoundary) << "accepted a triangle the shader turns away, s0 " << s0 << " trial " << trial;
        }
      }
    }
  // Measured: 16,733 of the 24,000 cases visited, 18,060 accepted (the vertices lie on cell
  // boundaries on purpose). A quarter visited: the cases reach both sides of the test.
  EXPECT_GT(visited, cases / 4);
  EXPECT_LT(visited, cases);
}

// --- GPU ------------------------------------------------------------------------------------------

using testing_support::capture;
using testing_support::session;

RunRequest clipRequest(glm::vec3 from, std::vector<std::string> sets, const std::string& until = "mips",
                       const std::string& scene = "cornell-box", const std::string& voxelSize = "0.015625") {
  RunRequest r;
  r.technique = "clipmap";
  r.scene = scene;
  r.until = until;
  r.width = r.height = 32;
  r.lookFrom = from;
  r.lookAt = from + glm::vec3(0.0f, 0.0f, 1.0f);
  // Levels centred on the camera, as the CPU models these tests replan with (snapOrigins without a
  // lead), and the atlas as voxelized and filtered, which the CPU models rebuild (no unreached
  // cells filled); a test that leads them or fills sets the parameter itself (later sets win).
  sets.insert(sets.begin(), "clipmap.fill-unreached=off");
  sets.insert(sets.begin(), "clipmap.look-ahead=0");
  sets.push_back("clipmap.resolution=16");
  sets.push_back("clipmap.levels=4");
  // Cornell: 1/64 m, level 3 spans 2 m, the box (0.56 m) lies in levels 1-3.
  sets.push_back("clipmap.voxel-size=" + voxelSize);
  r.sets = std::move(sets);
  return r;
}

TEST(ClipmapGpu, GlslToroidalAddressEqualsCpp) {
  auto& s = session(clipRequest({0.28f, 0.27f, 0.28f}, {}, "anchor"));
  GLuint program = s.cursor().shaders().program({"clipmap/toroidal_map.comp.glsl"});
  const int n = 16;
  const std::vector<Cell> origins = {Cell(0), Cell(-3, 5, -8), Cell(-(int64_t(1) << 30), (int64_t(1) << 30) - 16, 77),
                                     Cell(123457, -99999, -1)};
  Buffer map("toroidal-map", size_t(n) * n * n * 4);
  for (const Cell& o : origins) {
    setUniform(program, "u_clipN", n);
    setUniform(program, "u_clipLevels", 1);
    glm::ivec3 oi(o);
    glProgramUniform3iv(program, glGetUniformLocation(program, "u_clipOrigin"), 1, &oi.x);
    setUniform(program, "u_level", 0);
    glUseProgram(program);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, map.id());
    dispatchCompute({n, n, n}, {4, 4, 4});
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
    auto bytes = map.download();
    std::vector<uint32_t> got(size_t(n) * n * n);
    std::memcpy(got.data(), bytes.data(), got.size() * 4);
    std::set<uint32_t> seen(got.begin(), got.end());
    EXPECT_EQ(seen.size(), got.size()) << "GLSL map is not a bijection for origin " << describe(o);
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          glm::ivec3 t = toroidal(o + Cell(x, y, z), n);
          ASSERT_EQ(got[size_t((z * n + y) * n + x)], uint32_t((t.z * n + t.y) * n + t.x)) << "origin " << describe(o);
        }
  }
}

std::string exact(float v) {
  char text[64];
  std::snprintf(text, sizeof text, "%.10g", double(v));
  return text;
}

std::vector<uint32_t> u32Records(const CapturedOutput& c) {
  std::vector<uint32_t> v(c.records.size() / 4);
  std::memcpy(v.data(), c.records.data(), v.size() * 4);
  return v;
}

// A camera path: --look-from P with K moves of D ends with clip levels equal, bit
// for bit, to those of --look-from P + K D built from scratch (guards included).
// Returns the moved run's clip-plan records (9 words per move and level).
std::vector<uint32_t> expectPathEqualsScratch(glm::vec3 start, glm::vec3 step, int moves, const std::string& what,
                                              std::vector<std::string> extra = {}, const std::string& scene = "cornell-box",
                                              const std::string& voxelSize = "0.015625") {
  auto sets = extra;
  sets.push_back("clipmap.path-step.x=" + exact(step.x));
  sets.push_back("clipmap.path-step.y=" + exact(step.y));
  sets.push_back("clipmap.path-step.z=" + exact(step.z));
  sets.push_back("clipmap.path-moves=" + std::to_string(moves));
  // One session lives at a time (test_support.h): capture the moved run before the other.
  auto& moved = session(clipRequest(start, sets, "mips", scene, voxelSize));
  CapturedOutput a = capture(moved, "update", "clip-atlas");
  auto counters = u32Records(capture(moved, "update", "clip-counters"));
  auto plan = u32Records(capture(moved, "anchor", "clip-plan"));
  // Steps and starts are multiples of 1/256 m (exact in float and in the decimal text), so the
  // end of the path is exactly representable.
  const glm::dvec3 end = glm::dvec3(start) + double(moves) * glm::dvec3(step);
  auto& scratch = session(clipRequest(glm::vec3(end), extra, "mips", scene, voxelSize));
  CapturedOutput b = capture(scratch, "update", "clip-atlas");
  if (a.levels[0].values.size() != b.levels[0].values.size()) {
    ADD_FAILURE() << what << ": atlas sizes differ";
    return plan;
  }
  size_t differ = 0, nonEmpty = 0;
  for (size_t i = 0; i < a.levels[0].values.size(); ++i) {
    if (a.levels[0].values[i] != b.levels[0].values[i]) ++differ;
    if (b.levels[0].values[i] != 0.0f) ++nonEmpty;
  }
  EXPECT_EQ(differ, 0u) << what << ": " << differ << " atlas values differ from the from-scratch build";
  EXPECT_GT(nonEmpty, 1000u) << what << ": the scene must be in the levels for the test to mean anything";
  // The shaders' counters for the last move equal the planner's counts.
  const int levels = 4;
  for (int k = 0; k < levels; ++k) {
    const uint32_t* p = &plan[size_t(9 * (moves * levels + k))];
    EXPECT_EQ(p[0], uint32_t(moves));
    EXPECT_EQ(counters[size_t(5 * k + 0)], p[3]) << what << " level " << k << ": cleared != planned direct cells";
    EXPECT_EQ(counters[size_t(5 * k + 2)], p[3]) << what << " level " << k << ": resolved != planned direct cells";
    EXPECT_EQ(counters[size_t(5 * k + 3)], p[5]) << what << " level " << k << ": refiltered != covered block";
  }
  return plan;
}

// The exposed cells (N^3 - prod(N - |d_i|)) of level k in move j of a clip-plan (4 levels).
uint32_t exposedIn(const std::vector<uint32_t>& plan, int move, int k) { return plan[size_t(9 * (move * 4 + k) + 2)]; }

const glm::vec3 kInside(69.0f / 256.0f, 77.0f / 256.0f, 57.0f / 256.0f);  // inside the Cornell box

TEST(ClipmapGpu, PathOfSmallMovesEqualsScratch) {
  // Two level-0 voxels per move along +x, then check a small move writes far fewer than N^3.
  expectPathEqualsScratch(kInside, {2.0f / 64.0f, 0.0f, 0.0f}, 3, "+2 voxels x");
  auto& s = session(clipRequest(kInside, {"clipmap.path-step.x=" + exact(2.0f / 64.0f), "clipmap.path-step.y=0",
                                          "clipmap.path-step.z=0", "clipmap.path-moves=3"}));
  auto counters = u32Records(capture(s, "update", "clip-counters"));
  uint32_t written = 0;
  for (int k = 0; k < 4; ++k) written += counters[size_t(5 * k + 2)];
  EXPECT_LT(written, 16u * 16u * 16u / 4u) << "direct texels written by one small move";
  EXPECT_GT(written, 0u);
}

// With the fill of unreached cells, in a closed corridor (everything outside it filled): the cells
// an earlier move filled are searched again as empty and emptied where the moved camera's space
// reaches them, so three moves along the corridor end with the atlas of a build from scratch,
// bit for bit.
TEST(ClipmapGpu, PathWithTheFillEqualsScratch) {
  const glm::vec3 start(204.0f / 256.0f, 308.0f / 256.0f, 6.0f);
  expectPathEqualsScratch(start, {0.0f, 0.0f, -0.3125f}, 3, "corridor, filled", {"clipmap.fill-unreached=on"},
                          "corridor", "0.125");
  // The equality means something only where the fill wrote cells: the build from scratch (the
  // session left open) filled every level (measured 288, 2544, 3354, 3556 cells with these
  // settings from a nearby camera).
  auto& scratch = session(clipRequest(glm::vec3(glm::dvec3(start) + 3.0 * glm::dvec3(0.0, 0.0, -0.3125)),
                                      {"clipmap.fill-unreached=on"}, "mips", "corridor", "0.125"));
  StepCursor& c = scratch.cursor();
  const auto& stats = c.record(c.technique().stageIndex("update")).stats;
  for (int k = 0; k < 4; ++k) EXPECT_GT(stats.at("level" + std::to_string(k) + "_filled"), 100.0) << "level " << k;
}

// bench's timed runs (timeStages) start from scratch and carry the timings the update stage takes
// of its own parts: after earlier runs the last timed run is still a full build (invalidateAll
// drops the held origins; without it the run is a move of zero cells), and every level and phase
// has one *_ms value per timed run, the other statistics none.
TEST(ClipmapGpu, BenchRunsAreFullBuildsWithPerLevelTimings) {
  auto& s = session(clipRequest(kInside, {"clipmap.policy=all"}, "composite"));
  StepCursor& cursor = s.cursor();
  const int runs = 2;
  const StageTimes t = timeStages(cursor, runs);
  const int update = cursor.technique().stageIndex("update");
  const StageStats& last = t.lastStats[size_t(update)];
  EXPECT_EQ(last.at("full_build"), 1.0) << "the last timed run is a full build";
  EXPECT_EQ(last.at("cells_exposed"), 4.0 * 16 * 16 * 16);
  const auto& sub = t.sub[size_t(update)];
  std::vector<std::string> want = {"clear_ms", "voxelize_ms", "resolve_ms", "filter_ms", "guards_ms", "move0_ms"};
  for (int k = 0; k < 4; ++k) want.push_back("level" + std::to_string(k) + "_ms");
  for (const auto& name : want) {
    ASSERT_TRUE(sub.count(name)) << name;
    EXPECT_EQ(sub.at(name).size(), size_t(runs)) << name;
    for (double v : sub.at(name)) EXPECT_GE(v, 0.0) << name;
  }
  EXPECT_FALSE(sub.count("texels_written"));
  EXPECT_TRUE(isSubTiming("level0_ms"));
  EXPECT_FALSE(isSubTiming("level0_pairs"));
  EXPECT_FALSE(isSubTiming("_ms"));
}

TEST(ClipmapGpu, DiagonalAndLargeMovesEqualScratch) {
  expectPathEqualsScratch(kInside, {-13.0f / 256.0f, 7.0f / 256.0f, -29.0f / 256.0f}, 2, "diagonal");
  expectPathEqualsScratch({26.0f / 256.0f, 26.0f / 256.0f, 26.0f / 256.0f}, {0.0f, 0.0f, 21.0f / 64.0f}, 1, "N+5 along z");
}

// The path types of the CPU model (ClipmapMath.IncrementalEqualsFullAlongPaths) on the GPU, at
// N = 16 with level-0 voxels of 1/64 m = 4/256 m (every start and step a multiple of 1/256 m).
TEST(ClipmapGpu, PathTypesOfTheCpuModelEqualScratch) {
  struct Path {
    const char* what;
    glm::vec3 step;
    int moves;
  };
  const float v = 1.0f / 64.0f;  // one level-0 voxel
  const Path paths[] = {
      // A quarter voxel per move: level 0 snaps to 2/64 m, so no level's origin changes.
      {"no snap", {0.25f * v, 0.25f * v, 0.25f * v}, 1},
      {"N/2-2 = 6 voxels along z", {0.0f, 0.0f, 6.0f * v}, 2},
      {"N-2 = 14 voxels along -x", {-14.0f * v, 0.0f, 0.0f}, 1},
  };
  for (const Path& p : paths) {
    const auto plan = expectPathEqualsScratch(kInside, p.step, p.moves, p.what);
    if (std::string(p.what) == "no snap")
      for (int k = 0; k < 4; ++k) EXPECT_EQ(exposedIn(plan, 1, k), 0u) << "no snap: level " << k << " moved";
    else
      EXPECT_GT(exposedIn(plan, p.moves, 0), 0u) << p.what << ": level 0 must move";
  }
  // N = 16 voxels along y, six faces: level 0's new region shares no cell with the old one.
  const auto plan = expectPathEqualsScratch(kInside, {0.0f, 16.0f * v, 0.0f}, 1, "N along y, anisotropic",
                                            {"clipmap.faces=anisotropic"});
  EXPECT_EQ(exposedIn(plan, 1, 0), 16u * 16u * 16u);
}

TEST(ClipmapGpu, AnisotropicFacesAndPriorityEqualScratch) {
  expectPathEqualsScratch(kInside, {0.0f, -3.0f / 64.0f, 0.0f}, 2, "anisotropic -y", {"clipmap.faces=anisotropic"});
  // clipmap.policy=priority (L = 4): moves 1..8 update levels 0 1 0 2 0 1 0 3, so move 8 changes
  // only the coarsest level. Start x = 60/256 m and steps of 1/256 m (x, y) and -1/256 m (z): x
  // crosses 64/256 m, a level-3 snap (s_4 = 1/4 m), at the last move, and each finer level's last
  // update (moves 7, 6, 4) already snapped to the end's origins, so every level has caught up and
  // the atlas must equal the build from scratch at the end.
  const glm::vec3 start(60.0f / 256.0f, 77.0f / 256.0f, 57.0f / 256.0f);
  const auto plan = expectPathEqualsScratch(start, {1.0f / 256.0f, 1.0f / 256.0f, -1.0f / 256.0f}, 8,
                                            "priority, coarse level only at the last move",
                                            {"clipmap.policy=priority", "clipmap.faces=anisotropic"});
  for (int k = 0; k < 3; ++k) EXPECT_EQ(exposedIn(plan, 8, k), 0u) << "level " << k << " moved at the last move";
  EXPECT_GT(exposedIn(plan, 8, 3), 0u) << "the coarsest level moves at the last move";
}

// The camera follows the path: the G-buffer, the cone tracing and the composite of a run from P
// with K moves of D are those of a run from P + K D with no moves, bit for bit (the clip levels
// are equal bit for bit, the view matrix is rebuilt as lookAtRH builds it, and each pixel's
// result depends only on those).
// A run along a path of camera moves gives, bit for bit, the images of a run started at its end;
// 'extra' adds parameters to both runs.
void expectPathImagesEqualScratch(const std::vector<std::string>& extra) {
  const glm::vec3 start(69.0f / 256.0f, 77.0f / 256.0f, -64.0f / 256.0f);  // in front of the box
  const glm::vec3 step(2.0f / 64.0f, -1.0f / 64.0f, 5.0f / 64.0f);
  const int moves = 3;
  const std::pair<const char*, const char*> images[] = {{"gbuffer", "position"},
                                                        {"cone-trace", "indirect-diffuse"},
                                                        {"cone-trace", "indirect-specular"},
                                                        {"composite", "combined"},
                                                        {"composite", "final"}};
  std::vector<LevelData> moved;
  {
    std::vector<std::string> path = {"clipmap.path-step.x=" + exact(step.x), "clipmap.path-step.y=" + exact(step.y),
                                     "clipmap.path-step.z=" + exact(step.z), "clipmap.path-moves=" + std::to_string(moves)};
    path.insert(path.end(), extra.begin(), extra.end());
    auto& s = session(clipRequest(start, path, "composite"));
    for (const auto& [stage, output] : images) moved.push_back(capture(s, stage, output).levels[0]);
  }
  const glm::vec3 end = glm::vec3(glm::dvec3(start) + double(moves) * glm::dvec3(step));
  auto& scratch = session(clipRequest(end, extra, "composite"));
  size_t covered = 0;
  for (size_t i = 0; i < std::size(images); ++i) {
    const LevelData b = capture(scratch, images[i].first, images[i].second).levels[0];
    ASSERT_EQ(moved[i].values.size(), b.values.size());
    size_t differ = 0;
    for (size_t j = 0; j < b.values.size(); ++j) differ += moved[i].values[j] != b.values[j];
    EXPECT_EQ(differ, 0u) << images[i].first << "/" << images[i].second << ": " << differ
                          << " values differ from the run started at P + K D";
    if (i == 0)
      for (int y = 0; y < b.size.y; ++y)
        for (int x = 0; x < b.size.x; ++x) covered += b.at(x, y, 0, 3) > 0.0f;
  }
  // The camera at P + K D sees the box (a camera left at P sees other pixels: the test can fail).
  EXPECT_GT(covered, size_t(32 * 32 / 2));
}

TEST(ClipmapGpu, PathImagesEqualScratch) { expectPathImagesEqualScratch({}); }

// With the levels led ahead of the camera the lead is the same at every move (the path keeps the
// orientation), so the moves still expose exactly the slabs a fresh build at the end holds.
TEST(ClipmapGpu, PathImagesEqualScratchLookingAhead) { expectPathImagesEqualScratch({"clipmap.look-ahead=0.25"}); }

// The cells of box 'r' (cells of edge 1 / cellsPerMetre of the world lattice) that a triangle
// meets: the CPU reference voxelizer's double-precision half-open test.
std::set<std::tuple<int64_t, int64_t, int64_t>> cpuOccupiedCells(const Scene& scene, double cellsPerMetre, const Box& r) {
  std::set<std::tuple<int64_t, int64_t, int64_t>> cpu;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    glm::dvec3 w[3];
    for (int i = 0; i < 3; ++i) w[i] = glm::dvec3(scene.positions[scene.indices[3 * t + i]]) * cellsPerMetre;
    if (glm::length(glm::cross(w[1] - w[0], w[2] - w[0])) == 0.0) continue;
    const Cell lo = glm::max(Cell(glm::floor(glm::min(w[0], glm::min(w[1], w[2])))), r.lo);
    const Cell hi = glm::min(Cell(glm::floor(glm::max(w[0], glm::max(w[1], w[2])))), r.hi - Cell(1));
    for (int64_t z = lo.z; z <= hi.z; ++z)
      for (int64_t y = lo.y; y <= hi.y; ++y)
        for (int64_t x = lo.x; x <= hi.x; ++x)
          if (triangleOverlapsBox(w[0], w[1], w[2], glm::dvec3(x, y, z) + 0.5, glm::dvec3(0.5))) cpu.insert({x, y, z});
  }
  return cpu;
}

// covered-compare: each covered cell's own voxels are the CPU reference's, and the difference
// image is |direct - filtered| against the atlas, texel for texel within one RGBA8 step (0 outside
// the covered blocks).
TEST(ClipmapGpu, CoveredCellsDirectVersusFiltered) {
  auto& s = session(clipRequest(kInside, {"clipmap.compare-covered=on"}, "covered-compare"));
  const LevelData direct = capture(s, "covered-compare", "covered-direct").levels[0];
  const LevelData difference = capture(s, "covered-compare", "covered-difference").levels[0];
  const LevelData atlas = capture(s, "update", "clip-atlas").levels[0];
  CapturedOutput levels = capture(s, "anchor", "clip-levels");
  const int n = 16, b = n + 2;
  std::vector<Cell> origins;
  for (int k = 0; k < 4; ++k) {
    LevelRecord r;
    std::memcpy(&r, levels.records.data() + size_t(k) * sizeof(LevelRecord), sizeof(LevelRecord));
    origins.push_back(Cell(r.origin[0], r.origin[1], r.origin[2]));
  }
  size_t occupied = 0, differing = 0;
  for (int k = 0; k < 4; ++k) {
    const Box cov = coveredBlock(origins, k, n);
    const auto cpu = cpuOccupiedCells(s.cursor().scene(), 64.0 / double(1 << k), cov);
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const Cell c = origins[size_t(k)] + Cell(x, y, z);
          const glm::ivec3 t = toroidal(c, n);
          for (int ch = 0; ch < 4; ++ch) {
            const float d = direct.at(x, k * n + y, z, ch), diff = difference.at(x, k * n + y, z, ch);
            if (!cov.contains(c)) {
              ASSERT_EQ(d, 0.0f);
              ASSERT_EQ(diff, 0.0f);
              continue;
            }
            // The shader subtracts the unrounded direct value, then stores both rounded to RGBA8:
            // measured at most one step (1/255) from |stored direct - filtered|.
            ASSERT_NEAR(diff, std::abs(d - atlas.at(1 + t.x, k * b + 1 + t.y, 1 + t.z, ch)), 1.0f / 255.0f + 1e-5f);
            if (ch == 3) differing += diff > 0.0f;
          }
          if (cov.contains(c)) {
            const bool want = cpu.count({c.x, c.y, c.z}) != 0;
            EXPECT_EQ(direct.at(x, k * n + y, z, 3) > 0.0f, want) << "level " << k << " covered cell " << describe(c);
            occupied += want;
          }
        }
  }
  EXPECT_GT(occupied, 100u);
  EXPECT_GT(differing, 0u) << "filtered and direct content differ somewhere (the source of popping)";
}

// Mean light of the occupied cells of a single clip level over the whole corridor (its
// isotropic values: radiance over opacity), voxelized directly at cell size 'voxelSize'.
double corridorMeanLight(const std::string& voxelSize, int n) {
  RunRequest r;
  r.technique = "clipmap";
  r.scene = "corridor";
  r.until = "mips";
  r.width = r.height = 32;
  r.lookFrom = glm::vec3(0.8f, 1.2f, 6.0f);
  r.lookAt = glm::vec3(0.8f, 1.2f, 5.0f);
  // The cells as voxelized: the space outside the corridor, filled, would count as occupied.
  r.sets = {"clipmap.levels=1", "clipmap.resolution=" + std::to_string(n), "clipmap.voxel-size=" + voxelSize,
            "clipmap.faces=isotropic", "clipmap.fill-unreached=off"};
  auto& s = session(r);
  const LevelData cells = capture(s, "mips", "clip-logical").levels[0];
  double light = 0.0, opacity = 0.0;
  for (size_t i = 0; i < cells.texelCount(); ++i) {
    for (int ch = 0; ch < 3; ++ch) light += cells.values[i * 4 + size_t(ch)];
    opacity += cells.values[i * 4 + 3];
  }
  EXPECT_GT(opacity, 50.0) << voxelSize;
  return light / opacity;
}

// Coarse cells keep the light of their surfaces: over the whole corridor, the mean light of the
// occupied cells voxelized directly at 0.75 m (the cells that hold its lamp's end seen from the
// camera, 11 m away) against 0.1875 m. The light of a (triangle, cell) pair used to be evaluated
// at the cell centre's projection onto the triangle's plane: where a coarse cell holds a sliver
// of a wall, that point lies above the ceiling or beyond a corner, in the shadow or far from the
// lamp, and the coarse cells held 0.68 of the fine cells' light (the corridor's indirect light
// was 0.52 of the reference). Evaluated at the triangle's point nearest the centre: 0.85 (what is
// left: a coarse cell's mean weighs each of its triangles alike, whatever its area there).
TEST(ClipmapGpu, CoarseCellsKeepTheLightOfTheirSurfaces) {
  const double fine = corridorMeanLight("0.1875", 64), coarse = corridorMeanLight("0.75", 16);
  std::printf("corridor mean light of the occupied cells: 0.1875 m %.4f, 0.75 m %.4f (ratio %.3f)\n", fine, coarse,
              coarse / fine);
  // The sums are fixed point, so the ratio is the same on every run (0.845); the bound sits
  // halfway between the old evaluation point's 0.68 and now.
  EXPECT_GT(coarse / fine, 0.78);
  EXPECT_LT(coarse / fine, 1.1);
}

// The atlas against an independent CPU reference, level by level (catches Y flips, scroll signs,
// a wrong toroidal address or block layout): every uncovered cell of every level is occupied
// (alpha 1) exactly when a triangle meets its world cell [c, c+1) s_k (the CPU reference
// voxelizer's double-precision half-open test on the cell coordinates p / s_k), and every covered
// cell holds the mean of its 8 children (alpha within one RGBA8 step: the filter stores a float
// mean, rounded once). Guards hold the wrapped texel exactly.
TEST(ClipmapGpu, AtlasMatchesCpuVoxelsAndFilter) {
  auto& s = session(clipRequest(kInside, {"clipmap.faces=isotropic"}, "update"));
  CapturedOutput atlas = capture(s, "update", "clip-atlas");
  CapturedOutput levels = capture(s, "anchor", "clip-levels");
  const Scene& scene = s.cursor().scene();
  const int n = 16, levelCount = 4, b = n + 2;
  const LevelData& a = atlas.levels[0];
  ASSERT_EQ(a.size, glm::ivec3(b, levelCount * b, b));
  std::vector<Cell> origins;
  for (int k = 0; k < levelCount; ++k) {
    LevelRecord r;
    std::memcpy(&r, levels.records.data() + size_t(k) * sizeof(LevelRecord), sizeof(LevelRecord));
    origins.push_back(Cell(r.origin[0], r.origin[1], r.origin[2]));
  }
  auto texel = [&](int k, const Cell& c, int ch) {
    glm::ivec3 t = toroidal(c, n);
    return a.at(1 + t.x, k * b + 1 + t.y, 1 + t.z, ch);
  };
  size_t occupied = 0, mismatched = 0, covered = 0;
  for (int k = 0; k < levelCount; ++k) {
    const double cellsPerMetre = 64.0 / double(1 << k);  // s_0 = 1/64 m
    const Box r = region(origins[size_t(k)], n), cov = coveredBlock(origins, k, n);
    const auto cpu = cpuOccupiedCells(scene, cellsPerMetre, r);
    for (int64_t z = r.lo.z; z < r.hi.z; ++z)
      for (int64_t y = r.lo.y; y < r.hi.y; ++y)
        for (int64_t x = r.lo.x; x < r.hi.x; ++x) {
          const Cell c(x, y, z);
          if (cov.contains(c)) {
            float mean = 0.0f;
            for (int i = 0; i < 8; ++i) mean += texel(k - 1, Cell(2) * c + Cell(i & 1, (i >> 1) & 1, i >> 2), 3);
            EXPECT_NEAR(texel(k, c, 3), mean / 8.0f, 0.5f / 255.0f + 1e-6f) << "covered cell " << describe(c) << " of level " << k;
            ++covered;
            continue;
          }
          const bool gpu = texel(k, c, 3) > 0.0f, want = cpu.count({x, y, z}) != 0;
          if (gpu != want) ++mismatched;
          EXPECT_EQ(gpu, want) << "level " << k << " cell " << describe(c);
          occupied += want;
        }
  }
  EXPECT_EQ(mismatched, 0u);
  EXPECT_GT(occupied, 1000u);
  EXPECT_EQ(covered, size_t(3 * 8 * 8 * 8));  // levels 1-3: (N/2)^3 covered cells each
  // Guards: texel -1 holds N-1 and texel N holds 0 on every axis (corners included).
  for (int k = 0; k < levelCount; ++k)
    for (int z = 0; z < b; ++z)
      for (int y = 0; y < b; ++y)
        for (int x = 0; x < b; ++x) {
          glm::ivec3 l(x - 1, y - 1, z - 1);
          if (glm::all(glm::greaterThanEqual(l, glm::ivec3(0))) && glm::all(glm::lessThan(l, glm::ivec3(n)))) continue;
          glm::ivec3 src = (l + n) & (n - 1);
          for (int ch = 0; ch < 4; ++ch)
            ASSERT_EQ(a.at(x, k * b + y, z, ch), a.at(1 + src.x, k * b + 1 + src.y, 1 + src.z, ch)) << "guard " << x << "," << y << "," << z;
        }
}

// Locality: between the atlas after move K-1 and after move K, only texels of the move's planned
// cells (voxelized directly or refiltered) and guard texels differ: no data moves.
TEST(ClipmapGpu, AMoveChangesOnlyItsPlannedCells) {
  const glm::vec3 step(-2.0f / 64.0f, 0.0f, 6.0f / 64.0f);
  auto path = [&](int moves) {
    return clipRequest(kInside, {"clipmap.path-step.x=" + exact(step.x), "clipmap.path-step.y=0",
                                 "clipmap.path-step.z=" + exact(step.z), "clipmap.path-moves=" + std::to_string(moves)},
                       "update");
  };
  CapturedOutput before = capture(session(path(1)), "update", "clip-atlas");
  auto& s = session(path(2));
  CapturedOutput after = capture(s, "update", "clip-atlas");
  // Replan the last move on the CPU.
  Layout layout{4, 16, 1.0 / 64.0};
  auto o1 = snapOrigins(layout, glm::dvec3(kInside) + glm::dvec3(step));
  auto o2 = snapOrigins(layout, glm::dvec3(kInside) + 2.0 * glm::dvec3(step));
  auto plans = planMove(layout, o1, o2);
  const int n = 16, b = n + 2;
  std::set<std::tuple<int, int, int, int>> allowed;  // (level, physical x, y, z)
  for (int k = 0; k < 4; ++k) {
    std::vector<Box> boxes = plans[size_t(k)].direct;
    boxes.push_back(plans[size_t(k)].covered);
    for (const Box& box : boxes)
      ModelClipmap::forCells(box, [&](const Cell& c) {
        glm::ivec3 t = toroidal(c, n);
        allowed.insert({k, t.x, t.y, t.z});
      });
  }
  const LevelData& x0 = before.levels[0];
  const LevelData& x1 = after.levels[0];
  size_t changed = 0;
  for (int k = 0; k < 4; ++k)
    for (int z = 0; z < b; ++z)
      for (int y = 0; y < b; ++y)
        for (int x = 0; x < b; ++x) {
          bool differs = false;
          for (int ch = 0; ch < 4; ++ch) differs = differs || x0.at(x, k * b + y, z, ch) != x1.at(x, k * b + y, z, ch);
          if (!differs) continue;
          ++changed;
          glm::ivec3 l(x - 1, y - 1, z - 1);
          const bool guard = glm::any(glm::lessThan(l, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(l, glm::ivec3(n)));
          if (guard) continue;
          EXPECT_TRUE(allowed.count({k, l.x, l.y, l.z})) << "level " << k << " texel " << l.x << "," << l.y << "," << l.z
                                                          << " changed outside the move's plan";
        }
  EXPECT_GT(changed, 0u);
  EXPECT_LT(changed, size_t(4) * n * n * n / 4);
}

// The logical view unrolls each level: its texel (x, kN + y, z) is cell o_k + (x, y, z), found in
// the atlas at that cell's toroidal address (a second, C++ reading of the GLSL addresses).
TEST(ClipmapGpu, LogicalViewUnrollsEveryLevel) {
  auto& s = session(clipRequest(kInside, {"clipmap.path-moves=1", "clipmap.path-step.x=" + exact(-5.0f / 64.0f)}));
  const LevelData atlas = capture(s, "update", "clip-atlas").levels[0];
  const LevelData logical = capture(s, "mips", "clip-logical").levels[0];
  CapturedOutput levels = capture(s, "anchor", "clip-levels");
  const int n = 16, b = n + 2;
  size_t nonEmpty = 0;
  for (int k = 0; k < 4; ++k) {
    LevelRecord r;
    std::memcpy(&r, levels.records.data() + size_t(k) * sizeof(LevelRecord), sizeof(LevelRecord));
    const Cell o(r.origin[0], r.origin[1], r.origin[2]);
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const glm::ivec3 t = toroidal(o + Cell(x, y, z), n);
          EXPECT_EQ(cellAtTexel(t, o, n), o + Cell(x, y, z));
          for (int ch = 0; ch < 4; ++ch)
            ASSERT_EQ(logical.at(x, k * n + y, z, ch), atlas.at(1 + t.x, k * b + 1 + t.y, 1 + t.z, ch))
                << "level " << k << " logical " << x << "," << y << "," << z;
          nonEmpty += logical.at(x, k * n + y, z, 3) > 0.0f;
        }
  }
  EXPECT_GT(nonEmpty, 1000u);
}

// After every move, not only at the end: the update stage stepped one iteration (one move) at a
// time, the atlas after move j equals the build from scratch at P + j D, for a path that snaps
// levels 0 and 1 on alternate moves (3 level-0 voxels per move, diagonal).
TEST(ClipmapGpu, EveryMoveEqualsScratch) {
  const glm::vec3 step(3.0f / 64.0f, -3.0f / 64.0f, 1.0f / 64.0f);
  const int moves = 4;
  std::vector<LevelData> stepped;
  {
    auto& s = session(clipRequest(kInside, {"clipmap.path-step.x=" + exact(step.x), "clipmap.path-step.y=" + exact(step.y),
                                            "clipmap.path-step.z=" + exact(step.z), "clipmap.path-moves=" + std::to_string(moves)},
                                  "update"));
    StepCursor& c = s.cursor();
    const int update = c.technique().stageIndex("update");
    c.invalidate(update);
    for (int j = 0; j <= moves; ++j) {
      ASSERT_EQ(c.runIteration(update), j);
      stepped.push_back(capture(s, "update", "clip-atlas").levels[0]);
    }
  }
  for (int j = 0; j <= moves; ++j) {
    const glm::dvec3 end = glm::dvec3(kInside) + double(j) * glm::dvec3(step);
    auto& scratch = session(clipRequest(glm::vec3(end), {}, "update"));
    const LevelData b = capture(scratch, "update", "clip-atlas").levels[0];
    size_t differ = 0;
    for (size_t i = 0; i < b.values.size(); ++i) differ += stepped[size_t(j)].values[i] != b.values[i];
    EXPECT_EQ(differ, 0u) << "after move " << j << ": " << differ << " atlas values differ from the build from scratch";
  }
}

// A scene of the given triangles (positions in metres, one grey material) and a camera with a
// near plane of 1 cm (the loader's framing camera would put it at half its distance), written as
// glTF into the test's temporary folder; the loader adds the default sun.
std::string writeTriangleScene(const std::string& name, const std::vector<glm::vec3>& positions,
                               const std::vector<uint32_t>& indices) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(::testing::TempDir());
  const std::string bin = name + ".bin";
  const size_t p = positions.size() * 12, i = indices.size() * 4;
  std::ofstream out((dir / bin).string(), std::ios::binary);
  out.write(reinterpret_cast<const char*>(positions.data()), std::streamsize(p));
  out.write(reinterpret_cast<const char*>(indices.data()), std::streamsize(i));
  out.close();
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& v : positions) lo = glm::min(lo, v), hi = glm::max(hi, v);
  nlohmann::json g = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0, 1}}}}},
      {"nodes", {{{"mesh", 0}}, {{"camera", 0}, {"translation", {0.0, 0.5, 2.0}}}}},
      {"cameras", {{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.01}, {"zfar", 20.0}}}}}},
      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}, {"material", 0}}}}}}},
      {"materials", {{{"name", "grey"}, {"doubleSided", true}}}},
      {"buffers", {{{"uri", bin}, {"byteLength", p + i}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteLength", p}}, {{"buffer", 0}, {"byteOffset", p}, {"byteLength", i}}}},
      {"accessors",
       {{{"bufferView", 0}, {"componentType", 5126}, {"count", positions.size()}, {"type", "VEC3"},
         {"min", {lo.x, lo.y, lo.z}}, {"max", {hi.x, hi.y, hi.z}}},
        {{"bufferView", 1}, {"componentType", 5125}, {"count", indices.size()}, {"type", "SCALAR"}}}}};
  const std::string path = (dir / (name + ".gltf")).string();
  std::ofstream(path) << g.dump();
  return path;
}

// An L-shaped object of three arms from corner cell K = (-20, -6, -9) of level 0 (1/64 m): 80
// cells along +x, 24 along +y, 12 along +z, each arm a thin quad strictly inside one row of
// cells (its plane at a cell's middle, its width from 1/4 to 3/4 of a cell), so the level-0
// cells it meets are known without a voxelizer, and the level-k cells are their floor(c / 2^k).
// The arms' different lengths tell the axes and their signs apart: a Y flip, a swapped axis or
// a scroll of the wrong sign puts occupied cells where none are expected.
TEST(ClipmapGpu, LShapedObjectLandsInTheRightWorldCellsAfterMoves) {
  const float s = 1.0f / 64.0f;
  const glm::ivec3 k0(-20, -6, -9);
  const int arm[3] = {80, 24, 12};
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;
  std::set<std::tuple<int64_t, int64_t, int64_t>> cells0;
  for (int axis = 0; axis < 3; ++axis) {
    // Along 'axis' from K + 1/4 to K + arm - 1/4 cells; across it 1/4..3/4 of a cell along 'wide';
    // at the middle of K's cell along the third axis.
    const int wide = axis == 2 ? 1 : (axis + 1) % 3, flat = 3 - axis - wide;
    const uint32_t base = uint32_t(positions.size());
    for (int corner = 0; corner < 4; ++corner) {
      glm::vec3 c;
      c[axis] = float(k0[axis]) + ((corner & 1) ? float(arm[axis]) - 0.25f : 0.25f);
      c[wide] = float(k0[wide]) + ((corner & 2) ? 0.75f : 0.25f);
      c[flat] = float(k0[flat]) + 0.5f;
      positions.push_back(c * s);
    }
    indices.insert(indices.end(), {base, base + 1, base + 3, base, base + 3, base + 2});
    for (int i = 0; i < arm[axis]; ++i) {
      Cell c(k0);
      c[axis] += i;
      cells0.insert({c.x, c.y, c.z});
    }
  }
  const std::string scene = writeTriangleScene("voxlab-clipmap-l-shape", positions, indices);
  const glm::vec3 start(-54.0f / 256.0f, -6.0f / 256.0f, -18.0f / 256.0f);  // near K, multiples of 1/256 m
  const int n = 16, levelCount = 4, b = n + 2;
  std::vector<size_t> occupiedPerLevel(levelCount, 0);
  for (int axis = 0; axis < 3; ++axis)
    for (float sign : {1.0f, -1.0f}) {
      glm::vec3 step(0.0f);
      step[axis] = sign * 3.0f * s;  // 3 level-0 voxels per move: every move snaps level 0
      const std::string what = std::string(sign > 0 ? "+" : "-") + "xyz"[axis];
      auto& run = session(clipRequest(start,
                                      {"clipmap.path-step.x=" + exact(step.x), "clipmap.path-step.y=" + exact(step.y),
                                       "clipmap.path-step.z=" + exact(step.z), "clipmap.path-moves=2",
                                       "inject.mode=uniform"},
                                      "update", scene));
      const LevelData a = capture(run, "update", "clip-atlas").levels[0];
      const CapturedOutput levels = capture(run, "anchor", "clip-levels");
      std::vector<Cell> origins;
      for (int k = 0; k < levelCount; ++k) {
        LevelRecord r;
        std::memcpy(&r, levels.records.data() + size_t(k) * sizeof(LevelRecord), sizeof(LevelRecord));
        origins.push_back(Cell(r.origin[0], r.origin[1], r.origin[2]));
      }
      // The origins are the end of the path's (the anchor moved 6 voxels along 'axis').
      EXPECT_EQ(origins, snapOrigins(Layout{levelCount, n, 1.0 / 64.0}, glm::dvec3(start) + 2.0 * glm::dvec3(step)))
          << what;
      for (int k = 0; k < levelCount; ++k) {
        std::set<std::tuple<int64_t, int64_t, int64_t>> expected;
        for (const auto& [x, y, z] : cells0)
          expected.insert({floorDiv(x, int64_t(1) << k), floorDiv(y, int64_t(1) << k), floorDiv(z, int64_t(1) << k)});
        const Box r = region(origins[size_t(k)], n), cov = coveredBlock(origins, k, n);
        size_t wrong = 0;
        for (int64_t z = r.lo.z; z < r.hi.z; ++z)
          for (int64_t y = r.lo.y; y < r.hi.y; ++y)
            for (int64_t x = r.lo.x; x < r.hi.x; ++x) {
              const Cell c(x, y, z);
              if (cov.contains(c)) continue;  // filtered from level k-1 (AtlasMatchesCpuVoxelsAndFilter)
              const glm::ivec3 t = toroidal(c, n);
              const bool got = a.at(1 + t.x, k * b + 1 + t.y, 1 + t.z, 3) > 0.0f, want = expected.count({x, y, z}) != 0;
              if (got != want && ++wrong <= 5)
                ADD_FAILURE() << what << ": level " << k << " cell " << describe(c) << (want ? " empty" : " occupied");
              occupiedPerLevel[size_t(k)] += want;
            }
        EXPECT_EQ(wrong, 0u) << what << ": level " << k;
      }
    }
  // Every level holds part of the L in its uncovered cells, so every level's addressing is checked.
  for (int k = 0; k < levelCount; ++k) EXPECT_GT(occupiedPerLevel[size_t(k)], 6u) << "level " << k;
}

TEST(ClipmapGpu, SponzaPathEqualsScratch) {
  // The natural scene: larger than any level. Levels of 1/4 m .. 2 m around the nave, three moves
  // of 2.5 level-0 voxels diagonally (every level snaps at some move).
  expectPathEqualsScratch({0.5f, 2.0f, -0.25f}, {0.625f, 0.125f, -0.375f}, 3, "Sponza diagonal", {}, "sponza", "0.25");
}

}  // namespace
}  // namespace voxlab

namespace voxlab {
namespace {

// Toroidal addressing returns some texel for any position: the tracer must end a cone outside the
// coarsest region. Two levels of 1/64 m and 1/32 m (the coarsest spans 0.5 m) around the camera,
// which the path moves 0.9 m from camera 0's position into the box (to z = 0.1 m), looking at the
// back left lower corner; cones at most 0.05 m long. The floor and left wall beyond z = 0.46 m lie
// farther outside the region than a cone reaches, and their cells' aliases (z mod 0.5 m) are
// cells of the floor and left wall near the box's opening, which the atlas holds. Far pixels must
// gather nothing (without the bounds check they read the aliases: checked by mutating the
// tracer's "outside the coarsest region" test into "read the coarsest level": 1022 of the 1931
// far pixels then gather light), where pixels inside the region do gather (422).
TEST(ClipmapGpu, SamplesOutsideTheCoarsestRegionContributeNothing) {
  RunRequest r;
  r.technique = "clipmap";
  r.scene = "cornell-box";
  r.width = r.height = 64;
  r.lookFrom = glm::vec3(0.278f, 0.273f, -0.8f);
  r.lookAt = *r.lookFrom + glm::vec3(-0.278f, -0.273f, 0.46f);  // from (0.278, 0.273, 0.1) to (0, 0, 0.56)
  r.sets = {"clipmap.resolution=16", "clipmap.levels=2", "clipmap.voxel-size=0.015625", "clipmap.path-moves=1",
            "clipmap.path-step.z=0.9", "cone.resolution=full", "cone.max-distance=0.1"};
  auto& s = session(r);
  CapturedOutput indirect = capture(s, "cone-trace", "indirect-diffuse");
  CapturedOutput position = capture(s, "gbuffer", "position");
  CapturedOutput atlas = capture(s, "update", "clip-atlas");
  CapturedOutput levels = capture(s, "anchor", "clip-levels");
  size_t nonEmptyAtlas = 0;
  for (float v : atlas.levels[0].values) nonEmptyAtlas += v != 0.0f;
  ASSERT_GT(nonEmptyAtlas, 1000u) << "the region must hold part of the box";
  LevelRecord coarsest;
  std::memcpy(&coarsest, levels.records.data() + sizeof(LevelRecord), sizeof(LevelRecord));
  const glm::vec3 lo(coarsest.lo), hi(coarsest.hi);
  const float reach = 0.1f * 0.5f + 3.0f / 64.0f;  // cone length + start offset and first step
  const LevelData& in = indirect.levels[0];
  const LevelData& pos = position.levels[0];
  size_t far = 0, insideLit = 0;
  for (int y = 0; y < in.size.y; ++y)
    for (int x = 0; x < in.size.x; ++x) {
      if (pos.at(x, y, 0, 3) == 0.0f) continue;  // sky
      const glm::vec3 p(pos.at(x, y, 0, 0), pos.at(x, y, 0, 1), pos.at(x, y, 0, 2));
      const float outside = glm::length(glm::max(glm::max(lo - p, p - hi), glm::vec3(0.0f)));
      const float sum = in.at(x, y, 0, 0) + in.at(x, y, 0, 1) + in.at(x, y, 0, 2);
      if (outside > reach + 0.01f) {
        ++far;
        EXPECT_EQ(sum, 0.0f) << "pixel (" << x << ", " << y << ") " << outside << " m outside the coarsest region gathered light";
      } else if (outside == 0.0f && sum > 0.0f) {
        ++insideLit;
      }
    }
  std::printf("far pixels %zu (all dark), inside pixels that gathered light %zu\n", far, insideLit);
  EXPECT_GT(far, 200u);
  EXPECT_GT(insideLit, 200u);
}

// The opacity each diffuse cone of the probed pixel has gathered at its end (its last sample).
static std::map<int, float> coneOpacities(const std::string& frontHold, const std::string& fill = "off") {
  RunRequest r;
  r.technique = "clipmap";
  r.scene = "corridor";
  r.width = r.height = 128;
  r.sets = {"probe.x=0.5", "probe.y=0.5", "clipmap.front-hold=" + frontHold, "clipmap.fill-unreached=" + fill};
  auto& s = session(r);
  const CapturedOutput c = capture(s, "cone-trace", "cone-samples");
  std::vector<gpu::ConeSample> v(std::min<size_t>(c.recordCount, c.records.size() / sizeof(gpu::ConeSample)));
  if (!v.empty()) std::memcpy(v.data(), c.records.data(), v.size() * sizeof(gpu::ConeSample));
  std::map<int, float> opacity;  // samples of a cone come in order of distance
  for (const gpu::ConeSample& sample : v) opacity[int(sample.info.x)] = sample.accumulated.w;
  return opacity;
}

// Surfaces in coarse cells stop the cones that cross them. The probed pixel is the corridor's end
// wall, 11 m from the camera: it lies in 0.75 m cells (level 2), and its five tilted diffuse cones
// meet a side wall, the floor or the ceiling within a metre, sampled at level 2 while their width
// asks for level 1. Each such wall is one coarse cell, whose trilinear opacity peaks at the cell's
// centre, up to half a cell in front of the wall; the cones crossed it between samples and went on
// into the void outside the corridor, the cone towards the x = 0 wall with an opacity of only 0.56
// (the end wall's indirect light was 0.47 of the reference). Holding a front's opacity half a cell
// behind it (clipmap.front-hold=0.5) brings the least opaque of the five to 0.74 (deterministic
// runs, both measured here with nine cones: 0.561 without, 0.796 with); the bound 0.65 lies between. Measured
// without the fill of unreached cells, which stops them too (next test).
TEST(ClipmapPhysics, CoarseWallsStopTheConesThatCrossThem) {
  const auto without = coneOpacities("0"), with = coneOpacities("0.5");
  float leastWithout = 1.0f, leastWith = 1.0f;
  for (int cone = 1; cone <= 5; ++cone) {
    ASSERT_TRUE(without.count(cone) && with.count(cone)) << "cone " << cone << " has no samples";
    leastWithout = std::min(leastWithout, without.at(cone));
    leastWith = std::min(leastWith, with.at(cone));
  }
  std::printf("least opacity of the tilted cones from the corridor's end wall: %.3f without the hold, %.3f with\n",
              leastWithout, leastWith);
  EXPECT_LT(leastWithout, 0.65f);
  EXPECT_GT(leastWith, 0.65f);
}

// The corridor is closed, so every cone from its end wall ends on a wall: its opacity should reach
// 1. With the space outside the corridor empty, the cone along the wall's normal runs 12 m down
// the corridor seeing its walls edge-on (measured opacity 0.03) and the tilted ones leave through
// the walls they graze (0.74 to 0.97 with the hold): the end wall got 0.56 to 0.69 of the
// reference's light. With the cells the camera's space does not reach filled (clipmap.fill-
// unreached, the default) every cone ends opaque (measured 0.999 to 1.000, deterministic);
// the bound 0.98 fails if the fill stops short of any side of the corridor, and the normal cone's
// 0.5 if the coarse levels (where that cone reads) are left empty.
TEST(ClipmapPhysics, ConesEndOnTheWallsOfAClosedCorridor) {
  const auto empty = coneOpacities("0.5", "off"), filled = coneOpacities("0.5", "on");
  ASSERT_TRUE(empty.count(0) && filled.count(0));
  std::printf("end wall, normal cone opacity: %.3f empty outside, %.3f filled\n", empty.at(0), filled.at(0));
  EXPECT_LT(empty.at(0), 0.5f);
  for (const auto& [cone, opacity] : filled) {
    if (cone > 8) continue;  // the specular cone
    EXPECT_GT(opacity, 0.98f) << "cone " << cone;
  }
}

// One bounce against the path tracer (indirect-1) on the Cornell box, camera 0, at the snapshot
// size with the defaults (32^3 cells, 5 levels, s_0 = E/64, HDR cells, six faces showing the
// fronts each direction sees, cones an eighth of a voxel off the surface, fronts held half a cell
// behind where a sample reads a level coarser than its cone's, light injected at the point of each
// triangle nearest the cell centre): measured mean ratio 1.19 at 256x256 (voxlab fidelity), 1.184,
// RMSE 0.0502 and SSIM 0.784 here at 128x128 (the printed line); before the hold, with a quarter-
// voxel start, 1.17 at 256x256 and 1.167, RMSE 0.0530, SSIM 0.754 here. The sum is too
// high above and too low below: the ceiling and the top of the back wall get 1.4-1.9 times the
// reference (they see the tall box's top under the spot, and the emissive panel, whose light on
// the walls the reference counts as direct: 0.05 of the ratio), the floor and the boxes' fronts
// 0.25-0.7 (their lower cones start a coarse voxel out and step through the floor). With the
// light injected at the cell centre's projection onto the triangle's plane it measured 1.053
// (slivers of surfaces lit off the surface), with a start offset of one voxel 1.206, with 1.75
// voxels and RGBA8 isotropic cells 0.781. The band [0.95, 1.25] fails on a lost or extra pi
// (ratio 0.37 or 3.7), a lost cone or a level read at the wrong place (each shifts the ratio by
// more than the 0.07 to the band's upper edge; the run is deterministic).
TEST(ClipmapPhysics, OneBounceIndirectAgainstTheReferencePathTracer) {
  RunRequest r;
  r.technique = "clipmap";
  r.scene = "cornell-box";
  r.width = r.height = 128;
  auto& s = session(r);
  CapturedOutput out = capture(s, "cone-trace", "indirect-diffuse");
  const nlohmann::json e = compareWithReference(out, "cornell-box", 0, ::testing::TempDir(), "clipmap-indirect");
  ASSERT_FALSE(e.is_null());
  ASSERT_FALSE(e.contains("skipped")) << e.dump();
  const double ratio = e["mean_ratio"].get<double>(), rmse = e["rmse"].get<double>();
  std::printf("clipmap indirect-1 mean ratio %.3f, rmse %.4f, ssim %.3f\n", ratio, rmse, e["ssim"].get<double>());
  EXPECT_GT(ratio, 0.95);
  EXPECT_LT(ratio, 1.25);
  EXPECT_LT(rmse, 0.08);
}

// The traced pixels (of the half-resolution indirect image) that show the camera-facing faces of one
// of the Cornell box's boxes: G-buffer normal within 26 degrees of -z, in front of the back wall;
// 'sideX' picks the box by the sign of the normal's x (the tall box's front turns to -x, the short
// box's to +x). Also returns the indirect diffuse image they index.
static std::vector<glm::ivec2> boxFrontPixels(HeadlessSession& s, float sideX, CapturedOutput& indirect) {
  indirect = capture(s, "cone-trace", "indirect-diffuse");
  CapturedOutput position = capture(s, "gbuffer", "position");
  CapturedOutput normal = capture(s, "gbuffer", "normal");
  const LevelData& in = indirect.levels[0];
  const LevelData& pos = position.levels[0];
  const LevelData& nrm = normal.levels[0];
  const int scale = pos.size.x / in.size.x;  // half resolution: pixel p shades G-buffer pixel 2p
  std::vector<glm::ivec2> pixels;
  for (int y = 0; y < in.size.y; ++y)
    for (int x = 0; x < in.size.x; ++x) {
      const int gx = std::min(x * scale, pos.size.x - 1), gy = std::min(y * scale, pos.size.y - 1);
      if (pos.at(gx, gy, 0, 3) == 0.0f) continue;
      const float nx = nrm.at(gx, gy, 0, 0), nz = nrm.at(gx, gy, 0, 2);
      if (nz > -0.9f || pos.at(gx, gy, 0, 2) > 0.45f || nx * sideX <= 0.0f) continue;
      pixels.emplace_back(x, y);
    }
  return pixels;
}

static double rgbSum(const LevelData& l, int x, int y) { return double(l.at(x, y, 0, 0)) + l.at(x, y, 0, 1) + l.at(x, y, 0, 2); }

// The mean indirect diffuse radiance (r + g + b) over one box's camera-facing faces.
static double meanOverBoxFront(HeadlessSession& s, float sideX, size_t* count) {
  CapturedOutput indirect;
  const std::vector<glm::ivec2> pixels = boxFrontPixels(s, sideX, indirect);
  double sum = 0.0;
  for (const glm::ivec2& p : pixels) sum += rgbSum(indirect.levels[0], p.x, p.y);
  *count = pixels.size();
  return pixels.empty() ? 0.0 : sum / double(pixels.size());
}

// The same mean, and the path tracer's one-bounce radiance (tests/golden/reference/cornell-box/
// indirect-1.exr, 512x512, camera 0) over the same pixels: each traced pixel against the mean of
// the reference pixels it covers.
static std::pair<double, double> boxFrontAndReference(HeadlessSession& s, float sideX) {
  CapturedOutput indirect;
  const std::vector<glm::ivec2> pixels = boxFrontPixels(s, sideX, indirect);
  const LevelData& in = indirect.levels[0];
  const reference::Image ref = reference::readExr(projectPath("tests/golden/reference/cornell-box/indirect-1.exr"));
  const int refScale = ref.width / in.size.x;
  double sum = 0.0, refSum = 0.0;
  for (const glm::ivec2& q : pixels) {
    sum += rgbSum(in, q.x, q.y);
    double block = 0.0;
    for (int j = 0; j < refScale; ++j)
      for (int i = 0; i < refScale; ++i) {
        const size_t p = size_t(ref.height - 1 - (q.y * refScale + j)) * size_t(ref.width) + size_t(q.x * refScale + i);
        block += double(ref.rgb[3 * p]) + ref.rgb[3 * p + 1] + ref.rgb[3 * p + 2];
      }
    refSum += block / double(refScale * refScale);
  }
  EXPECT_GT(pixels.size(), 50u) << "the box's front must be in the picture";
  const double n = double(std::max<size_t>(pixels.size(), 1));
  return {sum / n, refSum / n};
}

// The same faces against the path tracer. Measured (128x128, deterministic): 0.929 of the
// reference on the tall box's front and 0.666 on the short box's at the defaults (levels led an
// eighth of their extent ahead of the camera, which puts the boxes in finer levels; faces read at
// level 0 too; a 3/8-voxel start; 0.613 and 0.748 with centred levels and an eighth-voxel start),
// 0.065 and 0.024 with cone.start-offset=1.75 and centred levels (the black faces: the boxes in
// level 3's 7 cm voxels). The bound 0.3 lies far from both, so the defaults pass and the black
// faces fail it.
constexpr double kBoxFrontBound = 0.3;
TEST(ClipmapPhysics, CameraFacingBoxFacesAgainstTheReference) {
  RunRequest r;
  r.technique = "clipmap";
  r.scene = "cornell-box";
  r.width = r.height = 128;
  RunRequest far = r;
  far.sets = {"cone.start-offset=1.75", "clipmap.look-ahead=0"};
  for (float side : {-1.0f, 1.0f}) {
    const auto [mean, reference] = boxFrontAndReference(session(r), side);
    const auto [farMean, farReference] = boxFrontAndReference(session(far), side);
    ASSERT_GT(reference, 0.0);
    std::printf("%s box front against the reference: %.3f (start offset 1.75: %.3f)\n", side < 0.0f ? "tall" : "short",
                mean / reference, farMean / farReference);
    ::testing::Test::RecordProperty(std::string(side < 0.0f ? "tall" : "short") + "_ratio", std::to_string(mean / reference));
    ::testing::Test::RecordProperty(std::string(side < 0.0f ? "tall" : "short") + "_ratio_offset_1_75",
                                    std::to_string(farMean / farReference));
    EXPECT_GT(mean / reference, kBoxFrontBound);
    EXPECT_LT(farMean / farReference, kBoxFrontBound);
  }
}

// The boxes' camera-facing faces face away from the spot, so all their light is indirect. With
// the clip levels centred on the camera 0.8 m in front of the box, the boxes lie in level 3 (7 cm
// voxels). With cones starting 1.75 of those voxels off the face, plus a first step of one voxel,
// the cones of the short box's front began outside the box's open side and those of the tall box's
// front close to it: measured 0.019 (short) and 0.060 (tall) of vct-grid's mean indirect radiance
// there (vct-grid's 128^3 grid starts its cones a centimetre off the face). With the one-voxel
// offset and isotropic RGBA8 cells: 0.377 and 0.401 against vct-grid's RGBA8 voxels. With the
// defaults now (HDR cells, six faces showing the fronts, also at level 0, levels led an eighth of
// their extent ahead of the camera, a 3/8-voxel offset, fronts held half a cell): 1.001 (tall)
// and 0.395 (short) against vct-grid's defaults (0.660 and 0.443 with centred levels, isotropic
// level 0 and an eighth-voxel offset; 0.643 and 0.317 with a quarter-voxel offset and no hold). The
// bound 0.25 sits below both and far above the far start's; the runs are deterministic, the
// measured ratios do not vary between runs.
TEST(ClipmapPhysics, CameraFacingBoxFacesGatherIndirectLight) {
  RunRequest r;
  r.technique = "clipmap";
  r.scene = "cornell-box";
  r.width = r.height = 128;
  RunRequest g = r;
  g.technique = "vct-grid";
  for (float side : {-1.0f, 1.0f}) {
    size_t clipmapPixels = 0, gridPixels = 0;
    const double clipmapMean = meanOverBoxFront(session(r), side, &clipmapPixels);
    const double gridMean = meanOverBoxFront(session(g), side, &gridPixels);
    std::printf("%s box front: clipmap %.4f over %zu pixels, vct-grid %.4f over %zu pixels, ratio %.3f\n",
                side < 0.0f ? "tall" : "short", clipmapMean, clipmapPixels, gridMean, gridPixels,
                clipmapMean / gridMean);
    ASSERT_GT(clipmapPixels, 50u);
    ASSERT_GT(gridPixels, 50u);
    ASSERT_GT(gridMean, 0.0);
    EXPECT_GT(clipmapMean / gridMean, 0.25);
  }
}

}  // namespace
}  // namespace voxlab
