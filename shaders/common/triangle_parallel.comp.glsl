#version 450
// Triangle-parallel voxelization (Schwarz & Seidel 2010; seed 002 section 3): one invocation per
// listed triangle. Setup once per triangle (common/triangle_cells.glsl): the plane's critical-point
// offsets and the three 2D edge functions of each projection. Then loop over the columns of the
// triangle's voxel bounding box projected along the dominant axis; in each column only the voxels
// the plane can reach within that column (at most 3 when the box is not touched exactly, 4 with
// touching faces) are tested. With the loop's bounding box the tests are exactly the 13-axis
// separating axis test of the CPU reference, with half-open cells. Each overlapped voxel
// appends one VoxelFragment through the shared atomic counter.
//
// The columns are one flat loop split into chunks of u_chunkColumns: invocation (x, y) of the
// dispatch does chunk u_firstChunk + y of one triangle. The stage (techniques/common/
// triangle_voxelizer.cpp) runs chunk 0 of every compute triangle, one dispatch per draw range
// (u_directRange = 1: triangle u_listBase + x), then the further chunks of the few triangles
// that have them (triangleList[u_listBase + x]), once per material; every dispatch sees one
// material (u_materialIndex), whose textures it samples. llvmpipe ends every shader invocation's loops after
// 65535 iterations in all (LP_MAX_TGSI_LOOP_ITERATIONS, shared by all loops of the shader), so an
// unsplit loop silently dropped the rest of any triangle with more than ~20000 columns (the
// Cornell box's walls at 256^3). A chunk of C columns costs at most C iterations of the column
// loop plus 4 per column of the candidate loop; the stage keeps 5 C well below the limit.
#include "common/shared.h"
#include "common/voxel_space.glsl"
#include "common/packing.glsl"
#include "common/scene_triangles.glsl"
#include "common/alpha_coverage.glsl"
#include "common/triangle_cells.glsl"

layout(local_size_x = 64) in;
#include "common/material.glsl"
#include "common/triangle_normal.glsl"
layout(std430, binding = VOXLAB_BINDING_TRIANGLE_INFO) readonly buffer TriangleInfo { uint triangleInfo[]; };
layout(std430, binding = VOXLAB_BINDING_TRIANGLE_LIST) readonly buffer TriangleList { uint triangleList[]; };
layout(binding = VOXLAB_BINDING_FRAGMENT_COUNT, offset = 0) uniform atomic_uint u_fragmentCount;
layout(std430, binding = VOXLAB_BINDING_FRAGMENTS) writeonly buffer Fragments { VoxelFragment fragments[]; };
uniform uint u_listBase;      // first entry of triangleList this dispatch visits (u_directRange: first triangle)
uniform uint u_listCount;     // entries it visits
// 1: invocation x visits triangle u_listBase + x of one draw range (material u_materialIndex,
// whose textures are bound), skipping triangles the classification left to the raster pass;
// 0: it visits triangleList[u_listBase + x], skipping triangles of other materials. Either way a
// dispatch sees one material, so its textures can be sampled (GpuScene binds them per range).
uniform int u_directRange;
uniform uint u_firstChunk;    // chunk of invocation y = 0
uniform uint u_chunkColumns;  // voxel columns per invocation
uniform uint u_capacity;   // records the fragment list holds

// Swizzle so that the projection axis becomes the third coordinate (as voxelize.geom.glsl does).
vec3 toProjected(vec3 v, int axis) { return axis == 0 ? v.yzx : (axis == 1 ? v.zxy : v); }
vec3 fromProjected(vec3 s, int axis) { return axis == 0 ? s.zxy : (axis == 1 ? s.yzx : s); }
uvec3 toProjectedU(uvec3 v, int axis) { return axis == 0 ? v.yzx : (axis == 1 ? v.zxy : v); }

// Albedo and emission come from the material's textures at the voxel centre's projection onto
// the triangle, at the mip level whose texel is about one voxel (lod = log2 of texels per voxel).
void appendVoxel(ivec3 voxel, vec3 normal, vec2 uv, float lod) {
  uint index = atomicCounterIncrement(u_fragmentCount);
  if (index >= u_capacity) return;  // the stage sees the count, grows the list and runs again
  VoxelFragment f;
  f.position = packVoxel10(uvec3(voxel));
  f.albedo = packUnorm4x8(vec4(materialAlbedoLod(uv, lod).rgb, 1.0));
  f.normal = packSnorm4x8(vec4(normal, 0.0));
  f.emission = packUnorm4x8(vec4(clamp(materialEmissionLod(uv, lod), 0.0, 1.0), 1.0));
  fragments[index] = f;
}

void main() {
  if (gl_GlobalInvocationID.x >= u_listCount) return;
  uint t = u_directRange != 0 ? u_listBase + gl_GlobalInvocationID.x : triangleList[u_listBase + gl_GlobalInvocationID.x];
  uint material = triangleInfo[t] & 0x00FFFFFFu;
  if (u_directRange != 0 ? (triangleInfo[t] & 0x80000000u) == 0u : material != uint(u_materialIndex)) return;
  uint i0 = sceneVertexIndex(t, 0), i1 = sceneVertexIndex(t, 1), i2 = sceneVertexIndex(t, 2);
  vec3 w0 = worldToVoxel(scenePosition(i0)), w1 = worldToVoxel(scenePosition(i1)), w2 = worldToVoxel(scenePosition(i2));

  // Cells [i, i+1) the triangle's bounding box meets (a vertex on a voxel face is in the upper cell).
  vec3 lo = min(w0, min(w1, w2)), hi = max(w0, max(w1, w2));
  ivec3 boxLo = clamp(ivec3(floor(lo)), ivec3(0), ivec3(u_resolution - 1));
  ivec3 boxHi = clamp(ivec3(floor(hi)), ivec3(0), ivec3(u_resolution - 1));
  uvec3 extent = uvec3(boxHi - boxLo + 1);

  // Work relative to an integer origin near the triangle: small numbers, exact voxel corners.
  vec3 origin = floor(w0);
  vec3 v0 = w0 - origin, v1 = w1 - origin, v2 = w2 - origin;
  vec3 n = cross(v1 - v0, v2 - v0);
  if (max(abs(n.x), max(abs(n.y), abs(n.z))) <= 0.0) return;
  int axis = dominantAxis(n);
  vec3 vertexNormals = sceneNormal(i0) + sceneNormal(i1) + sceneNormal(i2);
  vec3 normal = facingPlaneNormal(n, vertexNormals);

  // The plane and edge tests, set up once (common/triangle_cells.glsl); the column loop below
  // stays inside the triangle's bounding box of cells.
  TriangleCells cells = triangleCellsSetup(w0, w1, w2);
  // alphaMode MASK: a voxel also needs opaque texels near it (common/alpha_coverage.glsl; the
  // triangle in absolute voxel coordinates, as the raster pass and the CPU reference see it).
  vec4 alpha = materials[material].alpha;
  bool masked = coverageMasked(alpha);
  vec2 t0 = sceneUv(i0), t1 = sceneUv(i1), t2 = sceneUv(i2);
  uint level = masked ? coverageLevelFor(alpha, w0, w1, w2, t0, t1, t2) : 0u;
  float lod = voxelTextureLod(w0, w1, w2, t0, t1, t2);

  // Columns along the dominant axis: the plane's depth over a column spans at most
  // |dz/da| + |dz/db| <= 2 voxels, so only a few voxels per column are candidates.
  vec3 s0 = toProjected(v0, axis), sn = toProjected(n, axis);
  vec2 grad = -sn.xy / sn.z;
  float reach = 0.5 * (abs(grad.x) + abs(grad.y));
  vec3 pLo = toProjected(vec3(boxLo), axis);
  uvec2 columns = toProjectedU(extent, axis).xy;
  uint first = (u_firstChunk + gl_GlobalInvocationID.y) * u_chunkColumns;
  if (first >= columns.x * columns.y) return;  // this triangle has fewer chunks
  uint last = min(columns.x * columns.y, first + u_chunkColumns);
  float kMaxBox = toProjected(vec3(boxHi), axis).z;
  vec3 pOrigin = toProjected(origin, axis);
  float zMin = min(s0.z, min(toProjected(v1, axis).z, toProjected(v2, axis).z));
  float zMax = max(s0.z, max(toProjected(v1, axis).z, toProjected(v2, axis).z));
  for (uint column = first; column < last; ++column) {
    float a = pLo.x + float(column % columns.x), b = pLo.y + float(column / columns.x);
    vec2 center = vec2(a, b) - pOrigin.xy + 0.5;
    float zc = s0.z + dot(grad, center - s0.xy);
    float zlo = max(zc - reach, zMin), zhi = min(zc + reach, zMax);
    // Candidates: voxels whose closed depth range meets [zlo, zhi] (widened for rounding); the
    // range is at most 2 voxels deep, so at most 4 of them.
    float kLo = max(floor(zlo - 1e-3) + pOrigin.z, pLo.z);
    float kHi = min(min(floor(zhi + 1e-3) + pOrigin.z, kMaxBox), kLo + 3.0);
    for (float k = kLo; k <= kHi; k += 1.0) {
      vec3 voxel = fromProjected(vec3(a, b, k), axis);
      if (!triangleMeetsCell(cells, voxel)) continue;
      if (masked && !coverageAt(alpha, level, w0, w1, w2, t0, t1, t2, ivec3(voxel))) continue;
      appendVoxel(ivec3(voxel), normal, voxelSampleUv(w0, w1, w2, t0, t1, t2, ivec3(voxel)), lod);
    }
  }
}
