#version 450
// One pass of the edge-aware a-trous wavelet filter (Dammertz, Sewtz, Hanika, Lensch, "Edge-Avoiding
// A-Trous Wavelet Transform for fast Global Illumination Filtering", HPG 2010), shared by the
// techniques that trace a few rays per pixel (src/techniques/common/atrous_filter_stage.h): the
// 5-tap B3 spline (1/16, 1/4, 3/8, 1/4, 1/16) in x and y with holes of u_hole traced pixels, each
// tap weighted by the edge-stopping functions
//   depth:  exp(-(n . (q - p) / depthScale)^2)   (distance off the centre's plane, along its normal)
//   normal: exp(-|n - n_q|^2 / normalSigma^2)
// and normalised by the weights. Averaging only, so a flat region keeps its mean. No colour term:
// with a few rays per pixel the noise is as large as the edges it would keep.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 1) uniform sampler2D u_position;  // G-buffer: xyz, w = 0 where no surface
layout(binding = 2) uniform sampler2D u_normal;
layout(binding = 3) uniform sampler2D u_source;    // traced resolution
layout(rgba32f, binding = 0) uniform writeonly image2D u_target;
uniform int u_hole, u_traceScale;
uniform float u_depthScale, u_normalSigma;

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = textureSize(u_source, 0);
  if (any(greaterThanEqual(px, size))) return;
  ivec2 gsize = textureSize(u_position, 0);
  vec4 p = texelFetch(u_position, min(px * u_traceScale, gsize - 1), 0);
  vec4 centre = texelFetch(u_source, px, 0);
  if (p.w == 0.0) { imageStore(u_target, px, centre); return; }
  vec3 n = texelFetch(u_normal, min(px * u_traceScale, gsize - 1), 0).xyz;
  const float k[5] = float[5](0.0625, 0.25, 0.375, 0.25, 0.0625);
  vec3 sum = vec3(0.0);
  float total = 0.0;
  for (int j = -2; j <= 2; ++j)
    for (int i = -2; i <= 2; ++i) {
      ivec2 q = px + ivec2(i, j) * u_hole;
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
      ivec2 g = min(q * u_traceScale, gsize - 1);
      vec4 qp = texelFetch(u_position, g, 0);
      if (qp.w == 0.0) continue;
      float depth = dot(n, qp.xyz - p.xyz) / u_depthScale;
      vec3 dn = n - texelFetch(u_normal, g, 0).xyz;
      float w = k[i + 2] * k[j + 2] * exp(-depth * depth) * exp(-dot(dn, dn) / (u_normalSigma * u_normalSigma));
      sum += w * texelFetch(u_source, q, 0).rgb;
      total += w;
    }
  imageStore(u_target, px, vec4(total > 0.0 ? sum / total : centre.rgb, 1.0));
}
