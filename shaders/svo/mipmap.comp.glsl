#version 450
// svo-mipmap, one level per dispatch, one invocation per node of level u_level: a node with
// children gets the box filter of their centre values, (1/8) sum (absent or empty children count
// 0): the same average as vct-grid's isotropic mipmap.comp.glsl, so level l of the octree holds
// mip D - l of the dense grid. With u_anisotropic = 1 it also gets its six directional values
// (common/anisotropic_mip.glsl, as vct-grid's anisotropic mips): from its children's centre values
// where they are voxels, else from their own directional values; vct-grid builds its directional
// level 1 from the voxels and every higher level from the level below in the same way.
// With u_fronts = 1 (mipmap.fronts, the default, vct-grid's rule) a voxel shows its radiance only
// to the directions that see its surfaces' fronts, with their coverage as alpha (facingLeaf of its
// facing code, common/facing.glsl), and each node also keeps its solid opacity per axis (the
// voxels as opaque cubes, composited the same way: record 6), which ambient occlusion and shadows
// read; u_fronts = 0 is Crassin's classic rule, every voxel seen from all sides. One record serves
// both directions of an axis: opacity alone composited front to back, a0 + (1 - a0) a1 =
// 1 - (1 - a0)(1 - a1), does not depend on which child is in front (kept: +x, +y, +z's order).
#include "svo/svo_shared.h"

layout(local_size_x = 64) in;
// common/invocation.glsl reads gl_WorkGroupSize, so it comes after the layout line.
#include "common/invocation.glsl"
#include "common/anisotropic_mip.glsl"
#include "common/facing.glsl"
layout(std430, binding = SVO_BINDING_NODES) readonly buffer Nodes { SvoNode nodes[]; };
layout(std430, binding = SVO_BINDING_VALUES) buffer Values { vec4 values[]; };
layout(std430, binding = SVO_BINDING_DIRECTIONAL_VALUES) buffer Directional { vec4 directional[]; };
layout(std430, binding = SVO_BINDING_LEAF_FACING) readonly buffer LeafFacing { uint facing[]; };
uniform uint u_start;
uniform uint u_count;
uniform int u_anisotropic;
uniform int u_fronts;              // 1: the voxels show their fronts only, solid opacity kept apart
// SVO_CHILDREN_ARE_VOXELS 1: the level below is the voxel level (isotropic leaves). A define, two
// programs: llvmpipe runs both sides of a branch on a uniform, and the level above the voxels,
// which holds most of the nodes, then also paid for the gather of directional values.
#ifndef SVO_CHILDREN_ARE_VOXELS
#error "svo/mipmap.comp.glsl needs SVO_CHILDREN_ARE_VOXELS (svo/stages.cpp)"
#endif

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
  uint grandTile[8];  // the tiles of the children's own children (SVO_ABSENT: none)
  for (uint k = 0u; k < 8u; ++k) {
    uint grandchild = SVO_CHILDREN_ARE_VOXELS == 1 ? 0u : nodes[first + k].word & SVO_CHILD_MASK;
    grandTile[k] = grandchild == 0u ? SVO_ABSENT : tileOf(grandchild);
  }
  vec3 solidAxes = vec3(0.0);
  for (int d = 0; d < 6; ++d) {
    vec4 children[8], solid[8];
    for (uint k = 0u; k < 8u; ++k) {
      if (SVO_CHILDREN_ARE_VOXELS == 1) {
        vec4 voxel = values[first + k];
        children[k] = u_fronts == 1 ? facingLeaf(voxel, facing[first + k], d) : voxel;
        solid[k] = vec4(voxel.a);
      } else if (grandTile[k] == SVO_ABSENT) {
        children[k] = solid[k] = vec4(0.0);
      } else {
        uint record = SVO_DIRECTIONAL_RECORD * grandTile[k];
        children[k] = directional[record + uint(d)];
        solid[k] = vec4(directional[record + 6u][d >> 1]);
      }
    }
    directional[SVO_DIRECTIONAL_RECORD * tile + uint(d)] = anisotropicReduce(children, d);
    if (u_fronts == 0 || (d & 1) == 1) continue;
    solidAxes[d >> 1] = anisotropicReduce(solid, d).a;
  }
  directional[SVO_DIRECTIONAL_RECORD * tile + 6u] = vec4(solidAxes, 1.0);
}
