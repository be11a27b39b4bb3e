#version 450
// svo-leaves. Pass 0, one invocation per voxel fragment: light the fragment with vct-grid's
// inject code (common/fragment_light.glsl: Lambert, the shadow map read inject.shadow-offset voxels
// off the voxel centre along the fragment's normal, plus emission; or one uniform radiance),
// clamped to what the bricks hold (u_maxRadiance: 1 with voxel.format=rgba8, 64 with rgba16f), and
// add it to its leaf's fixed-point sums with atomicAdd (exact and order-independent: no RGBA8
// compare-and-swap average, whose counter wraps and whose truncation biases the mean, source
// error P8; the same 1/4096 steps as vct-grid's exact sums). Each fragment also ORs its normal's
// facing code (common/facing.glsl) into its leaf's: the directional bricks show a leaf only to the
// directions that see its surfaces' fronts (mipmap.fronts, svo/mipmap.comp.glsl). Pass 1, one
// invocation per leaf node: mean = sums / count, opacity 1.
#include "common/shared.h"
#include "common/voxel_space.glsl"
#include "common/packing.glsl"
#include "common/lights.glsl"
#include "common/fragment_light.glsl"
#include "common/facing.glsl"
#include "svo/svo_shared.h"

layout(local_size_x = 64) in;
// common/invocation.glsl reads gl_WorkGroupSize, so it comes after the layout line.
#include "common/invocation.glsl"
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(std430, binding = SVO_BINDING_NODES) readonly buffer Nodes { SvoNode nodes[]; };
layout(std430, binding = SVO_BINDING_LEAF_SUMS) coherent buffer LeafSums { uvec4 sums[]; };
layout(std430, binding = SVO_BINDING_VALUES) writeonly buffer Values { vec4 values[]; };
layout(std430, binding = SVO_BINDING_LEAF_FACING) coherent buffer LeafFacing { uint facing[]; };
layout(binding = 2) uniform sampler2D u_shadowMap;
uniform uint u_fragmentCount;
uniform uint u_start;  // the leaf level's nodes (pass 1)
uniform uint u_count;
uniform int u_depth;
// The pass, fixed per program (svo/stages.cpp builds one per pass): as a uniform, the leaves' pass
// also ran the fragments' lighting, masked, in every invocation.
#ifndef SVO_LEAVES_PASS
#error "svo/leaves.comp.glsl needs SVO_LEAVES_PASS (svo/stages.cpp)"
#endif
const int kPass = SVO_LEAVES_PASS;
uniform float u_maxRadiance;
// Radiance units per integer step, as vct-grid's exact sums: up to 16384 fragments of radiance 64
// per leaf fit in 32 bits.
const float kFixedPoint = 4096.0;
#include "svo/octree.glsl"

void main() {
  uint i = linearInvocation();
  if (kPass == 1) {
    if (i >= u_count) return;
    uvec4 s = sums[u_start + i];
    values[u_start + i] = s.w == 0u ? vec4(0.0) : vec4(vec3(s.xyz) / (kFixedPoint * float(s.w)), 1.0);
    return;
  }
  if (i >= u_fragmentCount) return;
  VoxelFragment f = fragments[i];
  uvec3 voxel = unpackVoxel10(f.position);
  uint leaf = svoFind(voxel, u_depth);
  if (leaf == SVO_ABSENT) return;
  vec3 radiance = fragmentRadiance(f, u_shadowMap);
  uvec3 fixedPoint = uvec3(clamp(radiance, 0.0, u_maxRadiance) * kFixedPoint + 0.5);
  atomicOr(facing[leaf], facingCode(normalize(unpackSnorm4x8(f.normal).xyz)));
  atomicAdd(sums[leaf].x, fixedPoint.x);
  atomicAdd(sums[leaf].y, fixedPoint.y);
  atomicAdd(sums[leaf].z, fixedPoint.z);
  atomicAdd(sums[leaf].w, 1u);
}
