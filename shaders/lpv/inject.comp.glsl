#version 450
// Injection, one invocation per cell (seed 000 section 4.3.2, Listings 4.30/4.31, with the
// physical flux of K&D): an occupied cell is lit with the shadow-mapped light through the stored
// normal that faces the light most; its reflected flux Phi = albedo * E * A (A = the surface in
// the cell, the bin stage's area word: each voxel's share of the surface, not fragments x voxel^2,
// which counts a voxel once per triangle touching it) becomes a VPL of intensity (Phi / pi) max(0, n.w),
// i.e. SH (Phi / pi) lobe(n) per colour channel. In point-VPL mode only u_vplCell holds lobe(n),
// a VPL of flux pi per channel.
// Two passes: u_pass 0 computes each cell's VPL and its normal into u_unshifted; u_pass 1 moves each
// VPL u_shift cells along its normal (K&D's half-cell shift against self-illumination) by a
// gather: a cell sums, in a fixed order, the VPLs of its 27 neighbourhood cells that land in it
// (a shift of at most one cell moves a VPL at most to a neighbour), so no atomics are needed.
#include "common/shared.h"
#include "common/lights.glsl"
#include "common/sh.glsl"
#include "lpv/encoding.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(std430, binding = LPV_BINDING_VOXELS) readonly buffer Voxels { LpvVoxel voxels[]; };
layout(binding = 2) uniform sampler2D u_shadowMap;
layout(rgba32f, binding = 0) uniform writeonly image3D u_vpl[3];
layout(std430, binding = LPV_BINDING_STATE_OUT) buffer Unshifted { vec4 u_unshifted[]; };  // per cell: r, g, b SH, normal
uniform int u_pass;
uniform float u_shift;
uniform float u_fragmentArea;
uniform float u_areaUnits;     // units of LpvVoxel.area per u_fragmentArea
uniform int u_pointVpl;
uniform ivec3 u_vplCell;
uniform vec3 u_vplNormal;
uniform int u_perFragment;     // 1: the VPL is the sum of the cell's lit fragments (inject_fragments.comp.glsl)
uniform float u_unitsPerWatt;
layout(std430, binding = LPV_BINDING_PROBE) readonly buffer FragmentSums { int fragmentSums[]; };
const float PI = 3.14159265358979;

void main() {
  ivec3 c = ivec3(gl_GlobalInvocationID);
  if (!cellInside(c)) return;
  if (u_pass == 1) {
    vec4 sum[3] = vec4[3](vec4(0.0), vec4(0.0), vec4(0.0));
    for (int k = 0; k < 27; ++k) {
      ivec3 s = c + ivec3(k % 3, (k / 3) % 3, k / 9) - 1;
      if (!cellInside(s)) continue;
      int base = 4 * cellIndex(s);
      vec3 n = u_unshifted[base + 3].xyz;
      ivec3 dest = ivec3(floor(vec3(s) + 0.5 + u_shift * n));
      if (dest != c) continue;
      for (int ch = 0; ch < 3; ++ch) sum[ch] += u_unshifted[base + ch];
    }
    for (int ch = 0; ch < 3; ++ch) imageStore(u_vpl[ch], c, sum[ch]);
    return;
  }
  vec4 sh[3] = vec4[3](vec4(0.0), vec4(0.0), vec4(0.0));
  vec3 normal = vec3(0.0);
  if (u_pointVpl == 1) {
    if (c == u_vplCell) sh[0] = sh[1] = sh[2] = shLobe(u_vplNormal);
  } else if (u_perFragment == 1) {
    int base = 12 * cellIndex(c);
    for (int ch = 0; ch < 3; ++ch)
      sh[ch] = vec4(fragmentSums[base + 4 * ch], fragmentSums[base + 4 * ch + 1], fragmentSums[base + 4 * ch + 2],
                    fragmentSums[base + 4 * ch + 3]) / u_unitsPerWatt;
    // The shift moves the sum along its band-1 direction (the mean normal of its lit fragments).
    vec4 all = sh[0] + sh[1] + sh[2];
    vec3 b = vec3(-all.w, -all.y, all.z);
    if (dot(b, b) > 0.0) normal = normalize(b);
  } else {
    LpvVoxel v = voxels[cellIndex(c)];
    if (decodeOccupied(v.colorOcclusion)) {
      vec3 p = u_gridOrigin + (vec3(c) + 0.5) * u_cellSize;
      vec3 toLight; float dist;
      lightDirection(p, toLight, dist);
      vec3 n = vec3(0.0);
      float best = -2.0;
      for (int k = 0; k < 4; ++k) {
        if (v.normals[k] == 0u) continue;  // an empty channel decodes to the zero vector: not a normal
        vec3 m = normalize(decodeNormalMask(v.normals[k]));
        float d = dot(m, toLight);
        if (d > best) { best = d; n = m; }
      }
      if (best > 0.0) {
        // The cell centre can lie up to half a cell behind the surface: test the shadow map half a
        // cell along the normal instead (pitfall 14 of the technical note).
        float visibility = shadowVisibility(u_shadowMap, p + n * (0.5 * u_cellSize), n);
        vec3 irradiance = lightIrradiance(p) * best * visibility;
        vec3 flux = decodeColor(v.colorOcclusion) * irradiance * (float(v.area) / u_areaUnits * u_fragmentArea);
        for (int ch = 0; ch < 3; ++ch) sh[ch] = (flux[ch] / PI) * shLobe(n);
        normal = n;
      }
    }
  }
  if (u_shift == 0.0 || u_perFragment == 1) {  // nothing moves here (fragments moved before binning): store directly
    for (int ch = 0; ch < 3; ++ch) imageStore(u_vpl[ch], c, sh[ch]);
    return;
  }
  int base = 4 * cellIndex(c);
  for (int ch = 0; ch < 3; ++ch) u_unshifted[base + ch] = sh[ch];
  u_unshifted[base + 3] = vec4(normal, 0.0);
}
