#version 450
// The octree's structure as a volume (svo-build's "svo-structure"): texel v of mip D - u_level
// says what the node of level u_level at cell v is: 1 = non-empty, 0.6 = tagged for dilation only,
// 0.3 = an empty sibling (allocated, never subdivided), 0 = no node there.
#include "svo/svo_shared.h"

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(std430, binding = SVO_BINDING_NODES) readonly buffer Nodes { SvoNode nodes[]; };
layout(r8, binding = 0) uniform writeonly image3D u_structure;
uniform int u_depth;
uniform int u_level;
#include "svo/octree.glsl"

void main() {
  ivec3 v = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(v, imageSize(u_structure)))) return;
  uint node = svoFind(uvec3(v), u_level);
  float code = 0.0;
  if (node != SVO_ABSENT) {
    uint word = nodes[node].word;
    code = (word & SVO_NON_EMPTY) != 0u ? 1.0 : (word & SVO_TAG) != 0u ? 0.6 : 0.3;
  }
  imageStore(u_structure, v, vec4(code));
}
