#version 450
// Density grid, part 2: the scattering coefficient of the particles, sigma_s = k * count (1/m),
// as a float volume the ray march samples with trilinear filtering (clamped to a zero border,
// so nothing scatters outside the grid).
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(binding = 0) uniform usampler3D u_counts;
layout(r32f, binding = 0) uniform writeonly image3D u_scattering;
uniform float u_scatteringPerParticle;
uniform int u_resolution;
void main() {
  ivec3 v = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(v, ivec3(u_resolution)))) return;
  imageStore(u_scattering, v, vec4(u_scatteringPerParticle * float(texelFetch(u_counts, v, 0).r)));
}
