#version 450
// Light injection, one invocation per voxel fragment: Lambertian direct light from the scene's
// light (shadow-mapped), plus emission (common/fragment_light.glsl, shared with svo's leaves),
// averaged into the voxel. Two ways to average (inject.average), one program each:
//  - exact-sum (the default): each channel is added, in fixed point (1/4096 steps), to a 32-bit
//    sum of the voxel together with a count (vct_grid/voxel_sums.glsl): the first fragment to
//    reach a voxel claims it with one image compare-and-swap on u_owner, and every fragment of
//    the voxel adds to the claimer's slot with buffer atomics, which llvmpipe runs far cheaper than
//    image atomics (four image atomics per fragment into four volumes cost two thirds of this
//    pass). inject_resolve.comp.glsl divides. Integer addition does not depend on the order of the
//    fragments, so the result is exact up to the one fixed-point rounding per fragment and the same
//    on every run.
//  - compare-and-swap (program built with "#define VOXLAB_INJECT_COMPARE_AND_SWAP"): a running
//    average in the RGBA8 voxel itself, updated with a compare-and-swap loop on its r32ui view
//    (seed 000, Crassin and Green). Alpha holds how many fragments have been averaged in
//    (saturating at 255: later fragments are ignored); each update rounds to 8 bits, so the result
//    depends on the order in which fragments arrive.
// Either way the occlusion fix stage then sets alpha to 1 in every non-empty voxel.
// Every fragment also ORs its normal's facing code (common/facing.glsl) into its voxel's (the
// slot's, written out by the resolve, with exact sums; u_facing's with compare-and-swap): per
// travel direction of a cone, how much of the voxel's surfaces' fronts it sees (the anisotropic
// mips' leaves, mipmap_anisotropic.comp.glsl).
#include "common/shared.h"
#include "common/voxel_space.glsl"
#include "common/packing.glsl"
#include "common/lights.glsl"
#include "common/fragment_light.glsl"
#include "common/facing.glsl"

layout(local_size_x = 64) in;
#include "common/invocation.glsl"
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(binding = 2) uniform sampler2D u_shadowMap;  // a texture unit (image units are separate)
uniform uint u_fragmentCount;
// What a voxel can hold: 1 with RGBA8 grids (voxel.format=rgba8), kHdrMaxRadiance with RGBA16F.
uniform float u_maxRadiance;
#ifdef VOXLAB_INJECT_COMPARE_AND_SWAP
layout(r32ui, binding = 0) uniform coherent uimage3D u_radianceAtomic;  // the RGBA8 grid's r32ui view
layout(r32ui, binding = 5) uniform uimage3D u_facing;                   // facing codes, common/facing.glsl
#else
#define VOXLAB_VOXEL_SUMS_ACCESS
#include "vct_grid/voxel_sums.glsl"
layout(r32ui, binding = 1) uniform uimage3D u_owner;  // per voxel its slot (kNoOwner: unclaimed)
#endif

void main() {
  uint i = linearInvocation();
  if (i >= u_fragmentCount) return;
  VoxelFragment f = fragments[i];
  ivec3 voxel = ivec3(unpackVoxel10(f.position));
  vec3 radiance = fragmentRadiance(f, u_shadowMap);
  radiance = clamp(radiance, 0.0, u_maxRadiance);
  uint facing = facingCode(normalize(unpackSnorm4x8(f.normal).xyz));

#ifndef VOXLAB_INJECT_COMPARE_AND_SWAP
  uint claimed = imageAtomicCompSwap(u_owner, voxel, kNoOwner, i);
  uint slot = claimed == kNoOwner ? i : claimed;
  if (claimed == kNoOwner) claimedSlots[atomicAdd(claimedVoxels, 1u)] = i;
  uvec3 fixedPoint = uvec3(radiance * kFixedPointScale + 0.5);
  atomicAdd(slots[slot].red, fixedPoint.r);
  atomicAdd(slots[slot].green, fixedPoint.g);
  atomicAdd(slots[slot].blue, fixedPoint.b);
  atomicAdd(slots[slot].count, 1u);
  atomicOr(slots[slot].facing, facing);
#else
  imageAtomicOr(u_facing, voxel, facing);
  uint expected = 0u;
  uint desired = packUnorm4x8(vec4(radiance, 1.0 / 255.0));
  for (int attempt = 0; attempt < 512; ++attempt) {
    uint seen = imageAtomicCompSwap(u_radianceAtomic, voxel, expected, desired);
    if (seen == expected) break;
    expected = seen;
    vec4 previous = unpackUnorm4x8(seen);
    float count = floor(previous.a * 255.0 + 0.5);
    if (count >= 255.0) break;
    vec3 average = (previous.rgb * count + radiance) / (count + 1.0);
    desired = packUnorm4x8(vec4(average, (count + 1.0) / 255.0));
  }
#endif
}
