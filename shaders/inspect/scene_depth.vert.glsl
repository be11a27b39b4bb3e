#version 450
// The scene's triangles into depth only (the viewer's overlays hide what lies behind surfaces).
#include "common/scene_vertex.glsl"
uniform mat4 u_viewProj;
void main() { gl_Position = u_viewProj * vec4(a_position, 1.0); }
