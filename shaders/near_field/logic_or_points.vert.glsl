#version 450
// Test kernel (tests/unit/test_near_field.cpp): the thesis' voxelization path, points rendered
// into an RGBA32UI target with the logic op OR. Point i sits at texel u_texel[i] and carries slice
// u_slice[i] (no vertex buffer: gl_VertexID picks it).
uniform ivec2 u_texel[8];
uniform int u_slice[8];
uniform ivec2 u_size;
flat out int vSlice;
void main() {
  vSlice = u_slice[gl_VertexID];
  gl_Position = vec4((vec2(u_texel[gl_VertexID]) + 0.5) / vec2(u_size) * 2.0 - 1.0, 0.0, 1.0);
  gl_PointSize = 1.0;
}
