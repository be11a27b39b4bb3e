#version 450
// Bilateral blur of the marched image along one axis (run twice: x, then y). Kernel taps
// -r..r with weight 1, the two end taps 1/2: for an even radius every residue of the pixel index
// mod 4 gets the same total weight, so along both passes each of the 16 Bayer offsets of a 4x4
// tile weighs the same and the blurred dither averages to a 16N-interval Riemann sum where the
// depth does not change (volumetric.cpp, Details). Weights also fall off with depth difference.
#include "volumetric/screen_distance.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 1) uniform sampler2D u_position;   // full-resolution G-buffer
layout(binding = 2) uniform sampler2D u_radiance;   // rgb: in-scattered radiance (a: transmittance when u_packed)
layout(binding = 3) uniform sampler2D u_transmittanceIn;
layout(rgba32f, binding = 0) uniform writeonly image2D u_out;   // rgb radiance, a transmittance
layout(r32f, binding = 1) uniform writeonly image2D u_outTransmittance;
uniform ivec2 u_axis;
uniform int u_radius;
uniform int u_packed;         // 1: transmittance is u_radiance.a (second pass)
uniform int u_scale;
uniform vec3 u_cameraPos;
uniform float u_depthSigma;

vec4 fetch(ivec2 q) {
  vec4 v = texelFetch(u_radiance, q, 0);
  if (u_packed == 0) v.a = texelFetch(u_transmittanceIn, q, 0).r;
  return v;
}

void main() {
  ivec2 q = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = textureSize(u_radiance, 0);
  if (q.x >= size.x || q.y >= size.y) return;
  ivec2 fullSize = textureSize(u_position, 0);
  float dp = surfaceDistance(u_position, min(q * u_scale, fullSize - 1), u_cameraPos);
  vec4 sum = vec4(0.0);
  float total = 0.0;
  for (int k = -u_radius; k <= u_radius; ++k) {
    ivec2 s = q + k * u_axis;
    if (any(lessThan(s, ivec2(0))) || any(greaterThanEqual(s, size))) continue;
    float w = (abs(k) == u_radius && u_radius > 0) ? 0.5 : 1.0;
    w *= depthWeight(dp, surfaceDistance(u_position, min(s * u_scale, fullSize - 1), u_cameraPos), u_depthSigma);
    sum += w * fetch(s);
    total += w;
  }
  vec4 v = total > 0.0 ? sum / total : fetch(q);
  imageStore(u_out, q, v);
  imageStore(u_outTransmittance, q, vec4(v.a));
}
