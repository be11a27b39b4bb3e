#version 450
// The dense view of one octree level: texel v of mip D - u_level gets the centre value of the node
// of that level at cell v (0 where the octree has no node there).
#include "svo/svo_shared.h"

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(std430, binding = SVO_BINDING_NODES) readonly buffer Nodes { SvoNode nodes[]; };
layout(std430, binding = SVO_BINDING_VALUES) readonly buffer Values { vec4 values[]; };
layout(rgba8, binding = 0) uniform writeonly image3D u_dense;
uniform int u_depth;
uniform int u_level;
#include "svo/octree.glsl"

void main() {
  ivec3 v = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(v, imageSize(u_dense)))) return;
  uint node = svoFind(uvec3(v), u_level);
  imageStore(u_dense, v, node == SVO_ABSENT ? vec4(0.0) : values[node]);
}
