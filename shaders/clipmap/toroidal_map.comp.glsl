#version 450
// Test shader: for every logical offset j in [0, N)^3 of level u_level's region, the physical
// texel of cell o + j as this library's shaders address it (written x + N (y + N z)).
#include "clipmap/clipmap.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(std430, binding = 0) writeonly buffer Map { uint map[]; };
uniform int u_level;

void main() {
  ivec3 j = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(j, ivec3(u_clipN)))) return;
  ivec3 phys = toroidalAddress(u_clipOrigin[u_level] + j);
  uint n = uint(u_clipN);
  map[(uint(j.z) * n + uint(j.y)) * n + uint(j.x)] = (uint(phys.z) * n + uint(phys.y)) * n + uint(phys.x);
}
