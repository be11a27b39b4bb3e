// Structs and binding points of the near-field technique, included by C++ and GLSL (the same
// pattern as shaders/common/shared.h). std430-compatible: 16-byte members only.
#ifndef VOXLAB_NEAR_FIELD_SHARED_H
#define VOXLAB_NEAR_FIELD_SHARED_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace voxlab::gpu {
using vec4 = glm::vec4;
using uvec4 = glm::uvec4;
#endif

// Slices per column: fixed by the RGBA32UI format (4 channels x 32 bits).
#define NF_SLICES 128

// Binding points (SSBOs) used by the near-field stages.
#define NF_BINDING_TRAVERSAL_STEPS 10   // TraversalStep[] of the probed pixel's probed ray
#define NF_BINDING_PROBE_RAY 11         // ProbeRay (one record)
#define NF_BINDING_RAY_COUNTERS 12      // uint[16]: [0] step records written, [1 + category] rays per category
#define NF_BINDING_SEGMENTS 13          // vec4[2] per segment (tests: origin, end in unit space)
#define NF_BINDING_SEGMENT_HITS 14      // uvec4 per segment (tests: x, y, slice, termination)
#define NF_MAX_TRAVERSAL_STEPS 256      // records kept for the probe (the walk itself may be longer)

// Termination of a ray's walk (TraversalStep.action of the last record, ProbeRay.result.w).
#define NF_END_HIT 0u          // a set voxel found at level 0
#define NF_END_LEFT 1u         // reached the end of the segment or left the voxel volume
#define NF_END_BUDGET 2u       // the step budget ran out (counted: would silently be a miss)
#define NF_END_OUTSIDE 3u      // the origin lies outside the voxel volume (guard, no fetch)
#define NF_END_DROPPED 4u      // the start offset used up the ray's radius

// Per-step actions.
#define NF_STEP_DESCEND 8u     // ray mask AND texel mask != 0 above level 0: go one level finer
#define NF_STEP_ADVANCE 9u     // empty: move to the texel's exit and go one level coarser

// Categories of a ray's RSM lookup (image "ray-category", counters [1 + category]).
#define NF_CAT_VALID 0u         // hit, RSM texel is the hit surface and faces the receiver
#define NF_CAT_NO_HIT 1u        // no voxel within the radius (or outside the volume)
#define NF_CAT_NOT_IN_RSM 2u    // hit point behind the light or outside its map
#define NF_CAT_TOO_FAR 3u       // the RSM sees another surface there (distance > epsilon)
#define NF_CAT_WRONG_FACING 4u  // the sender faces away from the receiver
#define NF_CAT_BUDGET 5u        // the walk ran out of steps
#define NF_CAT_DROPPED 6u       // the start offset exceeded the radius
#define NF_CAT_NO_RECEIVER 7u   // no geometry at the pixel
#define NF_CATEGORIES 8

// One step of the hierarchical traversal, recorded for the probed pixel and ray.
struct TraversalStep {
  uvec4 where;     // x: step index, y: level, z: texel x, w: texel y (at that level)
  uvec4 slices;    // x: first slice, y: last slice the ray covers in the texel, z: action, w: hit slice (or 255)
  uvec4 rayMask;   // the ray mask of slices x..y (RGBA = slices 0-31, 32-63, 64-95, 96-127, MSB first)
  uvec4 hitMask;   // ray mask AND the texel's column at that level
  vec4 t;          // x: t entering the texel, y: t leaving it, z: segment end t, w: unused
};

// The probed pixel's probed ray: set-up, walk result, hit and RSM lookup.
struct ProbeRay {
  vec4 receiver;     // xyz: receiver (world), w: 1 when the pixel has geometry
  vec4 direction;    // xyz: ray direction (world, unit), w: cos(theta) to the normal
  vec4 origin;       // xyz: offset ray origin (world), w: radius left after the start offset (m)
  vec4 hitPoint;     // xyz: point of the ray in the hit voxel (world), w: t (m from origin)
  uvec4 result;      // x, y: hit column (level 0), z: hit slice, w: termination (NF_END_*)
  vec4 rsmSample;    // xy: RSM texel, z: distance |hit - RSM position| (m), w: epsilon (m)
  vec4 rsmRadiance;  // rgb: reflected radiance read from the RSM, w: category (NF_CAT_*)
  vec4 steps;        // x: traversal steps taken, y: budget, z: cos between RSM normal and sender->receiver, w: unused
  // Filled on the CPU after the walk (src/techniques/near_field/surface_query.h), not by the shader:
  vec4 surface;      // xyz: the true first surface point on origin + t direction, t in (0, radius left] (exact
                     // ray/triangle query), w: its t (m); w = -1 when no triangle lies within the radius left
  vec4 surfaceGap;   // hit voxel vs that point, in voxels (per axis in that axis' voxel size): x: largest axis
                     // distance from the voxel's box (0 inside or on a face, <= 1 in a 26-neighbour), y: the
                     // same as a Euclidean length, z: (surface t - hit t) / voxel diagonal; all -1 unless both
                     // exist; w: the surface's triangle index (-1 none)
  // The RSM lookup's texel (shader again): what the RSM sees there, beside rsmSample's distance and threshold.
  vec4 rsmPosition;  // xyz: the RSM texel's surface position (world), w: its footprint (m; 0 = an empty texel)
  vec4 rsmNormal;    // xyz: that surface's normal, w: 1 if the normal test (rsm.normal-check) is on, + 2 if the
                     // distance is to the surface's plane (rsm.validity=plane)
};

#ifdef __cplusplus
}  // namespace voxlab::gpu
#endif
#endif  // VOXLAB_NEAR_FIELD_SHARED_H
