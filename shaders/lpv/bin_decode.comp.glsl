#version 450
// Decoded colour of every cell of an LPV voxel grid (alpha = occupied), for display.
#include "lpv/encoding.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(std430, binding = LPV_BINDING_VOXELS) readonly buffer Voxels { LpvVoxel voxels[]; };
layout(rgba8, binding = 0) uniform writeonly image3D u_colour;
void main() {
  ivec3 c = ivec3(gl_GlobalInvocationID);
  if (!cellInside(c)) return;
  uint m = voxels[cellIndex(c)].colorOcclusion;
  imageStore(u_colour, c, decodeOccupied(m) ? vec4(decodeColor(m), 1.0) : vec4(0.0));
}
