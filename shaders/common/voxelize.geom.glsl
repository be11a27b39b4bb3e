#version 450
// Voxelization, per triangle: pick the dominant axis of the triangle's plane normal (computed from
// its positions), project onto the plane of that axis so the triangle covers the most pixels, and
// (conservative mode) push every edge out by half a pixel diagonal (Hasselgren et al. 2005) so each
// pixel the triangle touches gets a fragment. The fragment shader discards fragments outside the
// triangle's half-pixel-grown bounding box and decides the exact voxels.
#include "common/shared.h"
#include "common/voxel_space.glsl"
#include "common/triangle_normal.glsl"

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

in VertexData { vec3 worldPos; vec3 normal; vec2 uv; } vin[];
out VoxelData {
  vec3 normal;
  vec2 uv;
  flat vec4 boundsPx;        // triangle bounds in projected pixels, grown by half a pixel
  flat int axis;             // 0 = x, 1 = y, 2 = z: the projection axis
  flat vec3 tri0, tri1, tri2;  // triangle in voxel coordinates (not swizzled)
  flat vec2 uv0, uv1, uv2;     // its texture coordinates (alphaMode MASK coverage)
  // The plane normal turned to the vertex normals' side, computed as triangle_parallel.comp.glsl
  // does (positions relative to floor(tri0)), for records the same as that pass's.
  flat vec3 faceNormal;
} vout;

layout(std430, binding = VOXLAB_BINDING_AXIS_COUNTS) buffer AxisCounts { uint axisCount[4]; };
uniform int u_conservative;
#if defined(VOXLAB_SKIP_SMALL_TRIANGLES) || defined(VOXLAB_SKIP_OTHER_PART)
// Hybrid voxelization (shaders/voxelization/): triangles classified small are voxelized by the
// triangle-parallel compute pass instead, so the raster pass skips them. When one part of the
// scene is voxelized (its static or its moving triangles), the others carry bit 30 and are skipped.
layout(std430, binding = VOXLAB_BINDING_TRIANGLE_INFO) readonly buffer TriangleInfo { uint triangleInfo[]; };
uniform int u_firstTriangle;  // set by GpuScene::draw: the draw range's first triangle
#endif

// Swizzle voxel coordinates so the projection axis becomes z.
vec3 toProjected(vec3 v, int axis) { return axis == 0 ? v.yzx : (axis == 1 ? v.zxy : v); }

void main() {
  vec3 v[3];
  for (int i = 0; i < 3; ++i) v[i] = worldToVoxel(vin[i].worldPos);
  vec3 n = cross(v[1] - v[0], v[2] - v[0]);  // plane normal from positions, not from normals
  vec3 an = abs(n);
  if (max(an.x, max(an.y, an.z)) <= 0.0) return;  // degenerate triangle: no area, no voxels
#ifdef VOXLAB_SKIP_SMALL_TRIANGLES
  if ((triangleInfo[u_firstTriangle + gl_PrimitiveIDIn] & 0x80000000u) != 0u) return;
#endif
#ifdef VOXLAB_SKIP_OTHER_PART
  if ((triangleInfo[u_firstTriangle + gl_PrimitiveIDIn] & 0x40000000u) != 0u) return;
#endif
  int axis = (an.x >= an.y && an.x >= an.z) ? 0 : (an.y >= an.z ? 1 : 2);
  atomicAdd(axisCount[axis], 1u);

  vec3 s[3];
  for (int i = 0; i < 3; ++i) s[i] = toProjected(v[i], axis);
  int order[3] = int[3](0, 1, 2);
  vec2 e01 = s[1].xy - s[0].xy, e02 = s[2].xy - s[0].xy;
  if (e01.x * e02.y - e01.y * e02.x < 0.0) { order[1] = 2; order[2] = 1; }  // make it counter-clockwise

  vec2 p[3];
  for (int i = 0; i < 3; ++i) p[i] = s[order[i]].xy;
  vec2 lo = min(p[0], min(p[1], p[2])), hi = max(p[0], max(p[1], p[2]));
  vec4 bounds = vec4(lo - 0.5, hi + 0.5);
  vec2 outPos[3] = p;
  if (u_conservative != 0) {
    // Edge lines l.(x,y,1) >= 0 inside; moving each out by half the pixel's extent along its normal,
    // and by 1/64 pixel more: an edge on a pixel boundary puts the grown edge through pixel centres,
    // where the rasterizer's tie rule (and its 1/256 pixel vertex snapping) would drop the pixels
    // beyond a right or top edge, whose cells the edge touches on their lower face (half-open cells
    // include it). Extra pixels cost only a failed exact test.
    vec3 lines[3];
    for (int i = 0; i < 3; ++i) {
      vec3 l = cross(vec3(p[i], 1.0), vec3(p[(i + 1) % 3], 1.0));
      l.z += (0.5 + 1.0 / 64.0) * (abs(l.x) + abs(l.y));
      lines[i] = l;
    }
    for (int i = 0; i < 3; ++i) {
      vec3 q = cross(lines[(i + 2) % 3], lines[i]);
      outPos[i] = abs(q.z) > 1e-12 ? q.xy / q.z : p[i];
    }
  }
  vec3 origin = floor(v[0]);
  vec3 local[3] = vec3[3](v[0] - origin, v[1] - origin, v[2] - origin);
  vec3 localNormal = cross(local[1] - local[0], local[2] - local[0]);
  vec3 vertexNormals = vin[0].normal + vin[1].normal + vin[2].normal;
  vec3 faceNormal = facingPlaneNormal(localNormal, vertexNormals);
  // Depth of any point of the (grown) triangle from the plane through s[0] with normal ns.
  vec3 ns = toProjected(n, axis);
  for (int i = 0; i < 3; ++i) {
    vec2 xy = outPos[i];
    float z = s[0].z - (ns.x * (xy.x - s[0].x) + ns.y * (xy.y - s[0].y)) / ns.z;
    gl_Position = vec4(xy / float(u_resolution) * 2.0 - 1.0, clamp(z / float(u_resolution) * 2.0 - 1.0, -1.0, 1.0), 1.0);
    // Attributes at the grown vertex: extrapolated with its barycentric coordinates in the
    // original projected triangle, so a fragment's uv is the uv at its pixel centre (giving the
    // grown vertex the original vertex's uv would squeeze the texture into the grown triangle).
    vec2 d1 = p[1] - p[0], d2 = p[2] - p[0], dq = xy - p[0];
    float area = d1.x * d2.y - d1.y * d2.x;
    float b1 = (dq.x * d2.y - dq.y * d2.x) / area, b2 = (d1.x * dq.y - d1.y * dq.x) / area;
    vec3 bary = u_conservative != 0 ? vec3(1.0 - b1 - b2, b1, b2) : vec3(i == 0, i == 1, i == 2);
    vout.normal = bary.x * vin[order[0]].normal + bary.y * vin[order[1]].normal + bary.z * vin[order[2]].normal;
    vout.uv = bary.x * vin[order[0]].uv + bary.y * vin[order[1]].uv + bary.z * vin[order[2]].uv;
    vout.boundsPx = bounds;
    vout.axis = axis;
    vout.tri0 = v[0];
    vout.tri1 = v[1];
    vout.tri2 = v[2];
    vout.uv0 = vin[0].uv;
    vout.uv1 = vin[1].uv;
    vout.uv2 = vin[2].uv;
    vout.faceNormal = faceNormal;
    EmitVertex();
  }
  EndPrimitive();
}
