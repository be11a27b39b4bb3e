// The integer structure of a 3D clipmap (docs: ../shared/guide/techniques/clipmap.md sections
// 1.2, 1.3, 2.1, 2.2), on the CPU in int64: world-anchored cells, per-level origins snapped to
// the next level's voxel, toroidal addresses, disjoint slabs of newly exposed cells, covered
// blocks and the invalidation plan of one camera move. No GL here: the stages upload what this
// computes, and the unit tests check it against brute force.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace voxlab::clipmap {

using Cell = glm::i64vec3;

// Floor division and the non-negative remainder (b > 0). C++ '/' truncates toward zero and '%'
// keeps the dividend's sign (-3 % 8 == -3): the classic toroidal-addressing bug.
int64_t floorDiv(int64_t a, int64_t b);
int64_t modPos(int64_t a, int64_t b);
Cell floorDiv(const Cell& a, int64_t b);

// A half-open box of cells [lo, hi).
struct Box {
  Cell lo{0}, hi{0};
  bool empty() const { return hi.x <= lo.x || hi.y <= lo.y || hi.z <= lo.z; }
  int64_t volume() const { return empty() ? 0 : (hi.x - lo.x) * (hi.y - lo.y) * (hi.z - lo.z); }
  bool contains(const Cell& c) const {
    return c.x >= lo.x && c.y >= lo.y && c.z >= lo.z && c.x < hi.x && c.y < hi.y && c.z < hi.z;
  }
};
Box intersect(const Box& a, const Box& b);
// Disjoint boxes whose union is a \ b: cut along x first, shrink a to b's x range, then y, then z
// (at most 6 boxes). For a region moved by d this gives slabs of |d_x| N^2, (N-|d_x|) |d_y| N and
// (N-|d_x|)(N-|d_y|) |d_z| cells: N^3 - prod(N - |d_i|) in all.
std::vector<Box> subtract(const Box& a, const Box& b);

// The toroidal address of a cell: c mod N per axis, non-negative; N a power of two, so it is
// c & (N-1) on two's complement integers (what the shaders compute).
glm::ivec3 toroidal(const Cell& c, int n);
// The cell of region [origin, origin+N)^3 stored at physical texel 'texel': origin + ((texel - origin) mod N).
Cell cellAtTexel(const glm::ivec3& texel, const Cell& origin, int n);

struct Layout {
  int levels = 5;            // L clip levels
  int n = 32;                // N^3 cells per level, a power of two
  double voxelSize0 = 0.05;  // s_0, metres; level k has s_k = s_0 2^k
  double voxelSize(int k) const { return voxelSize0 * double(int64_t(1) << k); }
};

// Origins (min corners, in level-k cells) of every level for anchor a (metres):
// o_k = 2 floor(a / s_{k+1}) - N/2 per axis, snapped to the next level's voxel, so every origin
// is even, level k lies inside level k+1 and the anchor lies within [o_k + N/2, o_k + N/2 + 2).
std::vector<Cell> snapOrigins(const Layout& layout, const glm::dvec3& anchor);
// The same with each level led ahead of the anchor: level k is snapped around a + lead N s_k
// (lead in units of the level's extent, e.g. a quarter of the view direction). Consecutive
// centres then differ by lead N s_{k-1}, |lead_i| N / 2 coarse cells, which the margin of N/4 - 1
// coarse cells absorbs while every component of lead is at most 1/4 (for N >= 8): level k-1 stays
// inside level k.
std::vector<Cell> snapOrigins(const Layout& layout, const glm::dvec3& anchor, const glm::dvec3& lead);

// The region of a level with origin o: [o, o + N)^3.
Box region(const Cell& origin, int n);
// The covered block of level k (k >= 1): its cells whose 8 children all lie in level k-1's
// region, i.e. region(o_k) intersected with [o_{k-1}/2, (o_{k-1} + N)/2) (floor division; exact
// because o_{k-1} is even). Level 0 has none (an empty box).
Box coveredBlock(const std::vector<Cell>& origins, int k, int n);

// Which levels a move updates: all of them, or one per move by priority (compix's
// ONE_PER_FRAME_PRIORITY: level i when (move - (2^i - 1)) mod 2^(i+1) == 0, the coarsest level
// every 2^(L-1) moves), the coarsest taking the remaining slot.
enum class Policy { All = 0, Priority = 1 };
bool levelScheduled(Policy policy, int level, int levels, int64_t move);

// The plan of one move of level k from 'before' (or from nothing: a full build) to 'after'.
struct LevelPlan {
  Cell origin{0}, delta{0};  // new origin, and new - old (0 for a full build)
  bool full = false;         // nothing valid before: every cell is rebuilt
  std::vector<Box> exposed;  // disjoint slabs of newly exposed cells (R' \ R)
  int64_t exposedCells = 0;  // N^3 - prod(N - |d_i|), or N^3 for a full build
  // Disjoint boxes of the cells to voxelize directly: uncovered cells (outside the new covered
  // block) that were exposed, or that were covered before (their texels held filtered values).
  std::vector<Box> direct;
  int64_t directCells = 0;
  int64_t coverageChanged = 0;  // cells of R and R' whose covered status changed (both ways)
  Box covered;                  // the new covered block, refiltered from level k-1 on every move
  int64_t refilteredCells = 0;
};
// 'before' empty: a full build. Both are the origins of all levels (the covered blocks depend on
// the finer level).
std::vector<LevelPlan> planMove(const Layout& layout, const std::vector<Cell>& before, const std::vector<Cell>& after);

std::string describe(const Cell& c);

}  // namespace voxlab::clipmap
