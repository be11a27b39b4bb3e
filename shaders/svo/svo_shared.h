// The sparse voxel octree's pool layouts and bit masks, shared by C++ (src/techniques/svo) and
// GLSL (shaders/svo): one header, so the two sides cannot disagree on a mask or a field (source
// error P11 of the technical note: mixed 30/31-bit masks, undefined sentinels).
#ifndef VOXLAB_SVO_SHARED_H
#define VOXLAB_SVO_SHARED_H

#ifdef __cplusplus
#include <algorithm>
#include <cmath>
#include <cstdint>
namespace voxlab::svo {
using uint = uint32_t;
#define SVO_CONST inline constexpr
#define SVO_FN inline
using std::floor;
using std::min;
#else
#define SVO_CONST const
#define SVO_FN
#endif

// SSBO binding points of the octree passes (after those of common/shared.h).
#define SVO_BINDING_NODES 12        // SvoNode[]: the node pool
#define SVO_BINDING_COUNTERS 13     // uint[SVO_COUNTER_WORDS]
#define SVO_BINDING_VALUES 14       // vec4[] per node: premultiplied radiance + opacity at its centre
#define SVO_BINDING_LEAF_SUMS 15    // uvec4[] per node: fixed-point radiance sums + fragment count
#define SVO_BINDING_BRICK_INDEX 16  // uint[] per node: its brick (0 = the zero brick)
#define SVO_BINDING_DESCENT 17      // SvoDescentStep[] of the probed pixel
#define SVO_BINDING_DESCENT_COUNT 18  // uint: descent steps written
#define SVO_BINDING_GROUPS 19       // uint[] per work group of 64 nodes: tagged count, then exclusive prefix
#define SVO_BINDING_NEIGHBOURS 20   // uint[6] per node: same-level face neighbours +x, -x, +y, -y, +z, -z (SVO_ABSENT: none)

// Node word 0: [31] TAG (subdivide at an inner level, owns a brick at any level),
//              [30] NON-EMPTY (a voxel fragment lies inside the node),
//              [29:0] index of the first of the 2x2x2 children (0 = none; the root, node 0, is
//              never a child, so 0 is free as "none"). Children of a tile are contiguous,
//              child index = x + 2y + 4z (Gomes, [MF], [AY]; not [OT]'s x + 4y + 2z).
SVO_CONST uint SVO_TAG = 0x80000000u;
SVO_CONST uint SVO_NON_EMPTY = 0x40000000u;
SVO_CONST uint SVO_CHILD_MASK = 0x3FFFFFFFu;

// One node of the node pool: 16 bytes, std430.
struct SvoNode {
  uint word;    // flags + first child (above)
  uint coords;  // the node's cell at its level, packed 10:10:10 (x bits 0-9), as fragments
  uint level;   // 0 = root ... D = one voxel
  uint parent;  // index of the parent node (the root's is 0)
};

// Counters of the build and brick passes (one SSBO of uints).
SVO_CONST uint SVO_COUNTER_TILES = 0u;      // 2x2x2 tiles allocated so far (node count = 1 + 8 tiles; set by the CPU)
SVO_CONST uint SVO_COUNTER_OVERFLOW = 1u;   // set to 1 by any pass that found its pool full
SVO_CONST uint SVO_COUNTER_NON_EMPTY = 2u;  // non-empty nodes of the level being built
SVO_CONST uint SVO_COUNTER_TAGGED = 3u;     // tagged nodes of the level (non-empty + dilated)
SVO_CONST uint SVO_COUNTER_WORDS = 8u;

// Per-level table ("svo-levels"), one record per level.
struct SvoLevel {
  uint start;     // first node of the level (levels are contiguous in the pool)
  uint count;     // nodes of the level (8 per tagged parent; 1 at the root)
  uint nonEmpty;  // nodes holding a fragment: the distinct occupied cells of the level
  uint tagged;    // nodes subdivided (inner levels) / given a brick (every level): non-empty + dilated
};

// One step of a cone sample's descent (probe record "descent").
struct SvoDescentStep {
  uint sampleIndex;  // index of the cone sample (the record index in "cone-samples")
  uint level;    // octree level of the node
  uint node;     // node index (0 = the root); SVO_ABSENT = no node at this level
  uint coords;   // cell at that level, 10:10:10
  float value[4];  // the node brick's trilinear sample (premultiplied rgb, alpha) at the sample centre
};
// The picked node (svo-pick's probe record): the node of level 'level' at cell 'coords'.
struct SvoPickedNode {
  uint node;          // SVO_ABSENT: no node there (the region is empty at that level)
  uint level;
  uint coords;        // cell at that level, 10:10:10
  uint word;          // flags + first child
  uint children[8];   // first child + k, k = x + 2y + 4z (SVO_ABSENT: not subdivided)
  uint neighbours[6]; // +x, -x, +y, -y, +z, -z (svo-neighbour-links)
  uint brick;         // its brick (0 = none)
  uint pad;
  float texels[108];  // the brick's 27 texels (rgba each), t = x + 3y + 9z (premultiplied rgb, alpha)
};
#define SVO_BINDING_PICKED 21       // SvoPickedNode: the picked node
// vec4[SVO_DIRECTIONAL_RECORD] per node with children (indexed by its tile, (first child - 1) / 8):
// the node as seen by a cone travelling along +x, -x, +y, -y, +z, -z (anisotropic mips,
// common/anisotropic_mip.glsl), then its solid opacity seen along x, y, z (rgb of record 6, the
// same travelling either way; mipmap.fronts, where the six hold the surfaces' fronts only)
#define SVO_BINDING_DIRECTIONAL_VALUES 22
SVO_CONST uint SVO_DIRECTIONAL_RECORD = 7u;
// uint per node: its leaf's facing code, the OR of its fragments' (common/facing.glsl)
#define SVO_BINDING_LEAF_FACING 23
// float[8] per brick number (HDR bricks of Layout N, SVO_SCALED_BRICKS): the scale of its isotropic
// brick's radiance, then of its six directional bricks' (+x -x +y -y +z -z); the texels hold
// radiance / scale in RGBA8 (alpha unscaled)
#define SVO_BINDING_BRICK_SCALES 24
SVO_CONST uint SVO_ABSENT = 0xFFFFFFFFu;
SVO_CONST uint SVO_MAX_DESCENT_STEPS = 16u * 64u * 10u;
// Most bricks a pool may hold: the cone tracer finds a brick's place by float division, exact
// below 2^22 (svoDivide in svo/octree.glsl); 4,194,304 bricks are 453 MB of RGBA8 texels.
SVO_CONST uint SVO_MAX_BRICKS = 4194304u;

// Quadrilinear level weighting (note 1.6). levelStar = D - (log2(diameter / voxel) + bias),
// clamped to [0, D]: the fine level is min(D, floor(levelStar) + 1), the coarse one below it, and
// the fine level's weight is levelStar - coarse. The weight goes to 0 as levelStar reaches the
// coarse level from above and to 1 as it reaches the fine one, so the blend is continuous across
// every integer level (Gomes' listing 4.25 gives the weight to the other level: a jump at each
// integer, invariant I10; tests/unit/test_svo.cpp checks both).
SVO_FN float svoFineLevel(float levelStar, float depth) { return min(depth, floor(levelStar) + 1.0f); }
SVO_FN float svoFineWeight(float levelStar, float depth) { return levelStar - (svoFineLevel(levelStar, depth) - 1.0f); }

#ifdef __cplusplus
#undef SVO_CONST
#undef SVO_FN
}  // namespace voxlab::svo
#endif
#endif  // VOXLAB_SVO_SHARED_H
