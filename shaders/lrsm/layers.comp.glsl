#version 450
// Layer assignment and warp (src/techniques/lrsm/lrsm.h): one invocation per 2x2 RSM block.
// Each texel gets layer depthInterval * (b + 1) + normalInterval; the texels of a layer are
// merged into the block's texel of that layer's tile, premultiplied by alpha = count / 4.
#include "common/shared.h"
#include "common/lights.glsl"
#include "lrsm/lrsm_shared.h"
#include "lrsm/lrsm_common.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D u_rsmPosition;
layout(binding = 1) uniform sampler2D u_rsmNormal;
layout(binding = 2) uniform sampler2D u_rsmRadiance;
layout(rgba32f, binding = 0) uniform writeonly image2D u_depth;
layout(r8ui, binding = 1) uniform writeonly uimage2D u_layerId;
layout(rgba16f, binding = 2) uniform writeonly image2D u_radiance;
layout(rgba16f, binding = 3) uniform writeonly image2D u_normal;
layout(rgba16, binding = 4) uniform writeonly image2D u_moments;
uniform int u_layerWidth;

void main() {
  ivec2 block = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(block, ivec2(u_layerWidth)))) return;
  int ids[4];
  vec3 rad[4], nor[4];
  float zw[4];
  for (int i = 0; i < 4; ++i) {
    ivec2 t = 2 * block + ivec2(i & 1, i >> 1);
    vec4 n = texelFetch(u_rsmNormal, t, 0);
    ids[i] = -1;
    if (n.w < 0.5) {
      imageStore(u_depth, t, vec4(0.0));
      imageStore(u_layerId, t, uvec4(LRSM_EMPTY_LAYER));
      continue;
    }
    vec3 p = texelFetch(u_rsmPosition, t, 0).xyz;
    vec3 toLight; float dist;
    lightDirection(p, toLight, dist);
    float z = lightDepth(p);
    float ndotl = max(dot(n.xyz, toLight), 0.0);
    int d = depthIntervalOf(z);
    ids[i] = d * u_normalIntervals + normalIntervalOf(ndotl);
    float lo, hi;
    layerRange(d, lo, hi);
    zw[i] = clamp((z - lo) / max(hi - lo, 1e-20), 0.0, 1.0);
    rad[i] = texelFetch(u_rsmRadiance, t, 0).rgb;
    nor[i] = n.xyz;
    imageStore(u_depth, t, vec4(z, ndotl, zw[i], 0.0));
    imageStore(u_layerId, t, uvec4(ids[i]));
  }
  int layers = u_depthIntervals * u_normalIntervals;
  for (int l = 0; l < layers; ++l) {
    vec4 r = vec4(0.0), n = vec4(0.0), m = vec4(0.0);
    for (int i = 0; i < 4; ++i) {
      if (ids[i] != l) continue;
      r += vec4(rad[i], 1.0);
      n += vec4(nor[i], 1.0);
      float z2 = zw[i] * zw[i];
      m += vec4(zw[i], z2, z2 * zw[i], z2 * z2);
    }
    ivec2 a = ivec2(l * u_layerWidth + block.x, block.y);
    imageStore(u_radiance, a, 0.25 * r);
    imageStore(u_normal, a, 0.25 * n);
    imageStore(u_moments, a, 0.25 * m);
  }
}
