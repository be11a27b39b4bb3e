#version 450
// Bins voxel fragments into one cascade's cells (seed 000 section 4.3.1, from the fragment list
// instead of a second rasterization): colour word and normal masks by atomicMax, a fragment count
// and the surface area the cell holds (each fragment's share of its voxel, fragmentAreaUnits) by
// atomicAdd; all are order independent, so the grid does not depend on thread timing.
// Fragments outside the grid are counted (stage statistics) and dropped.
#include "common/shared.h"
#include "common/voxel_space.glsl"
#include "common/packing.glsl"
#include "lpv/encoding.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(std430, binding = LPV_BINDING_VOXELS) buffer Voxels { LpvVoxel voxels[]; };
layout(std430, binding = LPV_BINDING_SCRATCH) buffer Outside { uint outside[]; };
layout(std430, binding = LPV_BINDING_VOXEL_FRAGMENTS) readonly buffer Counts { uint counts[]; };
uniform uint u_fragmentCount;
uniform float u_areaUnits;
uniform int u_cascade;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_fragmentCount) return;
  VoxelFragment f = fragments[i];
  uvec3 voxel = unpackVoxel10(f.position);
  precise vec3 p = u_volumeOrigin + (vec3(voxel) + 0.5) * u_voxelSize;
  precise vec3 u = (p - u_gridOrigin) / u_cellSize;
  ivec3 c = ivec3(floor(u));
  if (!cellInside(c)) { atomicAdd(outside[u_cascade], 1u); return; }
  int idx = cellIndex(c);
  uvec3 rgb8 = uvec3(f.albedo & 255u, (f.albedo >> 8) & 255u, (f.albedo >> 16) & 255u);
  atomicMax(voxels[idx].colorOcclusion, encodeColorOcclusion(rgb8));
  atomicAdd(voxels[idx].fragmentCount, 1u);
  ivec3 k = snormComponents(f.normal);
  uint sharing = counts[(voxel.z * uint(u_resolution) + voxel.y) * uint(u_resolution) + voxel.x];
  atomicAdd(voxels[idx].area, fragmentAreaUnits(k, sharing, u_areaUnits));
  uint dotField;
  int channel = tetraChannel(k, dotField);
  atomicMax(voxels[idx].normals[channel], encodeNormalMask(k, dotField));
}
