#version 450
// Reflective shadow map (src/techniques/common/rsm_stage.h): what the light sees and reflects.
#include "common/material.glsl"
#include "common/lights.glsl"
in VertexData { vec3 worldPos; vec3 normal; vec2 uv; } fin;
layout(location = 0) out vec4 outPosition;
layout(location = 1) out vec4 outNormal;
layout(location = 2) out vec4 outRadiance;
layout(location = 3) out vec4 outFlux;
const float PI = 3.14159265358979;

void main() {
  vec3 toLight; float dist;
  lightDirection(fin.worldPos, toLight, dist);
  // Surfaces reflect on both sides (as in the reference path tracer): use the lit side.
  vec3 n = normalize(fin.normal);
  if (dot(n, toLight) < 0.0) n = -n;
  vec3 dx = dFdx(fin.worldPos), dy = dFdy(fin.worldPos);
  float footprint = max(length(dx), length(dy));
  float area = length(cross(dx, dy));
  vec3 irradiance = lightIrradiance(fin.worldPos) * max(dot(n, toLight), 0.0);
  vec3 albedo = materialAlbedo(fin.uv).rgb;
  outPosition = vec4(fin.worldPos, max(footprint, 1e-8));
  outNormal = vec4(n, 1.0);
  outRadiance = vec4(albedo / PI * irradiance, 1.0);
  outFlux = vec4(albedo * irradiance * area, 1.0);
}
