#version 450
// One isotropic occlusion level: the mean of the 8 children (an explicit reduction, not
// glGenerateMipmap, whose filter is implementation-defined).
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(binding = 0) uniform sampler3D u_source;
layout(r8, binding = 0) uniform writeonly image3D u_level;
uniform int u_sourceLevel;
uniform ivec3 u_size;

void main() {
  ivec3 v = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(v, u_size))) return;
  float sum = 0.0;
  for (int i = 0; i < 8; ++i) sum += texelFetch(u_source, 2 * v + ivec3(i & 1, (i >> 1) & 1, i >> 2), u_sourceLevel).r;
  imageStore(u_level, v, vec4(sum / 8.0));
}
