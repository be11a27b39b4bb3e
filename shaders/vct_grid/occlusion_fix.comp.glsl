#version 450
// Occlusion fix: after averaging, alpha counts fragments; set it to 1 in every non-empty voxel so
// a voxel is fully opaque to cones.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(binding = 0) uniform sampler3D u_injected;
layout(rgba8, binding = 0) uniform writeonly image3D u_fixed;
void main() {
  ivec3 v = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(v, textureSize(u_injected, 0)))) return;
  vec4 c = texelFetch(u_injected, v, 0);
  imageStore(u_fixed, v, c.a > 0.0 ? vec4(c.rgb, 1.0) : vec4(0.0));
}
