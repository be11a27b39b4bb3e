#version 450
// Camera-facing discs (sphere impostors): 6 vertices per instance, centre and radius from the
// instance record, expanded in view space so each disc has its sphere's true projected size.
#include "inspect/instances.glsl"
uniform mat4 u_view;
uniform mat4 u_projection;
out SphereData { vec2 uv; flat vec4 color; } vout;
void main() {
  ViewInstance inst = u_instances[gl_InstanceID];
  const vec2 quad[6] = vec2[6](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, -1), vec2(1, 1), vec2(-1, 1));
  vec2 c = quad[gl_VertexID];
  vec4 centre = u_view * vec4(inst.positionSize.xyz, 1.0);
  vout.uv = c;
  vout.color = inst.color;
  gl_Position = u_projection * vec4(centre.xy + c * inst.positionSize.w, centre.z, 1.0);
}
