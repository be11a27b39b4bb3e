#version 450
// svo-bricks, one invocation per node. kPass 1: every tagged node (non-empty, or dilated) takes
// the 3x3x3 brick (Layout N: node-centred, borders included) whose number is 1 + its rank among
// the tagged nodes in pool order (brick 0 is the reserved all-zero brick), after checking the
// pool's capacity. The rank needs no count of its own: svo-build gave each tagged node above the
// voxels the 2x2x2 tile numbered by the same rank, so its brick is 1 + (first child - 1) / 8;
// the tagged voxels come after all tiles (u_tiles), ranked by the exclusive prefix sums of tagged
// voxels per group of 64 that svo-build's last level left in svo-groups. The pool is identical on
// every run. Texel t in {0,1,2}^3 lies at node.min + t * size / 2; it gets the mean of the centre
// values of the 1, 2, 4 or 8 same-level cells that share that point, found by position (a gather:
// exact where the separable x, y, z transfer of Basgier and Gomes is not, source error P3; absent
// cells count 0; cells beyond the volume are clamped to the edge, as vct-grid's CLAMP_TO_EDGE
// sampling is). Trilinear filtering inside the brick then reproduces the dense grid's trilinear
// sample exactly inside the node.
// kLayoutTile = 1 (Layout T, Crassin/Gomes): a brick for every subdivided node (tagged, above the
// voxels) instead, numbered 1 + its tile; its texel t lies at the corner 2 * cell + t of its
// children (child-level coordinates) and gets the mean of the 8 child-level cells sharing that
// corner (clamped to the volume), so the brick of a level-l node holds level l + 1 and leaves have
// none. kPass 2 (Layout T, Gaussian) is below.
// kAnisotropic = 1 (Layout N): every tagged node above the voxels also gets six directional
// bricks in a second pool (u_directionalPool), one per travel direction d (+x -x +y -y +z -z),
// with the same texel layout and border means as its isotropic brick but made of the same-level
// cells' directional values (svo-mipmap): brick b of direction d lies at 3 * (b mod X, b / X mod
// Y, b / XY) + (0, 0, 3 Z d) for the directional pool's X x Y x Z bricks per direction. Its
// numbers are those of the isotropic bricks above the voxels (1 + the node's tile), so one brick
// number addresses both pools. Trilinear filtering inside a directional brick then equals
// vct-grid's trilinear sample of its directional volume of that level inside the node. With
// kFronts = 1 (mipmap.fronts) the same bricks of a third pool (u_opacityPool, RGBA8, one part)
// hold the nodes' solid opacity seen along x, y, z (rgb, either way), as vct-grid's solid-opacity
// volume.
// The pools' image format: rgba8 unless the stage defines VOXLAB_GRID_FORMAT (voxel.format=rgba16f
// with Layout T). With SVO_SCALED_BRICKS (voxel.format=rgba16f, Layout N) the pools stay RGBA8 and
// every brick stores its radiance divided by its own scale, the largest radiance channel of its 27
// texels (brickScales, per brick number: the isotropic brick, then the six directions); a sample
// filters within one brick only, so the scaled texels filter exactly. Opacity is not scaled.
// Layout N's pass 1 runs in two dispatches, two programs (llvmpipe runs both sides of every
// branch, so the code a dispatch never needs must not be in its program): SVO_VOXEL_TILES 1 for the
// tiles of voxels (their parents at level D - 1, most of the tiles: no directional bricks), 0 for
// the tiles above and the root (and for Layout T and pass 2, over every node).
#ifndef VOXLAB_GRID_FORMAT
#define VOXLAB_GRID_FORMAT rgba8
#endif
#ifndef SVO_VOXEL_TILES
#error "svo/bricks.comp.glsl needs SVO_VOXEL_TILES (svo/stages.cpp)"
#endif
// The stage's choices, fixed per program by its defines (svo/stages.cpp, brickChoiceDefines): as
// uniforms, every invocation also ran the code of the layout, pass and kernel not chosen, masked.
#if !defined(SVO_BRICK_PASS) || !defined(SVO_LAYOUT_TILE) || !defined(SVO_ANISOTROPIC_BRICKS) || \
    !defined(SVO_FRONTS_BRICKS) || !defined(SVO_GAUSSIAN)
#error "svo/bricks.comp.glsl needs SVO_BRICK_PASS, SVO_LAYOUT_TILE, SVO_ANISOTROPIC_BRICKS, SVO_FRONTS_BRICKS and SVO_GAUSSIAN (svo/stages.cpp)"
#endif
const int kPass = SVO_BRICK_PASS;                 // 1: bricks from the values; 2: Layout T's Gaussian, one level
const int kLayoutTile = SVO_LAYOUT_TILE;          // 1: Layout T (svo.layout=tile)
const int kAnisotropic = SVO_ANISOTROPIC_BRICKS;  // 1: the directional bricks too (Layout N)
const int kFronts = SVO_FRONTS_BRICKS;            // 1: the solid-opacity bricks are built too
const int kGaussian = SVO_GAUSSIAN;               // Layout T only: 1 = Crassin/Gomes' 1/8-1/16-1/32-1/64 kernel above level D - 1
#include "common/packing.glsl"
#include "svo/svo_shared.h"

layout(local_size_x = 64) in;
// common/invocation.glsl reads gl_WorkGroupSize, so it comes after the layout line.
#include "common/invocation.glsl"
layout(std430, binding = SVO_BINDING_NODES) readonly buffer Nodes { SvoNode nodes[]; };
layout(std430, binding = SVO_BINDING_VALUES) readonly buffer Values { vec4 values[]; };
layout(std430, binding = SVO_BINDING_COUNTERS) coherent buffer Counters { uint counters[]; };
layout(std430, binding = SVO_BINDING_BRICK_INDEX) buffer BrickIndex { uint brickIndex[]; };
layout(std430, binding = SVO_BINDING_GROUPS) readonly buffer Groups { uint groups[]; };  // svo-build's, of the voxel level
layout(std430, binding = SVO_BINDING_DIRECTIONAL_VALUES) readonly buffer Directional { vec4 directional[]; };
layout(std430, binding = SVO_BINDING_BRICK_SCALES) writeonly buffer BrickScales { float brickScales[]; };
layout(VOXLAB_GRID_FORMAT, binding = 0) uniform writeonly image3D u_brickPool;
layout(VOXLAB_GRID_FORMAT, binding = 1) uniform writeonly image3D u_directionalPool;
layout(rgba8, binding = 2) uniform writeonly image3D u_opacityPool;
uniform ivec3 u_directionalPerAxis;  // bricks per axis of one direction's part of the directional pool
uniform uint u_firstNode;  // the dispatch's nodes: u_firstNode .. u_nodeEnd - 1
uniform uint u_nodeEnd;
uniform uint u_brickCapacity;  // bricks the pool holds, the zero brick included
uniform ivec3 u_bricksPerAxis;
uniform int u_depth;
uniform int u_level;      // pass 2: the level whose bricks are filtered from the level below
uniform uint u_leafStart; // first node of the voxel level (level D)
uniform uint u_tiles;     // tiles svo-build allocated: the tagged nodes above the voxels
layout(binding = 0) uniform sampler3D u_poolRead;  // the same pool, read back in pass 2
#include "svo/octree.glsl"

ivec3 brickOrigin(uint b) { return 3 * ivec3(svoBrickCoords(b, uvec2(u_bricksPerAxis.xy))); }

// A Layout N brick's 27 texels, scaled (SVO_SCALED_BRICKS): its radiance divided by the largest
// radiance channel among them, which is stored as the scale of part 'part' of brick b.
void scaleBrick(inout vec4 nb[27], uint b, uint part) {
#ifdef SVO_SCALED_BRICKS
  float largest = 0.0;
  for (int t = 0; t < 27; ++t) largest = max(largest, max(nb[t].r, max(nb[t].g, nb[t].b)));
  float scale = largest > 0.0 ? largest : 1.0;
  for (int t = 0; t < 27; ++t) nb[t].rgb /= scale;
  brickScales[8u * b + part] = scale;
#endif
}

bool hasBrick(uint n) {
  return (nodes[n].word & SVO_TAG) != 0u && (kLayoutTile == 0 || int(nodes[n].level) < u_depth);
}

// The first child of every node in the 3x3x3 neighbourhood of node n (at cell pc of level
// 'level'; 0 = none or outside the volume).
void neighbourhoodChildren(uint n, ivec3 pc, int level, out uint around[27]) {
  int cells = 1 << level;
  for (int k = 0; k < 27; ++k) {
    ivec3 q = pc + ivec3(k % 3, (k / 3) % 3, k / 9) - 1;
    uint other = k == 13 ? n
               : any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, ivec3(cells))) ? SVO_ABSENT
               : svoNeighbour(n, uvec3(pc), uvec3(q));
    around[k] = other == SVO_ABSENT ? 0u : (nodes[other].word & SVO_CHILD_MASK);
  }
}

// The value of child-level cell m (clamped to the volume) among the children of the neighbourhood.
vec4 childValue(uint around[27], ivec3 pc, ivec3 m, int childCells) {
  m = clamp(m, ivec3(0), ivec3(childCells - 1));
  ivec3 o = (m >> 1) - pc + 1;
  uint f = around[o.x + 3 * o.y + 9 * o.z];
  ivec3 bit = m & 1;
  return f == 0u ? vec4(0.0) : values[f + uint(bit.x + 2 * bit.y + 4 * bit.z)];
}

// The brick of tagged node n above the voxels: 1 + the tile its children were given, whose
// number is n's rank among the tagged nodes (svo-build allocates tiles in that order).
uint innerBrick(uint n) { return 1u + ((nodes[n].word & SVO_CHILD_MASK) - 1u) / 8u; }

// Origin of brick b of direction d in the directional pool.
ivec3 directionalOrigin(uint b, int d) {
  return 3 * ivec3(svoBrickCoords(b, uvec2(u_directionalPerAxis.xy))) + ivec3(0, 0, 3 * u_directionalPerAxis.z * d);
}

// The border means of a node-centred brick, in place: nb holds the centre values of the node's
// 3x3x3 same-level cells and becomes the brick's 27 texels. The mean over the cells sharing a
// texel's point is separable: per axis texel 0 is the mean of cells -1 and 0, texel 1 cell 0,
// texel 2 the mean of cells 0 and +1. Filtering x, then y, then z adds every pair in the order of
// increasing position, so two bricks sharing a texel compute it with the same operations
// (identical values, test I7).
void borderMeans(inout vec4 nb[27]) {
  for (int j = 0; j < 9; ++j) {
    vec4 lo = nb[3 * j], mid = nb[3 * j + 1], hi = nb[3 * j + 2];
    nb[3 * j] = 0.5 * (lo + mid);
    nb[3 * j + 2] = 0.5 * (mid + hi);
  }
  for (int j = 0; j < 9; ++j) {
    int base = (j % 3) + 9 * (j / 3);
    vec4 lo = nb[base], mid = nb[base + 3], hi = nb[base + 6];
    nb[base] = 0.5 * (lo + mid);
    nb[base + 6] = 0.5 * (mid + hi);
  }
  for (int j = 0; j < 9; ++j) {
    vec4 lo = nb[j], mid = nb[j + 9], hi = nb[j + 18];
    nb[j] = 0.5 * (lo + mid);
    nb[j + 18] = 0.5 * (mid + hi);
  }
}

// The tile of child-level cell m's children (clamped to the volume; 0xffffffff: the cell has no
// node or no children, its directional values are 0).
uint childTile(uint around[27], ivec3 pc, ivec3 m, int childCells) {
  m = clamp(m, ivec3(0), ivec3(childCells - 1));
  ivec3 o = (m >> 1) - pc + 1;
  uint f = around[o.x + 3 * o.y + 9 * o.z];
  if (f == 0u) return SVO_ABSENT;
  ivec3 bit = m & 1;
  uint grandchild = nodes[f + uint(bit.x + 2 * bit.y + 4 * bit.z)].word & SVO_CHILD_MASK;
  return grandchild == 0u ? SVO_ABSENT : (grandchild - 1u) / 8u;
}

// The directional bricks of brick b (and with the fronts rule its solid-opacity brick), from
// the tiles of the node's 3x3x3 same-level cells.
void directionalBricks(uint b, uint tiles[27]) {
  for (int d = 0; d < (kFronts == 1 ? 7 : 6); ++d) {
    vec4 nb[27];
    for (int j = 0; j < 27; ++j)
      nb[j] = tiles[j] == SVO_ABSENT ? vec4(0.0) : directional[SVO_DIRECTIONAL_RECORD * tiles[j] + uint(d)];
    borderMeans(nb);
    if (d < 6) scaleBrick(nb, b, uint(1 + d));
    if (d == 6) {
      ivec3 origin = directionalOrigin(b, 0);
      for (int t = 0; t < 27; ++t) imageStore(u_opacityPool, origin + ivec3(t % 3, (t / 3) % 3, t / 9), nb[t]);
      continue;
    }
    ivec3 origin = directionalOrigin(b, d);
    for (int t = 0; t < 27; ++t) imageStore(u_directionalPool, origin + ivec3(t % 3, (t / 3) % 3, t / 9), nb[t]);
  }
}

// Layout T, pass 1: node n's own tile brick.
void tileBrick(uint n) {
  if (!hasBrick(n)) { brickIndex[n] = 0u; return; }
  uint brick = innerBrick(n);
  if (brick >= u_brickCapacity) {
    atomicMax(counters[SVO_COUNTER_OVERFLOW], 1u);
    brickIndex[n] = 0u;
    return;
  }
  brickIndex[n] = brick;
  int level = int(nodes[n].level);
  ivec3 pc = ivec3(unpackVoxel10(nodes[n].coords));
  uint around[27];
  neighbourhoodChildren(n, pc, level, around);
  int childCells = 2 << level;
  vec4 cellValue[64];  // child-level cells 2 pc - 1 .. 2 pc + 2 per axis
  for (int j = 0; j < 64; ++j)
    cellValue[j] = childValue(around, pc, 2 * pc - 1 + ivec3(j % 4, (j / 4) % 4, j / 16), childCells);
  // With the Gaussian kernel only the finest bricks hold corner means; pass 2 fills the others.
  if (kGaussian == 1 && level < u_depth - 1) return;
  ivec3 origin = brickOrigin(brick);
  for (int t = 0; t < 27; ++t) {
    ivec3 tx = ivec3(t % 3, (t / 3) % 3, t / 9);
    vec4 sum = vec4(0.0);
    for (int z = 0; z < 2; ++z)
      for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 2; ++x) sum += cellValue[(tx.x + x) + 4 * (tx.y + y) + 16 * (tx.z + z)];
    imageStore(u_brickPool, origin + tx, sum / 8.0);
  }
}

// Pass 2 (Layout T, Gaussian), one level per dispatch from D - 2 up to 0: texel t of a level-l
// brick is the level-(l+1) vertex value at p = 2 cell + t, the sum over o in {-1, 0, 1}^3 of
// w(o) V(2p + o) with w = 1/2 per axis for o = 0 and 1/4 for o = +-1 (1/8 centre, 1/16 face, 1/32
// edge, 1/64 corner) of the level-(l+2) vertex values V, read from the level-(l+1) bricks (the
// first of the nodes sharing the point that has a brick; none: 0) and clamped to the volume.
vec4 vertexValue(uint around[27], ivec3 pc, ivec3 r, int childCells) {
  r = clamp(r, ivec3(0), ivec3(2 * childCells));
  for (int k = 0; k < 8; ++k) {
    ivec3 alt = ivec3(k & 1, (k >> 1) & 1, k >> 2);
    // An even coordinate lies on a face between two cells: its texel 0 in one, texel 2 in the other.
    bvec3 moved = greaterThan(alt, ivec3(0)), odd = notEqual(r & 1, ivec3(0));
    if ((moved.x && odd.x) || (moved.y && odd.y) || (moved.z && odd.z)) continue;
    ivec3 m = clamp((r >> 1) - alt, ivec3(0), ivec3(childCells - 1));
    ivec3 t = r - 2 * m;
    if (any(lessThan(t, ivec3(0))) || any(greaterThan(t, ivec3(2)))) continue;
    ivec3 o = (m >> 1) - pc + 1;
    uint f = around[o.x + 3 * o.y + 9 * o.z];
    if (f == 0u) continue;
    ivec3 bit = m & 1;
    uint b = brickIndex[f + uint(bit.x + 2 * bit.y + 4 * bit.z)];
    if (b == 0u) continue;
    return texelFetch(u_poolRead, brickOrigin(b) + t, 0);
  }
  return vec4(0.0);
}

void gaussianBrick(uint n) {
  if (int(nodes[n].level) != u_level) return;
  uint brick = brickIndex[n];
  if (brick == 0u) return;
  ivec3 pc = ivec3(unpackVoxel10(nodes[n].coords));
  uint around[27];
  neighbourhoodChildren(n, pc, u_level, around);
  int childCells = 2 << u_level;
  ivec3 origin = brickOrigin(brick);
  for (int t = 0; t < 27; ++t) {
    ivec3 tx = ivec3(t % 3, (t / 3) % 3, t / 9);
    ivec3 p = 2 * pc + tx;
    vec4 sum = vec4(0.0);
    for (int k = 0; k < 27; ++k) {
      ivec3 o = ivec3(k % 3, (k / 3) % 3, k / 9) - 1;
      float w = (o.x == 0 ? 0.5 : 0.25) * (o.y == 0 ? 0.5 : 0.25) * (o.z == 0 ? 0.5 : 0.25);
      sum += w * vertexValue(around, pc, 2 * p + o, childCells);
    }
    imageStore(u_brickPool, origin + tx, sum);
  }
}

void main() {
  uint n = u_firstNode + linearInvocation();
  if (n >= u_nodeEnd) return;
  if (kPass == 2) {
    gaussianBrick(n);
    return;
  }
  bool tagged = hasBrick(n);
  if (kLayoutTile == 1) {
    tileBrick(n);
    return;
  }
  // Pass 1 runs per tile: invocation n fills the bricks of node n's 8 children (and, for n = 0,
  // the root's). The children's 3x3x3 neighbourhoods lie among the children of the parent's own
  // 3x3x3 neighbourhood, so 26 neighbour lookups per tile replace 26 per node.
#if SVO_VOXEL_TILES == 0
  if (n == 0u) {
    if (tagged) {
      brickIndex[0] = 1u;  // the root is the first tagged node: rank 0
      ivec3 origin = brickOrigin(1u);
      if (1u >= u_brickCapacity) { atomicMax(counters[SVO_COUNTER_OVERFLOW], 1u); brickIndex[0] = 0u; }
      else {
        vec4 root[27];
        for (int t = 0; t < 27; ++t) root[t] = values[0];
        scaleBrick(root, 1u, 0u);
        for (int t = 0; t < 27; ++t) imageStore(u_brickPool, origin + ivec3(t % 3, (t / 3) % 3, t / 9), root[t]);
        if (kAnisotropic == 1 && u_depth > 0) {
          // The root's cells beyond the volume are clamped to the root itself: tile 0 everywhere.
          uint rootTiles[27];
          for (int j = 0; j < 27; ++j) rootTiles[j] = 0u;
          directionalBricks(1u, rootTiles);
        }
      }
    } else {
      brickIndex[0] = 0u;
    }
  }
#endif
  uint first = nodes[n].word & SVO_CHILD_MASK;
  if (first == 0u) return;
  int parentLevel = int(nodes[n].level);
  ivec3 pc = ivec3(unpackVoxel10(nodes[n].coords));
  int parentCells = 1 << parentLevel;
  uint around[27];  // first child of each node in the parent's 3x3x3 neighbourhood (0 = none)
  neighbourhoodChildren(n, pc, parentLevel, around);
  int cells = 2 * parentCells;
  // Voxel-level children: the rank of the first among the tagged voxels; the others follow.
  const bool voxels = SVO_VOXEL_TILES == 1;
  uint rank = 0u;
  if (voxels) {
    uint group = (first - u_leafStart) / 64u;
    rank = groups[group];
    for (uint m = u_leafStart + group * 64u; m < first; ++m)
      if ((nodes[m].word & SVO_TAG) != 0u) ++rank;
  }
  for (uint k = 0u; k < 8u; ++k) {
    uint child = first + k;
    if ((nodes[child].word & SVO_TAG) == 0u) { brickIndex[child] = 0u; continue; }
    uint brick = voxels ? 1u + u_tiles + rank : innerBrick(child);
    ++rank;
    if (brick >= u_brickCapacity) {
      atomicMax(counters[SVO_COUNTER_OVERFLOW], 1u);
      brickIndex[child] = 0u;
      continue;
    }
    brickIndex[child] = brick;
    ivec3 c = 2 * pc + ivec3(k & 1u, (k >> 1) & 1u, (k >> 2) & 1u);
    vec4 nb[27];  // centre values of the child's 3x3x3 same-level cells (clamped to the volume)
    for (int j = 0; j < 27; ++j) nb[j] = childValue(around, pc, c + ivec3(j % 3, (j / 3) % 3, j / 9) - 1, cells);
    borderMeans(nb);
    scaleBrick(nb, brick, 0u);
    ivec3 origin = brickOrigin(brick);
    for (int t = 0; t < 27; ++t) imageStore(u_brickPool, origin + ivec3(t % 3, (t / 3) % 3, t / 9), nb[t]);
    if (kAnisotropic == 1 && !voxels) {
      uint tiles[27];
      for (int j = 0; j < 27; ++j) tiles[j] = childTile(around, pc, c + ivec3(j % 3, (j / 3) % 3, j / 9) - 1, cells);
      directionalBricks(brick, tiles);
    }
  }
}
