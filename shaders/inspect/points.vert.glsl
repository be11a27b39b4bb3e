#version 450
// Buffer records as points (one per instance record, drawn as GL_POINTS).
#include "inspect/instances.glsl"
uniform mat4 u_viewProj;
uniform float u_pointSize;
out vec3 v_color;
void main() {
  ViewInstance inst = u_instances[gl_VertexID];
  v_color = inst.color.rgb;
  gl_PointSize = u_pointSize;
  gl_Position = u_viewProj * vec4(inst.positionSize.xyz, 1.0);
}
