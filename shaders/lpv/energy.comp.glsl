#version 450
// Flux of a cascade's grids (sum of c00 * 2 sqrt(pi) per channel) for the per-step energy record,
// in two passes with a fixed summation order (deterministic): u_pass 0, one invocation per row of
// cells, sums the row into u_partials; u_pass 1, one invocation, sums the rows in order.
#include "common/sh.glsl"
#include "lpv/lpv_shared.h"
layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = LPV_BINDING_ENERGY) buffer Energy { LpvEnergy energy[]; };
layout(std430, binding = LPV_BINDING_PROBE) buffer Partials { vec4 partials[]; };  // 2 per row: light, wave
layout(binding = 0) uniform sampler3D u_light[3];
layout(binding = 3) uniform sampler3D u_wave[3];
uniform int u_gridRes;
uniform int u_pass;
uniform int u_step;
uniform int u_record;
uniform int u_cascade;
void main() {
  if (u_pass == 0) {
    ivec2 row = ivec2(gl_GlobalInvocationID.xy);  // (y, z)
    if (row.x >= u_gridRes || row.y >= u_gridRes) return;
    vec3 l = vec3(0.0), w = vec3(0.0);
    for (int x = 0; x < u_gridRes; ++x) {
      ivec3 c = ivec3(x, row);
      l += vec3(texelFetch(u_light[0], c, 0).x, texelFetch(u_light[1], c, 0).x, texelFetch(u_light[2], c, 0).x);
      w += vec3(texelFetch(u_wave[0], c, 0).x, texelFetch(u_wave[1], c, 0).x, texelFetch(u_wave[2], c, 0).x);
    }
    int r = row.y * u_gridRes + row.x;
    partials[2 * r] = vec4(l, 0.0);
    partials[2 * r + 1] = vec4(w, 0.0);
    return;
  }
  if (gl_GlobalInvocationID.x != 0u || gl_GlobalInvocationID.y != 0u) return;
  vec3 l = vec3(0.0), w = vec3(0.0);
  for (int r = 0; r < u_gridRes * u_gridRes; ++r) {
    l += partials[2 * r].xyz;
    w += partials[2 * r + 1].xyz;
  }
  energy[u_record].wavefront = vec4(w * SH_FLUX_PER_C00, float(u_step));
  energy[u_record].total = vec4(l * SH_FLUX_PER_C00, float(u_cascade));
}
