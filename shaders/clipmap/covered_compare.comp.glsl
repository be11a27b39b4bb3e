#version 450
// Direct versus filtered content of covered cells, in logical order (levels along y, as
// clip-logical): u_direct gets the cell's own voxelization Direct_k (resolved from the
// accumulators this stage filled for the covered blocks), u_difference |Direct_k - F| against the
// filtered value the atlas holds: what a cell shows when it leaves the covered block (popping).
// Cells of level 0 and uncovered cells are 0 in both.
#include "clipmap/clipmap.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(std430, binding = CLIPMAP_BINDING_ACCUM) readonly buffer Accumulators { uint accum[]; };
layout(std430, binding = CLIPMAP_BINDING_COUNTERS) buffer Counters { uint counters[]; };
layout(CLIPMAP_ATLAS_FORMAT, binding = 0) uniform readonly image3D u_atlas;
layout(CLIPMAP_ATLAS_FORMAT, binding = 1) uniform writeonly image3D u_direct;
layout(CLIPMAP_ATLAS_FORMAT, binding = 2) uniform writeonly image3D u_difference;
uniform ivec3 u_coveredLo[CLIPMAP_MAX_LEVELS];
uniform ivec3 u_coveredHi[CLIPMAP_MAX_LEVELS];

void main() {
  ivec3 g = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(g, imageSize(u_direct)))) return;
  int k = g.y / u_clipN;
  ivec3 cell = u_clipOrigin[k] + ivec3(g.x, g.y % u_clipN, g.z);
  vec4 direct = vec4(0.0), difference = vec4(0.0);
  if (k > 0 && all(greaterThanEqual(cell, u_coveredLo[k])) && all(lessThan(cell, u_coveredHi[k]))) {
    ivec3 phys = toroidalAddress(cell);
    uint i = accumulatorIndex(k, phys);
    uint count = accum[i];
    if (count > 0u) direct = vec4(vec3(uvec3(accum[i + 1u], accum[i + 2u], accum[i + 3u]) / count) / u_fixedScale, 1.0);
    difference = abs(direct - imageLoad(u_atlas, atlasTexel(0, k, phys)));
  }
  imageStore(u_direct, g, direct);
  imageStore(u_difference, g, difference);
}
