#version 450
// Packs the four words of each column into one RGBA32UI texel and counts its set slices.
layout(local_size_x = 8, local_size_y = 8) in;
layout(r32ui, binding = 0) uniform readonly uimage2D u_words;
layout(rgba32ui, binding = 1) uniform writeonly uimage2D u_columns;
layout(r32ui, binding = 2) uniform writeonly uimage2D u_popcount;
uniform int u_resolution;

void main() {
  ivec2 c = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(c, ivec2(u_resolution)))) return;
  uvec4 m;
  for (int w = 0; w < 4; ++w) m[w] = imageLoad(u_words, ivec2(4 * c.x + w, c.y)).r;
  imageStore(u_columns, c, m);
  ivec4 n = bitCount(m);
  imageStore(u_popcount, c, uvec4(uint(n.x + n.y + n.z + n.w)));
}
