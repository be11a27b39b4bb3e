// The set-up every cone-tracing stage shares (included by the cone_trace.comp.glsl of vct-grid, svo
// and clipmap): the cone table,
// apertures and distances as uniforms, set by setConeUniforms() in
// src/techniques/common/cone_setup.cpp (for all three) from the cone.* / ao.range /
// specular.roughness / shadow.cone-aperture / probe.* parameters, whose defaults each technique
// gives (ConeDefaults); the G-buffer point a traced pixel shades; the tangent frame the cone table
// is given in (z = the normal). The step uniforms (u_stepScale, u_lodBias, u_maxSteps) belong to
// the tracer (common/cone_trace.glsl declares them for vct-grid).
#ifndef VOXLAB_CONE_SETUP_GLSL
#define VOXLAB_CONE_SETUP_GLSL
#include "common/shared.h"

layout(binding = 1) uniform sampler2D u_position;
layout(binding = 2) uniform sampler2D u_normal;
layout(binding = 3) uniform sampler2D u_albedo;

uniform int u_coneCount;
uniform vec4 u_cones[VOXLAB_MAX_CONES];  // xyz: direction in tangent space (z = normal), w: weight
uniform float u_diffuseAperture;         // radians
uniform float u_specularAperture;        // radians
uniform float u_shadowAperture;          // radians
uniform float u_startOffset;             // metres, along the normal
uniform float u_maxDistance;             // metres
uniform float u_aoRange;                 // metres
uniform vec3 u_cameraPos;
uniform ivec2 u_probePixel;              // pixel (of the traced image) whose samples are recorded
uniform int u_scale;                     // 1: one cone set per G-buffer pixel; 2: per 2x2 block

// The surface a traced pixel shades: at half resolution the top-left G-buffer pixel of its 2x2
// block (composite upsamples along surfaces). 'valid' is false where the G-buffer holds no surface.
struct ConeSurface {
  bool valid;
  vec3 position;
  vec3 normal;   // unit
  vec3 albedo;
  vec3 origin;   // where the cones start: u_startOffset along the normal
};
ConeSurface coneSurface(ivec2 px) {
  ivec2 g = min(px * u_scale, textureSize(u_position, 0) - 1);
  vec4 pos = texelFetch(u_position, g, 0);
  ConeSurface s;
  s.valid = pos.w != 0.0;
  s.position = pos.xyz;
  s.normal = s.valid ? normalize(texelFetch(u_normal, g, 0).xyz) : vec3(0.0, 0.0, 1.0);
  s.albedo = texelFetch(u_albedo, g, 0).rgb;
  s.origin = s.position + s.normal * u_startOffset;
  return s;
}

// The tangent frame (t, b, n) of the cone table.
void coneFrame(vec3 n, out vec3 t, out vec3 b) {
  t = normalize(abs(n.y) < 0.9 ? cross(n, vec3(0, 1, 0)) : cross(n, vec3(1, 0, 0)));
  b = cross(n, t);
}
// A cone of the table (tangent-space direction in xyz) as a world direction.
vec3 coneAxis(vec4 cone, vec3 t, vec3 b, vec3 n) { return normalize(cone.x * t + cone.y * b + cone.z * n); }
#endif
