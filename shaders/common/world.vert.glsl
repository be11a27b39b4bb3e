#version 450
// Passes world-space attributes through (voxelization projects in the geometry shader).
#include "common/scene_vertex.glsl"
out VertexData { vec3 worldPos; vec3 normal; vec2 uv; } vout;
void main() {
  vout.worldPos = a_position;
  vout.normal = a_normal;
  vout.uv = a_uv;
  gl_Position = vec4(a_position, 1.0);
}
