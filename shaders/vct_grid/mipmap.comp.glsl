#version 450
// Isotropic mipmapping: each texel of level L is the average of its 8 children at level L-1
// (premultiplied radiance and opacity alike).
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(binding = 0) uniform sampler3D u_source;   // the same texture, read at level u_sourceLevel
layout(rgba8, binding = 0) uniform writeonly image3D u_target;
uniform int u_sourceLevel;
void main() {
  ivec3 v = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(v, imageSize(u_target)))) return;
  vec4 sum = vec4(0.0);
  for (int i = 0; i < 8; ++i)
    sum += texelFetch(u_source, 2 * v + ivec3(i & 1, (i >> 1) & 1, (i >> 2) & 1), u_sourceLevel);
  imageStore(u_target, v, sum * 0.125);
}
