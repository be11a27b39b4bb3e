#version 450
// Density grid, part 1 (seed 000 Listing 4.50, after Vos 2014): each particle of an ascending
// smoke plume adds 1 to the R32UI count of the voxel it is in, with an integer atomic (order
// independent, so the grid is the same on every run). The voxel is floor() of the particle's
// voxel coordinates (int() would truncate (-1, 0) into voxel 0); particles outside the grid are
// dropped and counted. Positions are a pure function of (particle index, u_time).
#include "volumetric/volumetric_shared.h"
layout(local_size_x = 64) in;
layout(std430, binding = VOXLAB_BINDING_PARTICLES) writeonly buffer Particles { vec4 particles[]; };
layout(std430, binding = VOXLAB_BINDING_PARTICLE_STATS) buffer ParticleStats { uint particleStats[4]; };
layout(r32ui, binding = 0) uniform coherent uimage3D u_counts;
uniform uint u_count;
uniform float u_time;        // seconds
uniform float u_lifetime;    // seconds from the source to the top of the plume
uniform vec3 u_source;       // world centre of the source disc
uniform float u_sourceRadius;
uniform float u_riseHeight;  // metres risen over a lifetime
uniform float u_spread;      // lateral drift over a lifetime (metres, per axis)
uniform vec3 u_volumeOrigin;
uniform float u_invVoxelSize;
uniform int u_resolution;

uint hash(uint x) {  // a 32-bit integer hash (lowbias32)
  x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15; x *= 0x846ca68bu; x ^= x >> 16;
  return x;
}
float unit(uint i, uint k) { return float(hash(i * 8u + k) >> 8) * (1.0 / 16777216.0); }

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_count) return;
  float age = fract(unit(i, 0u) + u_time / u_lifetime);
  float r = u_sourceRadius * sqrt(unit(i, 1u));
  float a = 6.28318530718 * unit(i, 2u);
  // Drift grows with age (the plume widens as it rises) and sways with a per-particle phase.
  vec2 drift = (vec2(unit(i, 3u), unit(i, 4u)) - 0.5) * u_spread * age;
  float sway = 0.15 * u_spread * sin(6.0 * age + 6.28318530718 * unit(i, 5u));
  vec3 p = u_source + vec3(r * cos(a) + drift.x + sway, u_riseHeight * age, r * sin(a) + drift.y);
  vec3 v = (p - u_volumeOrigin) * u_invVoxelSize;
  particles[i] = vec4(v, age);
  ivec3 cell = ivec3(floor(v));
  if (all(greaterThanEqual(cell, ivec3(0))) && all(lessThan(cell, ivec3(u_resolution)))) {
    imageAtomicAdd(u_counts, cell, 1u);
    atomicAdd(particleStats[0], 1u);
  } else {
    atomicAdd(particleStats[1], 1u);
  }
}
