#version 450
// Reflection grid, level 0, part 1 (seed 000 section 4.3.4): the voxel fragments binned into a
// finer grid with the fine cascade's footprint, colour/contrast/occupancy by atomicMax as in the
// LPV grids (Listing 4.27), no normals.
#include "common/shared.h"
#include "common/voxel_space.glsl"
#include "common/packing.glsl"
#include "lpv/encoding.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(r32ui, binding = 0) uniform uimage3D u_colour;
uniform uint u_fragmentCount;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_fragmentCount) return;
  VoxelFragment f = fragments[i];
  precise vec3 p = u_volumeOrigin + (vec3(unpackVoxel10(f.position)) + 0.5) * u_voxelSize;
  precise vec3 u = (p - u_gridOrigin) / u_cellSize;
  ivec3 c = ivec3(floor(u));
  if (!cellInside(c)) return;
  uvec3 rgb8 = uvec3(f.albedo & 255u, (f.albedo >> 8) & 255u, (f.albedo >> 16) & 255u);
  imageAtomicMax(u_colour, c, encodeColorOcclusion(rgb8));
}
