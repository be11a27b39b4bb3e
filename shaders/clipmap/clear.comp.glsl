#version 450
// Clears the accumulators of one box of cells of one level (the cells a move voxelizes anew),
// counting them: nothing outside the planner's boxes is touched.
#include "clipmap/clipmap.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
// The accumulators as uvec4: a cell's u_cellWords (4 or 32) start at a multiple of 4 words, so a
// cell is cleared in u_cellWords / 4 stores.
layout(std430, binding = CLIPMAP_BINDING_ACCUM) buffer Accumulators { uvec4 accum4[]; };
layout(std430, binding = CLIPMAP_BINDING_COUNTERS) buffer Counters { uint counters[]; };  // per level: cleared, pairs, resolved, filtered, guards
uniform ivec3 u_boxLo;
uniform ivec3 u_boxSize;
uniform int u_level;
uniform ivec3 u_skipLo;  // cells of [u_skipLo, u_skipHi) are left alone (a full build's covered block)
uniform ivec3 u_skipHi;

void main() {
  ivec3 g = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(g, u_boxSize))) return;
  ivec3 cell = u_boxLo + g;
  if (all(greaterThanEqual(cell, u_skipLo)) && all(lessThan(cell, u_skipHi))) return;
  uint i = accumulatorIndex(u_level, toroidalAddress(cell));
  for (uint w = 0u; w < u_cellWords / 4u; ++w) accum4[i / 4u + w] = uvec4(0u);
  atomicAdd(counters[5 * u_level + 0], 1u);
}
