#version 450
// The OR-table entry of the point's slice (slice k: bit 31 - (k & 31) of channel k >> 5).
flat in int vSlice;
layout(location = 0) out uvec4 outMask;
void main() {
  uvec4 m = uvec4(0u);
  m[vSlice >> 5] = 0x80000000u >> uint(vSlice & 31);
  outMask = m;
}
