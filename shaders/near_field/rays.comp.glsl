#version 450
// One ray per traced pixel (ray index u_rayIndex of u_rayCount): cosine-distributed direction,
// start offsets, hierarchical traversal to the first set voxel, RSM lookup of the hit, and the
// estimator (rho * spread / N) * sum of the reflected radiance L~ of valid hits (seed 000
// section 3.2.3 / 4.4.6, Listings 4.45-4.49; the printed (rho/pi)/N form lacks the pi that the
// cosine pdf cos/pi cancels; see src/techniques/near_field/near_field.cpp). A ray that reaches the
// end of its radius without a hit, outside the scene's bounds, sees the sky (common/sky.glsl) and
// adds it as a valid hit would; one that ends inside the bounds adds nothing (the far field).
//
// The probed ray's traversal steps and probe record come from the recorder
// (common/probe_recorder.glsl), in the dispatch of the probed ray, which writes nothing else:
// recording behind a per-pixel flag made every pixel pay for its stores at each step (almost half
// of the stage).
#ifdef VOXLAB_RECORD_PROBE
#define NF_RECORD_STEPS
#endif
#include "common/shared.h"
#include "common/lights.glsl"
#include "near_field/traversal.glsl"
#include "near_field/ray_common.glsl"
#include "common/sky.glsl"
#include "common/probe_recorder.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 1) uniform sampler2D u_position;    // G-buffer: xyz, w = 1 covered
layout(binding = 2) uniform sampler2D u_normal;
layout(binding = 3) uniform sampler2D u_albedo;
layout(rgba32f, binding = 0) uniform image2D u_indirect;        // running (rho * spread / N) * sum L~
layout(r32ui, binding = 1) uniform writeonly uimage2D u_category;  // NF_CAT_* of this ray
layout(r32ui, binding = 2) uniform uimage2D u_steps;            // traversal steps, summed over rays
layout(rgba32f, binding = 3) uniform writeonly image2D u_hitPosition;  // this ray's hit (w = 1)
layout(std430, binding = NF_BINDING_PROBE_RAY) buffer Probe { ProbeRay probe; };

uniform int u_rayIndex, u_rayCount, u_traceScale, u_budget, u_shift;
uniform float u_radius, u_normalOffset, u_rayOffset, u_spread;
uniform vec3 u_volumeOrigin;
uniform float u_volumeEdge;
uniform ivec2 u_probePixel;
uniform int u_probeRay;

#ifndef NF_RECORD_STEPS
// The tracer's counters (traversal.glsl declares them with the recorder's steps).
layout(std430, binding = NF_BINDING_RAY_COUNTERS) buffer Counters { uint counters[]; };
#endif

void main() {
  const bool probing = kRecordProbe;
  ivec2 px;
  if (!recorderPixel(u_probePixel, px) || (probing && u_rayIndex != u_probeRay)) return;
  ivec2 traced = imageSize(u_indirect);
  if (any(greaterThanEqual(px, traced))) return;
  ivec2 g = min(px * u_traceScale, textureSize(u_position, 0) - 1);
  vec4 pos = texelFetch(u_position, g, 0);
  uint category = NF_CAT_NO_RECEIVER;
  vec4 hitOut = vec4(0.0);
  Walk w;
  w.end = NF_END_LEFT; w.steps = 0; w.voxel = ivec3(-1); w.tHit = 1.0;
  vec3 dir = vec3(0.0), origin = vec3(0.0), hit = vec3(0.0), radiance = vec3(0.0);
  float cosTheta = 0.0, radiusLeft = 0.0, dist = 0.0, epsilon = 0.0, facing = 0.0;
  bool escapedToSky = false;
  vec2 rsmTexel = vec2(-1.0);
  vec4 rsmPosition = vec4(0.0);
  vec3 rsmNormal = vec3(0.0);
  if (pos.w != 0.0) {
    vec3 n = normalize(texelFetch(u_normal, g, 0).xyz);
    // Cosine-distributed direction in the cone of the hemisphere that 'spread' keeps.
    vec2 u = u_shift != 0 ? samplePoint(u_rayIndex, u_rayCount, px, 0) : hammersley(u_rayIndex, u_rayCount);
    dir = cosineDirection(n, u, u_spread, cosTheta);
    // Start offsets against self-intersection: along the normal, and along the ray growing as
    // 1/cos (GP3's voxelOffsetNormalScale / voxelOffsetCosThetaScale, in voxel diagonals).
    float along = u_rayOffset * u_voxelDiagonal / max(cosTheta, 1e-3);
    origin = pos.xyz + n * (u_normalOffset * u_voxelDiagonal) + dir * along;
    radiusLeft = u_radius - along;
    if (radiusLeft <= 0.0) {
      w.end = NF_END_DROPPED;
      category = NF_CAT_DROPPED;
    } else {
      vec3 o = (origin - u_volumeOrigin) / u_volumeEdge;
      vec3 e = (origin + dir * radiusLeft - u_volumeOrigin) / u_volumeEdge;
      w = traverse(o, e, u_budget, probing);
      if (w.end == NF_END_BUDGET) category = NF_CAT_BUDGET;
      else if (w.end != NF_END_HIT) {
        category = NF_CAT_NO_HIT;
        escapedToSky = skyOn() && skyEscaped(false, w.end == NF_END_LEFT, origin + dir * radiusLeft);
      } else {
        hit = u_volumeOrigin + u_volumeEdge * (o + w.tHit * (e - o));
        hitOut = vec4(hit, 1.0);
        RsmLookup look = lookupRsm(hit, pos.xyz);
        category = look.category;
        radiance = look.radiance;
        rsmTexel = look.texel;
        dist = look.dist;
        epsilon = look.epsilon;
        facing = look.facing;
        rsmPosition = look.position;
        rsmNormal = look.normal;
      }
    }
#ifndef VOXLAB_RECORD_PROBE
    if (category == NF_CAT_VALID || escapedToSky) {
      vec3 albedo = texelFetch(u_albedo, g, 0).rgb;
      vec4 sum = imageLoad(u_indirect, px);
      vec3 seen = escapedToSky ? skyThrough(1.0) : radiance;
      imageStore(u_indirect, px, vec4(sum.rgb + albedo * u_spread / float(u_rayCount) * seen, 1.0));
    }
    imageStore(u_steps, px, imageLoad(u_steps, px) + uvec4(uint(w.steps)));
    atomicAdd(counters[1 + category], 1u);
    atomicAdd(counters[16 + min(w.steps, 255)], 1u);
#endif
  }
#ifndef VOXLAB_RECORD_PROBE
  imageStore(u_category, px, uvec4(category));
  imageStore(u_hitPosition, px, hitOut);
#else
  probe.receiver = vec4(pos.xyz, pos.w != 0.0 ? 1.0 : 0.0);
  probe.direction = vec4(dir, cosTheta);
  probe.origin = vec4(origin, radiusLeft);
  probe.hitPoint = vec4(hit, w.tHit * max(radiusLeft, 0.0));
  probe.result = uvec4(uvec3(max(w.voxel, ivec3(0))), w.end);
  probe.rsmSample = vec4(rsmTexel, dist, epsilon);
  probe.rsmRadiance = vec4(radiance, float(category));
  probe.steps = vec4(float(w.steps), float(u_budget), facing, 0.0);
  probe.rsmPosition = rsmPosition;
  probe.rsmNormal = vec4(rsmNormal, float((u_normalCheck != 0 ? 1 : 0) + (u_planeTest != 0 ? 2 : 0)));
#endif
}
