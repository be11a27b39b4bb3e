#version 450
// G-buffer: world position, normal (facing the camera), albedo and emission of the visible surface.
#include "common/material.glsl"
in VertexData { vec3 worldPos; vec3 normal; vec2 uv; } fin;
layout(location = 0) out vec4 outPosition;
layout(location = 1) out vec4 outNormal;
layout(location = 2) out vec4 outAlbedo;
layout(location = 3) out vec4 outEmission;
uniform vec3 u_cameraPos;
void main() {
  if (materialCutAway(fin.uv)) discard;  // alphaMode MASK
  vec3 n = normalize(fin.normal);
  if (dot(n, u_cameraPos - fin.worldPos) < 0.0) n = -n;
  outPosition = vec4(fin.worldPos, 1.0);
  outNormal = vec4(n, 1.0);
  outAlbedo = vec4(materialAlbedo(fin.uv).rgb, 1.0);
  outEmission = vec4(materialEmission(fin.uv), 1.0);
}
