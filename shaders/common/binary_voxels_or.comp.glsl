#version 450
// One invocation per voxel fragment: OR the fragment's slice bits into the four 32-bit words of
// its column (word c of column (x, y) at texel (4x + c, y)). Bit order: see
// src/techniques/common/binary_voxels_stage.h (slice k = bit 31 - (k & 31) of word k >> 5).
#include "common/shared.h"
#include "common/packing.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(r32ui, binding = 0) uniform coherent uimage2D u_words;
uniform int u_resolution;
uniform uint u_fragmentCount;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_fragmentCount) return;
  uvec3 v = unpackVoxel10(fragments[i].position);
  if (any(greaterThanEqual(v, uvec3(u_resolution)))) return;
  int first, last;
  if (u_resolution <= 128) {
    first = int(v.z) * (128 / u_resolution);
    last = first + 128 / u_resolution - 1;
  } else {
    first = last = int(v.z) / (u_resolution / 128);
  }
  for (int k = first; k <= last; ++k)
    imageAtomicOr(u_words, ivec2(4 * int(v.x) + (k >> 5), int(v.y)), 0x80000000u >> uint(k & 31));
}
