#version 450
// Test kernel (tests/unit/test_near_field.cpp): the hierarchical traversal of traversal.glsl on a
// list of unit-space segments, so it can be compared with a brute-force DDA on the CPU, and the
// GPU first-bit function on a list of masks.
#include "near_field/traversal.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = NF_BINDING_SEGMENTS) readonly buffer Segments { vec4 segments[]; };  // mode 0: o, e per segment
layout(std430, binding = NF_BINDING_SEGMENTS) readonly buffer Masks { uvec4 masks[]; };  // mode 1 view
layout(std430, binding = NF_BINDING_SEGMENT_HITS) writeonly buffer Hits { uvec4 hits[]; };
uniform int u_count, u_budget, u_mode;  // mode 0: traverse segments; 1: first slice of masks

void main() {
  int i = int(gl_GlobalInvocationID.x);
  if (i >= u_count) return;
  if (u_mode == 1) {
    uvec4 m = masks[i];
    hits[i] = uvec4(uint(firstSliceAlong(m, false) + 1), uint(firstSliceAlong(m, true) + 1), 0u, 0u);
    return;
  }
  Walk w = traverse(segments[2 * i].xyz, segments[2 * i + 1].xyz, u_budget, false);
  hits[i] = uvec4(uvec3(max(w.voxel, ivec3(0))), w.end | (uint(w.steps) << 8));
}
