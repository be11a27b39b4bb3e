#version 450
// Voxelization, per fragment: the fragment is one column of voxels along the projection axis.
// Conservative mode tests each voxel of the column that the triangle's plane can reach within
// this pixel (at most 3, because the projection axis is dominant) with the exact triangle/cell
// overlap test of the compute pass (common/triangle_cells.glsl, the same bits), and appends one
// voxel fragment per overlapping voxel. Plain mode appends the one
// voxel at the pixel centre's depth.
#include "common/shared.h"
#include "common/voxel_space.glsl"
#include "common/material.glsl"
#include "common/packing.glsl"
#include "common/triangle_cells.glsl"
#include "common/alpha_coverage.glsl"

in VoxelData {
  vec3 normal;
  vec2 uv;
  flat vec4 boundsPx;
  flat int axis;
  flat vec3 tri0, tri1, tri2;
  flat vec2 uv0, uv1, uv2;
  flat vec3 faceNormal;
} fin;

layout(binding = VOXLAB_BINDING_FRAGMENT_COUNT, offset = 0) uniform atomic_uint u_fragmentCount;
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) writeonly buffer Fragments { VoxelFragment fragments[]; };
uniform uint u_capacity;
uniform int u_conservative;

vec3 fromProjected(vec3 s, int axis) { return axis == 0 ? s.zxy : (axis == 1 ? s.yzx : s); }
vec3 toProjected(vec3 v, int axis) { return axis == 0 ? v.yzx : (axis == 1 ? v.zxy : v); }

// With VOXLAB_RECORDS_AS_COMPUTE (the hybrid's raster pass) a record is the one the
// triangle-parallel pass would write for the voxel: the plane normal turned to the vertex normals'
// side, albedo and emission at the voxel centre's projection onto the triangle, at the mip level
// whose texel is about one voxel; so the hybrid's fragments do not depend on how a triangle was
// routed. Otherwise the interpolated vertex normal and the pixel centre's uv.

void appendVoxel(ivec3 voxel) {
  if (any(lessThan(voxel, ivec3(0))) || any(greaterThanEqual(voxel, ivec3(u_resolution)))) return;
  uint index = atomicCounterIncrement(u_fragmentCount);
  if (index >= u_capacity) return;  // the stage sees the count, grows the list and runs again
#ifdef VOXLAB_RECORDS_AS_COMPUTE
  vec2 uv = voxelSampleUv(fin.tri0, fin.tri1, fin.tri2, fin.uv0, fin.uv1, fin.uv2, voxel);
  float lod = voxelTextureLod(fin.tri0, fin.tri1, fin.tri2, fin.uv0, fin.uv1, fin.uv2);
  vec4 albedo = materialAlbedoLod(uv, lod);
  vec3 emission = materialEmissionLod(uv, lod);
  vec3 normal = fin.faceNormal;
#else
  vec4 albedo = materialAlbedo(fin.uv);
  vec3 emission = materialEmission(fin.uv);
  vec3 normal = normalize(fin.normal);
#endif
  VoxelFragment f;
  f.position = packVoxel10(uvec3(voxel));
  f.albedo = packUnorm4x8(vec4(albedo.rgb, 1.0));
  f.normal = packSnorm4x8(vec4(normal, 0.0));
  f.emission = packUnorm4x8(vec4(clamp(emission, 0.0, 1.0), 1.0));
  fragments[index] = f;
}

void main() {
  vec2 px = gl_FragCoord.xy;
  if (u_conservative == 0) {
    if (materialCutAway(fin.uv)) return;  // alphaMode MASK, tested at the pixel centre like a camera
    appendVoxel(ivec3(fromProjected(vec3(floor(px), floor(gl_FragCoord.z * float(u_resolution))), fin.axis)));
    return;
  }
  if (px.x < fin.boundsPx.x || px.y < fin.boundsPx.y || px.x > fin.boundsPx.z || px.y > fin.boundsPx.w) discard;
  vec3 s0 = toProjected(fin.tri0, fin.axis), s1 = toProjected(fin.tri1, fin.axis), s2 = toProjected(fin.tri2, fin.axis);
  vec3 ns = cross(s1 - s0, s2 - s0);
  vec2 grad = -ns.xy / ns.z;  // dz/dx, dz/dy of the plane; |grad| <= 1 per axis (dominant axis)
  float zc = s0.z + dot(grad, px - s0.xy);
  float reach = 0.5 * (abs(grad.x) + abs(grad.y));
  float zlo = max(zc - reach, min(s0.z, min(s1.z, s2.z)));
  float zhi = min(zc + reach, max(s0.z, max(s1.z, s2.z)));
  vec2 cell = floor(px);
  // alphaMode MASK: a voxel also needs opaque texels near it (common/alpha_coverage.glsl).
  vec4 alpha = materials[u_materialIndex].alpha;
  bool masked = coverageMasked(alpha);
  uint level = masked ? coverageLevelFor(alpha, fin.tri0, fin.tri1, fin.tri2, fin.uv0, fin.uv1, fin.uv2) : 0u;
  // Candidates: the cells whose depth range meets [zlo, zhi], widened by 1e-3 voxel for rounding
  // (a plane exactly on a cell boundary must reach the cell above it); at most 4. The exact test
  // decides, with half-open cells; its setup is the triangle's, once per pixel.
  TriangleCells cells = triangleCellsSetup(fin.tri0, fin.tri1, fin.tri2);
  float kLo = floor(zlo - 1e-3), kHi = min(floor(zhi + 1e-3), kLo + 3.0);
  for (float z = kLo; z <= kHi; z += 1.0) {
    ivec3 voxel = ivec3(fromProjected(vec3(cell, z), fin.axis));
    if (!triangleCellsBoxHolds(cells, voxel) || !triangleMeetsCell(cells, vec3(voxel))) continue;
    if (masked && !coverageAt(alpha, level, fin.tri0, fin.tri1, fin.tri2, fin.uv0, fin.uv1, fin.uv2, voxel)) continue;
    appendVoxel(voxel);
  }
}
