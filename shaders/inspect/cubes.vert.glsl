#version 450
// Instanced unit cubes, 36 vertices generated from gl_VertexID (no vertex buffer). color.a holds
// a bit mask of the faces to draw (bit axis * 2 + side); the others are moved outside the clip volume.
#include "inspect/instances.glsl"
uniform mat4 u_viewProj;
out CubeData { flat vec3 color; flat int axis; vec3 local; } vout;
void main() {
  ViewInstance inst = u_instances[gl_InstanceID];
  int face = gl_VertexID / 6, corner = gl_VertexID % 6;
  // Two triangles per face: corners (0,0) (1,0) (1,1) (0,0) (1,1) (0,1) in the face's plane.
  const vec2 quad[6] = vec2[6](vec2(0, 0), vec2(1, 0), vec2(1, 1), vec2(0, 0), vec2(1, 1), vec2(0, 1));
  int axis = face >> 1;
  float side = float(face & 1);
  vec2 q = quad[corner];
  vec3 p = axis == 0 ? vec3(side, q.x, q.y) : axis == 1 ? vec3(q.y, side, q.x) : vec3(q.x, q.y, side);
  vout.color = inst.color.rgb;
  if ((int(inst.color.a) & (1 << face)) == 0) {
    vout.axis = axis;
    vout.local = vec3(0.0);
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    return;
  }
  vout.axis = axis;
  vout.local = p;
  gl_Position = u_viewProj * vec4(inst.positionSize.xyz + p * inst.positionSize.w, 1.0);
}
