// What every clipmap shader shares: the levels' integer origins, toroidal addresses and the
// atlas layout (src/techniques/clipmap/stages.h). Level k holds the world cells
// [o_k, o_k + N)^3 of edge s_k = s_0 2^k; cell c lives at physical texel c & (N-1), whatever
// the origin, so a move rewrites only the cells it exposes. The atlas packs blocks of
// (N+2)^3 texels: face f along x, level k along y, a one-texel guard on every side of each
// block holding the wrapped neighbour (guard -1 = physical N-1, guard N = physical 0), so
// trilinear filtering across the physical seam reads the right texels.
#define CLIPMAP_MAX_LEVELS 8
#define CLIPMAP_BINDING_ACCUM 12     // SSBO: u_cellWords uints per cell and level (see accumulatorIndex)
#define CLIPMAP_BINDING_COUNTERS 13  // SSBO: uint[5] per level: cleared, pairs, resolved, filtered, guards
#define CLIPMAP_BINDING_FILL 14      // SSBO: uint per cell of one level, what fill.comp.glsl writes there
#define CLIPMAP_BINDING_FILLED 15    // SSBO: uint per physical texel of the finer level, 1 where filled
uniform int u_clipN;                                   // N, a power of two
uniform int u_clipLevels;                              // L
uniform ivec3 u_clipOrigin[CLIPMAP_MAX_LEVELS];        // o_k, level-k cells

ivec3 toroidalAddress(ivec3 cell) { return cell & ivec3(u_clipN - 1); }

// Atlas texel of physical texel 'phys' (guards: -1 and N) of level 'level', face 'face'.
ivec3 atlasTexel(int face, int level, ivec3 phys) {
  int b = u_clipN + 2;
  return ivec3(face * b + 1 + phys.x, level * b + 1 + phys.y, 1 + phys.z);
}

bool insideRegion(ivec3 cell, int level) {
  ivec3 o = u_clipOrigin[level];
  return all(greaterThanEqual(cell, o)) && all(lessThan(cell, o + ivec3(u_clipN)));
}

// Words per cell of the accumulators: 4 with one face (fragments, red, green, blue); 32 with six
// faces, which add at word 4 the OR of the fragments' facing codes (common/facing.glsl) and at
// words 8 + 4 d, per travel direction d of a cone (+x -x +y -y +z -z), the fronts that direction
// sees: the sum of the fragments' front weights in fifths, then red, green, blue weighted by them.
uniform uint u_cellWords;
const uint kClipFacingWord = 4u;
uint clipDirectionWord(int d) { return 8u + 4u * uint(d); }

// Levels with accumulators of their own: 1 where the levels take turns (the update stage clears,
// voxelizes and resolves one level before the next), L where one pass fills every level's
// (covered-compare).
uniform int u_accumulatorLevels;

// Index of a cell's accumulator (u_cellWords uints) by its level and physical address.
uint accumulatorIndex(int level, ivec3 phys) {
  uint n = uint(u_clipN);
  uint slot = uint(level % u_accumulatorLevels);
  return u_cellWords * (((slot * n + uint(phys.z)) * n + uint(phys.y)) * n + uint(phys.x));
}

// Fixed-point scale of the accumulated radiance: integer sums are order-independent, so a cell
// built in a slab gets the bits it gets in a full build. u_fixedScale = 2^b with b =
// clipmap.fixed-point-bits (default 14); each fragment adds its light times 2^b to a 32-bit sum,
// so a cell's sum overflows when its fragments' light adds up to 2^(32 - b) (4 W/(m^2 sr) per
// fragment over 4,096 fragments at b = 14); the voxelizer counts the additions that wrap it
// (addLight), the stages report them.
// Radiance a fragment may add: 1 with the RGBA8 atlas, 64 with RGBA16F (clipmap.format).
uniform float u_fixedScale;
uniform float u_maxRadiance;

// The image format of the atlas and of the textures copied from it (mips, the unrolled levels):
// rgba8 unless the stage builds the program with "#define CLIPMAP_ATLAS_FORMAT rgba16f" (the
// stages do by default: atlasFormatDefines).
#ifndef CLIPMAP_ATLAS_FORMAT
#define CLIPMAP_ATLAS_FORMAT rgba8
#endif
