#version 450
// The per-node passes of one level [u_start, u_start + u_count) of svo-build, a program per pass
// (SVO_LEVEL_PASS; as a uniform, every pass also ran the dilation's neighbour walks, masked):
//  pass 0 (dilate):   every non-empty node tags its 26 same-level neighbours (svo.dilate=1), so
//                       the level below also holds the empty cells next to occupied ones;
//  pass 1 (count):    count the level's non-empty and tagged nodes (sizes the next level), and
//                       the tagged nodes of each work group of 64 (the CPU turns these into
//                       exclusive prefix sums);
//  pass 2 (allocate): every tagged node takes the 2x2x2 tile whose number is its rank among the
//                       level's tagged nodes (group prefix + the tagged nodes before it in its
//                       group): a deterministic scan instead of an atomicAdd, so the pool is the
//                       same on every run and thread count (and there is no read-then-increment
//                       race, source error P9). It checks the pool's capacity first (overflow
//                       flag, nothing written past the end) and initialises its 8 children
//                       (word 0, cell 2c + offset, level + 1).
#include "common/shared.h"
#include "common/packing.glsl"
#include "svo/svo_shared.h"

layout(local_size_x = 64) in;
// common/invocation.glsl reads gl_WorkGroupSize, so it comes after the layout line.
#include "common/invocation.glsl"
layout(std430, binding = SVO_BINDING_NODES) coherent buffer Nodes { SvoNode nodes[]; };
layout(std430, binding = SVO_BINDING_COUNTERS) coherent buffer Counters { uint counters[]; };
layout(std430, binding = SVO_BINDING_GROUPS) coherent buffer Groups { uint groups[]; };  // counts, then prefixes
uniform uint u_start;
uniform uint u_count;
uniform uint u_capacity;  // nodes the pool holds
uniform uint u_tilesBefore;  // tiles allocated by the levels above
uniform int u_depth;
uniform int u_level;
#ifndef SVO_LEVEL_PASS
#error "svo/level_pass.comp.glsl needs SVO_LEVEL_PASS (svo/stages.cpp)"
#endif
const int kPass = SVO_LEVEL_PASS;
#include "svo/octree.glsl"

void main() {
  uint i = linearInvocation();
  if (i >= u_count) return;
  uint n = u_start + i;
  uint word = nodes[n].word;
  if (kPass == 0) {
    if ((word & SVO_NON_EMPTY) == 0u) return;
    ivec3 c = ivec3(unpackVoxel10(nodes[n].coords));
    int cells = 1 << u_level;
    for (int k = 0; k < 27; ++k) {
      ivec3 o = ivec3(k % 3, (k / 3) % 3, k / 9) - 1;
      ivec3 m = c + o;
      if (k == 13 || any(lessThan(m, ivec3(0))) || any(greaterThanEqual(m, ivec3(cells)))) continue;
      uint other = svoNeighbour(n, uvec3(c), uvec3(m));
      if (other != SVO_ABSENT) atomicOr(nodes[other].word, SVO_TAG);
    }
  } else if (kPass == 1) {
    if ((word & SVO_NON_EMPTY) != 0u) atomicAdd(counters[SVO_COUNTER_NON_EMPTY], 1u);
    if ((word & SVO_TAG) != 0u) {
      atomicAdd(counters[SVO_COUNTER_TAGGED], 1u);
      atomicAdd(groups[(linearInvocation() / 64u)], 1u);
    }
  } else {
    if ((word & SVO_TAG) == 0u || u_level >= u_depth) return;
    uint groupStart = u_start + (linearInvocation() / 64u) * 64u;
    uint rank = groups[(linearInvocation() / 64u)];
    for (uint m = groupStart; m < n; ++m)
      if ((nodes[m].word & SVO_TAG) != 0u) ++rank;
    uint tile = u_tilesBefore + rank;
    uint first = 1u + 8u * tile;
    if (first + 8u > u_capacity) {
      atomicMax(counters[SVO_COUNTER_OVERFLOW], 1u);
      return;
    }
    nodes[n].word = word | first;
    uvec3 c = unpackVoxel10(nodes[n].coords);
    for (uint k = 0u; k < 8u; ++k) {
      uvec3 o = uvec3(k & 1u, (k >> 1) & 1u, (k >> 2) & 1u);
      nodes[first + k] = SvoNode(0u, packVoxel10(2u * c + o), uint(u_level + 1), n);
    }
  }
}
