#version 450
// Depth-only pass (shadow maps): the rasterizer writes depth; alphaMode MASK fragments that are
// cut away leave none (the sun shines through the gaps of leaves and chains).
#include "common/material.glsl"
in VertexData { vec3 worldPos; vec3 normal; vec2 uv; } fin;
void main() {
  if (materialCutAway(fin.uv)) discard;
}
