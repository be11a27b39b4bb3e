#version 450
// inject.lighting=per-fragment: the lighting of every voxel fragment, summed into its cell. Each
// fragment is lit with the shadow map at its own voxel (as vct-grid's inject), and its reflected
// flux Phi = albedo * E * A (A = the fragment's share of its voxel's surface, fragmentAreaUnits:
// the fragments of one voxel share it) becomes a VPL of its own normal,
// (Phi / pi) lobe(n), added to its cell's 12 coefficients (r, g, b x c00, c1-1, c10, c11) in fixed
// point by integer atomics, so the sums do not depend on the order of the fragments. A cell with
// surfaces in light and in shadow, or of several orientations (large cells: Sponza's fine cell is
// 1.74 m), then gets the flux of its lit fragments only, in their own directions, where the
// per-cell lighting lights every fragment of the cell through one normal and one shadow test.
// u_pass 0: the largest coefficient magnitude of any single fragment (atomicMax of the float's
// bits, order independent), from which the stage picks the fixed-point unit; u_pass 1: the sums.
#include "common/shared.h"
#include "common/voxel_space.glsl"
#include "common/packing.glsl"
#include "common/lights.glsl"
#include "common/sh.glsl"
#include "lpv/encoding.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(std430, binding = LPV_BINDING_PROBE) buffer Sums { int sums[]; };
layout(std430, binding = LPV_BINDING_SCRATCH) buffer Largest { uint largest; };
layout(std430, binding = LPV_BINDING_VOXEL_FRAGMENTS) readonly buffer Counts { uint counts[]; };
layout(binding = 2) uniform sampler2D u_shadowMap;
uniform uint u_fragmentCount;
uniform float u_fragmentArea;
uniform float u_areaUnits;
uniform float u_unitsPerWatt;  // fixed-point units per W/sr of one coefficient
uniform int u_pass;
uniform float u_shift;         // cells: each fragment's VPL moves this far along its normal before it is binned (K&D)
const float PI = 3.14159265358979;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_fragmentCount) return;
  VoxelFragment f = fragments[i];
  uvec3 voxel = unpackVoxel10(f.position);
  precise vec3 p = u_volumeOrigin + (vec3(voxel) + 0.5) * u_voxelSize;
  vec3 n = normalize(unpackSnorm4x8(f.normal).xyz);
  // K&D's shift: the fragment's VPL moves u_shift cells along its normal before it is binned.
  // Binned at the voxel centre (u_shift 0), a wall on a cell boundary (cell boundaries lie on
  // multiples of the cell size, walls often do too) puts up to half its voxels' VPLs in the cell
  // behind it, whose voxels then block the light from the second step on.
  precise vec3 u = (p - u_gridOrigin) / u_cellSize + u_shift * n;
  ivec3 c = ivec3(floor(u));
  if (!cellInside(c)) return;
  vec3 toLight; float dist;
  lightDirection(p, toLight, dist);
  float cosine = dot(n, toLight);
  if (!(cosine > 0.0)) return;
  vec3 albedo = vec3(float(f.albedo & 255u), float((f.albedo >> 8) & 255u), float((f.albedo >> 16) & 255u)) * LPV_INV255;
  uint sharing = counts[(voxel.z * uint(u_resolution) + voxel.y) * uint(u_resolution) + voxel.x];
  float area = float(fragmentAreaUnits(snormComponents(f.normal), sharing, u_areaUnits)) / u_areaUnits * u_fragmentArea;
  // The voxel centre lies up to half a voxel x |n|_1 behind the fragment's surface (the slab of
  // voxels a plane cuts): the shadow map is tested that far along the normal, or a sloped surface
  // shadows itself (pitfall 14 of the technical note; a 30 degree slope lost 39 % of its light).
  float behind = 0.5 * u_voxelSize * (abs(n.x) + abs(n.y) + abs(n.z));
  vec3 flux = albedo * lightIrradiance(p) * cosine * shadowVisibility(u_shadowMap, p + n * behind, n) * area;
  vec4 lobe = shLobe(n);
  if (u_pass == 0) {
    // |lobe coefficients| <= SH_LOBE1 (1.023 > 0.886).
    float m = max(flux.r, max(flux.g, flux.b)) / PI * SH_LOBE1;
    atomicMax(largest, floatBitsToUint(m));
    return;
  }
  int base = 12 * cellIndex(c);
  for (int ch = 0; ch < 3; ++ch)
    for (int k = 0; k < 4; ++k) atomicAdd(sums[base + 4 * ch + k], int(round(flux[ch] / PI * lobe[k] * u_unitsPerWatt)));
}
