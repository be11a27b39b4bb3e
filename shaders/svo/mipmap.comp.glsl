#version 450
// svo-mipmap, one level per dispatch, one invocation per node of level u_level: a node with
// children gets the box filter of their centre values, (1/8) sum (absent or empty children count
// 0): the same average as vct-grid's isotropic mipmap.comp.glsl, so level l of the octree holds
// mip D - l of the dense grid. With u_anisotropic = 1 it also gets its six directional values
// (common/anisotropic_mip.glsl, as vct-grid's anisotropic mips): from its children's centre values
// where they are voxels, else from their own directional values; vct-grid builds its directional
// level 1 from the voxels and every higher level from the level below in the same way.
#include "svo/svo_shared.h"

layout(local_size_x = 64) in;
// common/invocation.glsl reads gl_WorkGroupSize, so it comes after the layout line.
#include "common/invocation.glsl"
#include "common/anisotropic_mip.glsl"
layout(std430, binding = SVO_BINDING_NODES) readonly buffer Nodes { SvoNode nodes[]; };
layout(std430, binding = SVO_BINDING_VALUES) buffer Values { vec4 values[]; };
layout(std430, binding = SVO_BINDING_DIRECTIONAL_VALUES) buffer Directional { vec4 directional[]; };
uniform uint u_start;
uniform uint u_count;
uniform int u_anisotropic;
uniform int u_childrenAreVoxels;  // 1: the level below is the voxel level (isotropic leaves)

uint tileOf(uint first) { return (first - 1u) / 8u; }

void main() {
  uint i = linearInvocation();
  if (i >= u_count) return;
  uint n = u_start + i;
  uint first = nodes[n].word & SVO_CHILD_MASK;
  if (first == 0u) return;
  vec4 sum = vec4(0.0);
  for (uint k = 0u; k < 8u; ++k) sum += values[first + k];
  values[n] = sum * 0.125;
  if (u_anisotropic == 0) return;
  uint tile = tileOf(first);
  for (int d = 0; d < 6; ++d) {
    vec4 children[8];
    for (uint k = 0u; k < 8u; ++k) {
      if (u_childrenAreVoxels == 1) {
        children[k] = values[first + k];
      } else {
        uint grandchild = nodes[first + k].word & SVO_CHILD_MASK;
        children[k] = grandchild == 0u ? vec4(0.0) : directional[6u * tileOf(grandchild) + uint(d)];
      }
    }
    directional[6u * tile + uint(d)] = anisotropicReduce(children, d);
  }
}
