#version 450
// Projects the scene with u_viewProj; passes world-space attributes on.
#include "common/scene_vertex.glsl"
uniform mat4 u_viewProj;
out VertexData { vec3 worldPos; vec3 normal; vec2 uv; } vout;
void main() {
  vout.worldPos = a_position;
  vout.normal = a_normal;
  vout.uv = a_uv;
  gl_Position = u_viewProj * vec4(a_position, 1.0);
}
