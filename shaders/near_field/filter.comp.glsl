#version 450
// One pass of the geometry-aware filter of the near-field indirect light (the "filter and combine"
// step of seed 000 section 4.4; GP3 filters with a radius and a distance limit): an a-trous pass
// of the 5-tap B3 spline (1/16, 1/4, 3/8, 1/4, 1/16) in x and y with holes of u_step traced pixels,
// each tap weighted by how well its surface agrees with the centre's (distance to the centre's
// plane, normal agreement), normalised by the weights. Averaging only, so it moves no energy
// across surfaces and keeps a flat region's mean.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 1) uniform sampler2D u_position;
layout(binding = 2) uniform sampler2D u_normal;
layout(binding = 3) uniform sampler2D u_source;  // traced resolution
layout(rgba32f, binding = 0) uniform writeonly image2D u_target;
uniform int u_step, u_traceScale;
uniform float u_planeDistance;

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
      ivec2 q = px + ivec2(i, j) * u_step;
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
      ivec2 g = min(q * u_traceScale, gsize - 1);
      vec4 qp = texelFetch(u_position, g, 0);
      if (qp.w == 0.0) continue;
      float plane = max(0.0, 1.0 - abs(dot(n, qp.xyz - p.xyz)) / u_planeDistance);
      float facing = pow(max(dot(n, texelFetch(u_normal, g, 0).xyz), 0.0), 8.0);
      float w = k[i + 2] * k[j + 2] * plane * facing;
      sum += w * texelFetch(u_source, q, 0).rgb;
      total += w;
    }
  imageStore(u_target, px, vec4(total > 0.0 ? sum / total : centre.rgb, 1.0));
}
