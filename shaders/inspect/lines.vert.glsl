#version 450
// Line segments: consecutive instance records are a segment's two ends (positionSize.xyz, color).
#include "inspect/instances.glsl"
uniform mat4 u_viewProj;
out vec3 v_color;
void main() {
  ViewInstance inst = u_instances[gl_VertexID];
  v_color = inst.color.rgb;
  gl_Position = u_viewProj * vec4(inst.positionSize.xyz, 1.0);
}
