#version 450
// svo-mipmap, one level per dispatch, one invocation per node of level u_level: a node with
// children gets the box filter of their centre values, (1/8) sum (absent or empty children count
// 0): the same average as vct-grid's isotropic mipmap.comp.glsl, so level l of the octree holds
// mip D - l of the dense grid.
#include "svo/svo_shared.h"

layout(local_size_x = 64) in;
// common/invocation.glsl reads gl_WorkGroupSize, so it comes after the layout line.
#include "common/invocation.glsl"
layout(std430, binding = SVO_BINDING_NODES) readonly buffer Nodes { SvoNode nodes[]; };
layout(std430, binding = SVO_BINDING_VALUES) buffer Values { vec4 values[]; };
uniform uint u_start;
uniform uint u_count;

void main() {
  uint i = linearInvocation();
  if (i >= u_count) return;
  uint n = u_start + i;
  uint first = nodes[n].word & SVO_CHILD_MASK;
  if (first == 0u) return;
  vec4 sum = vec4(0.0);
  for (uint k = 0u; k < 8u; ++k) sum += values[first + k];
  values[n] = sum * 0.125;
}
