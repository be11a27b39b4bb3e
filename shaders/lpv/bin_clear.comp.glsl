#version 450
// Empties an LPV voxel grid (every cell: no colour, no normals, its own coordinates for point views).
#include "lpv/encoding.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(std430, binding = LPV_BINDING_VOXELS) writeonly buffer Voxels { LpvVoxel voxels[]; };
void main() {
  ivec3 c = ivec3(gl_GlobalInvocationID);
  if (!cellInside(c)) return;
  LpvVoxel v;
  v.colorOcclusion = 0u;
  v.fragmentCount = 0u;
  v.cell = uint(c.x) | (uint(c.y) << 10) | (uint(c.z) << 20);
  v.area = 0u;
  v.normals = uvec4(0u);
  voxels[cellIndex(c)] = v;
}
