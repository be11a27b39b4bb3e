#version 450
// Light injection, one invocation per voxel fragment: Lambertian direct light from the scene's
// light (shadow-mapped), plus emission (common/fragment_light.glsl, shared with svo's leaves),
// averaged into the voxel. Two ways to average
// (inject.average):
//  - exact-sum (u_average 0): each channel is added, in fixed point (1/4096 steps), to a 32-bit
//    sum per voxel with imageAtomicAdd, together with a count; inject_resolve.comp.glsl divides.
//    Integer addition does not depend on the order of the fragments, so the result is exact up to
//    the one fixed-point rounding per fragment and the same on every run.
//  - compare-and-swap (u_average 1): a running average in the RGBA8 voxel itself, updated with a
//    compare-and-swap loop on its r32ui view (seed 000, Crassin and Green). Alpha holds how many
//    fragments have been averaged in (saturating at 255: later fragments are ignored); each
//    update rounds to 8 bits, so the result depends on the order in which fragments arrive.
// Either way the occlusion fix stage then sets alpha to 1 in every non-empty voxel.
// Every fragment also ORs its normal's facing code (common/facing.glsl) into u_facing: per travel
// direction of a cone, how much of the voxel's surfaces' fronts it sees (the anisotropic mips'
// leaves, mipmap_anisotropic.comp.glsl).
#include "common/shared.h"
#include "common/voxel_space.glsl"
#include "common/packing.glsl"
#include "common/lights.glsl"
#include "common/fragment_light.glsl"
#include "common/facing.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) readonly buffer Fragments { VoxelFragment fragments[]; };
layout(r32ui, binding = 0) uniform coherent uimage3D u_radianceAtomic;  // compare-and-swap: the RGBA8 grid
// exact-sum: fixed-point sums of red, green, blue and the fragment count per voxel
layout(r32ui, binding = 1) uniform uimage3D u_sumR;
layout(r32ui, binding = 2) uniform uimage3D u_sumG;
layout(r32ui, binding = 3) uniform uimage3D u_sumB;
layout(r32ui, binding = 4) uniform uimage3D u_count;
layout(r32ui, binding = 5) uniform uimage3D u_facing;  // facing codes, common/facing.glsl
layout(binding = 2) uniform sampler2D u_shadowMap;  // a texture unit (image units are separate)
uniform uint u_fragmentCount;
uniform int u_average;            // 0 = exact-sum, 1 = compare-and-swap
// What a voxel can hold: 1 with RGBA8 grids (voxel.format=rgba8), kHdrMaxRadiance with RGBA16F.
uniform float u_maxRadiance;
const float kFixedPointScale = 4096.0;  // exact-sum: radiance units per integer step

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_fragmentCount) return;
  VoxelFragment f = fragments[i];
  ivec3 voxel = ivec3(unpackVoxel10(f.position));
  vec3 radiance = fragmentRadiance(f, u_shadowMap);
  radiance = clamp(radiance, 0.0, u_maxRadiance);
  imageAtomicOr(u_facing, voxel, facingCode(normalize(unpackSnorm4x8(f.normal).xyz)));

  if (u_average == 0) {
    uvec3 fixedPoint = uvec3(radiance * kFixedPointScale + 0.5);
    imageAtomicAdd(u_sumR, voxel, fixedPoint.r);
    imageAtomicAdd(u_sumG, voxel, fixedPoint.g);
    imageAtomicAdd(u_sumB, voxel, fixedPoint.b);
    imageAtomicAdd(u_count, voxel, 1u);
    return;
  }

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
}
