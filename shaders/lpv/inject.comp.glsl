#version 450
// Injection, one invocation per cell (seed 000 section 4.3.2, Listings 4.30/4.31, with the
// physical flux of K&D): an occupied cell is lit with the shadow-mapped light through the stored
// normal that faces the light most; its reflected flux Phi = albedo * E * A (A = fragments *
// fragment voxel^2, the surface in the cell) becomes a VPL of intensity (Phi / pi) max(0, n.w),
// i.e. SH (Phi / pi) lobe(n) per colour channel. In point-VPL mode only u_vplCell holds lobe(n),
// a VPL of flux pi per channel.
#include "common/shared.h"
#include "common/lights.glsl"
#include "common/sh.glsl"
#include "lpv/encoding.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(std430, binding = LPV_BINDING_VOXELS) readonly buffer Voxels { LpvVoxel voxels[]; };
layout(binding = 2) uniform sampler2D u_shadowMap;
layout(rgba32f, binding = 0) uniform writeonly image3D u_vpl[3];
uniform float u_fragmentArea;
uniform int u_pointVpl;
uniform ivec3 u_vplCell;
uniform vec3 u_vplNormal;
const float PI = 3.14159265358979;

void main() {
  ivec3 c = ivec3(gl_GlobalInvocationID);
  if (!cellInside(c)) return;
  vec4 sh[3] = vec4[3](vec4(0.0), vec4(0.0), vec4(0.0));
  if (u_pointVpl == 1) {
    if (c == u_vplCell) sh[0] = sh[1] = sh[2] = shLobe(u_vplNormal);
  } else {
    LpvVoxel v = voxels[cellIndex(c)];
    if (decodeOccupied(v.colorOcclusion)) {
      vec3 p = u_gridOrigin + (vec3(c) + 0.5) * u_cellSize;
      vec3 toLight; float dist;
      lightDirection(p, toLight, dist);
      vec3 n = vec3(0.0);
      float best = -2.0;
      for (int k = 0; k < 4; ++k) {
        if (v.normals[k] == 0u) continue;  // an empty channel decodes to the zero vector: not a normal
        vec3 m = normalize(decodeNormalMask(v.normals[k]));
        float d = dot(m, toLight);
        if (d > best) { best = d; n = m; }
      }
      if (best > 0.0) {
        // The cell centre can lie up to half a cell behind the surface: test the shadow map half a
        // cell along the normal instead (pitfall 14 of the technical note).
        float visibility = shadowVisibility(u_shadowMap, p + n * (0.5 * u_cellSize), n);
        vec3 irradiance = lightIrradiance(p) * best * visibility;
        vec3 flux = decodeColor(v.colorOcclusion) * irradiance * (float(v.fragmentCount) * u_fragmentArea);
        for (int ch = 0; ch < 3; ++ch) sh[ch] = (flux[ch] / PI) * shLobe(n);
      }
    }
  }
  for (int ch = 0; ch < 3; ++ch) imageStore(u_vpl[ch], c, sh[ch]);
}
