#version 450
// One LRSM level for all layers (tiles side by side): u_reduce = 0 copies the base (level 0),
// else the box mean of the 2x2 children at u_sourceLevel (a block never straddles two tiles).
// The coverage sum of tile texel x adds every layer's alpha (the fp16 radiance .a) at the written level.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D u_srcRadiance;
layout(binding = 1) uniform sampler2D u_srcNormal;
layout(binding = 2) uniform sampler2D u_srcMoments;
layout(rgba16f, binding = 0) uniform writeonly image2D u_radiance;
layout(rgba16f, binding = 1) uniform writeonly image2D u_normal;
layout(rgba16, binding = 2) uniform writeonly image2D u_moments;
layout(r16f, binding = 3) uniform writeonly image2D u_coverageSum;
uniform int u_reduce, u_sourceLevel, u_layers, u_tileWidth;

vec4 fetchMean(sampler2D s, ivec2 p) {
  if (u_reduce == 0) return texelFetch(s, p, 0);
  vec4 sum = vec4(0.0);
  for (int i = 0; i < 4; ++i) sum += texelFetch(s, 2 * p + ivec2(i & 1, i >> 1), u_sourceLevel);
  return 0.25 * sum;
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= u_layers * u_tileWidth || p.y >= u_tileWidth) return;
  imageStore(u_radiance, p, fetchMean(u_srcRadiance, p));
  imageStore(u_normal, p, fetchMean(u_srcNormal, p));
  imageStore(u_moments, p, fetchMean(u_srcMoments, p));
  if (p.x < u_tileWidth) {
    float sum = 0.0;
    for (int l = 0; l < u_layers; ++l) sum += fetchMean(u_srcRadiance, ivec2(p.x + l * u_tileWidth, p.y)).a;
    imageStore(u_coverageSum, p, vec4(sum));
  }
}
