#version 450
// Bilateral upsampling to the G-buffer's resolution. Marched pixel q carries the ray of G-buffer
// pixel q * scale, so full-resolution pixel p lies at p / scale in marched pixels: bilinear
// weights of the (up to) four marched pixels around it, times the depth weight of their surface
// against p's. When every weight vanishes (p's surface is on none of them), the marched pixel
// whose surface distance is closest to p's is taken: values never cross a depth edge by more
// than the one pixel between two marched samples.
#include "volumetric/screen_distance.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 1) uniform sampler2D u_position;
layout(binding = 2) uniform sampler2D u_low;   // rgb radiance, a transmittance
layout(rgba32f, binding = 0) uniform writeonly image2D u_radiance;
layout(r32f, binding = 1) uniform writeonly image2D u_transmittance;
uniform int u_scale;
uniform vec3 u_cameraPos;
uniform float u_depthSigma;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 fullSize = textureSize(u_position, 0);
  if (p.x >= fullSize.x || p.y >= fullSize.y) return;
  ivec2 lowSize = textureSize(u_low, 0);
  vec4 v;
  if (u_scale == 1) {
    v = texelFetch(u_low, p, 0);
  } else {
    float dp = surfaceDistance(u_position, p, u_cameraPos);
    vec2 f = vec2(p) / float(u_scale);
    ivec2 base = ivec2(floor(f));
    vec2 w = f - vec2(base);
    vec4 sum = vec4(0.0), best = vec4(0.0);
    float total = 0.0, bestGap = 1e30;
    for (int i = 0; i < 4; ++i) {
      ivec2 o = ivec2(i & 1, i >> 1);
      ivec2 q = min(base + o, lowSize - 1);
      float bilinear = (o.x == 1 ? w.x : 1.0 - w.x) * (o.y == 1 ? w.y : 1.0 - w.y);
      if (bilinear == 0.0) continue;
      float dq = surfaceDistance(u_position, min(q * u_scale, fullSize - 1), u_cameraPos);
      vec4 value = texelFetch(u_low, q, 0);
      float weight = bilinear * depthWeight(dp, dq, u_depthSigma);
      sum += weight * value;
      total += weight;
      float gap = (dp < 0.0) != (dq < 0.0) ? 1e20 : abs(dq - dp);
      if (gap < bestGap) { bestGap = gap; best = value; }
    }
    v = total > 1e-6 ? sum / total : best;
  }
  imageStore(u_radiance, p, vec4(v.rgb, 1.0));
  imageStore(u_transmittance, p, vec4(v.a));
}
