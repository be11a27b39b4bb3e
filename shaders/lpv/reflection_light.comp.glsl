#version 450
// Reflection grid, level 0, part 2 (Listing 4.34): each occupied voxel's outgoing radiance from
// the fine cascade's light, L0 only (the direction is ignored, as in the thesis): albedo / pi *
// c00 * sqrt(pi) / 2 * scale / cell^2, alpha 1. The texture coordinate is the voxel centre
// (+0.5 on every axis; Listing 4.34's +0.0 in z is a port error of a 2D-array version).
#include "common/sh.glsl"
#include "lpv/encoding.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(r32ui, binding = 0) uniform readonly uimage3D u_colour;
layout(rgba16f, binding = 1) uniform writeonly image3D u_target;
layout(binding = 0) uniform sampler3D u_light[3];  // fine cascade r, g, b
uniform vec3 u_fineOrigin;
uniform float u_fineCell;
uniform float u_fineRes;
uniform float u_radianceScale;
const float PI = 3.14159265358979;
void main() {
  ivec3 c = ivec3(gl_GlobalInvocationID);
  if (!cellInside(c)) return;
  uint m = imageLoad(u_colour, c).r;
  vec4 outV = vec4(0.0);
  if (decodeOccupied(m)) {
    vec3 p = u_gridOrigin + (vec3(c) + 0.5) * u_cellSize;
    vec3 uvw = (p - u_fineOrigin) / (u_fineCell * u_fineRes);
    vec3 e;
    for (int ch = 0; ch < 3; ++ch) e[ch] = max(0.0, texture(u_light[ch], uvw).x * SH_LOBE0);
    outV = vec4(decodeColor(m) / PI * e * (u_radianceScale / (u_fineCell * u_fineCell)), 1.0);
  }
  imageStore(u_target, c, outV);
}
