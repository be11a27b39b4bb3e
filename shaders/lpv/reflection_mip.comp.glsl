#version 450
// Reflection grid mip level: each texel is the mean of its 8 children (radiance and occupancy).
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(binding = 0) uniform sampler3D u_source;
layout(rgba16f, binding = 0) uniform writeonly image3D u_target;
uniform int u_sourceLevel;
void main() {
  ivec3 v = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(v, imageSize(u_target)))) return;
  vec4 sum = vec4(0.0);
  for (int i = 0; i < 8; ++i)
    sum += texelFetch(u_source, 2 * v + ivec3(i & 1, (i >> 1) & 1, (i >> 2) & 1), u_sourceLevel);
  imageStore(u_target, v, sum * 0.125);
}
