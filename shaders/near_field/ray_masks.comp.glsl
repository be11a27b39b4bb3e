#version 450
// Ray-mask table (seed 000 Listing 4.40, GP3 CreateVoxelRays.frag): texel (i, j) = XOR[i] ^ XOR[j + 1],
// slices i..j when i <= j. The XOR table has 129 entries with XOR[128] = 0, so row j = 127 reads
// a real texel (the public code fetches texel 128 of a 128-texel texture there).
layout(local_size_x = 8, local_size_y = 8) in;
layout(rgba32ui, binding = 0) uniform readonly uimage2D u_xorTable;  // 129 x 1
layout(rgba32ui, binding = 1) uniform writeonly uimage2D u_rayMasks; // 128 x 128
layout(r32ui, binding = 2) uniform writeonly uimage2D u_popcount;    // 128 x 128

void main() {
  ivec2 ij = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(ij, ivec2(128)))) return;
  uvec4 m = imageLoad(u_xorTable, ivec2(ij.x, 0)) ^ imageLoad(u_xorTable, ivec2(ij.y + 1, 0));
  imageStore(u_rayMasks, ij, m);
  ivec4 n = bitCount(m);
  imageStore(u_popcount, ij, uvec4(uint(n.x + n.y + n.z + n.w)));
}
