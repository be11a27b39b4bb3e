// Constants and records of the volumetric technique, included by C++ (src/techniques/volumetric,
// src/reference, tests) and GLSL (shaders/volumetric) alike, so the two cannot disagree.
#ifndef VOXLAB_VOLUMETRIC_SHARED_H
#define VOXLAB_VOLUMETRIC_SHARED_H

#include "common/shared.h"

#ifdef __cplusplus
namespace voxlab::gpu {
#endif

// The 4x4 Bayer matrix times 16, in the order of seed 000's Listing 4.51: entry [x][y] is element
// 4 * x + y, x = pixel column mod 4, y = pixel row mod 4 (rows counted from the bottom, as
// gl_FragCoord). The start offset of a ray is entry / 16 of a step. The thesis prints 0.22 for
// entry [1][1], where 4/16 = 0.25 belongs; VOXLAB_THESIS_BAYER_11 is that value, kept so the
// lesson and the tests can show what it does.
#define VOXLAB_BAYER4_X16 0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5
#define VOXLAB_THESIS_BAYER_11 0.22

#define VOXLAB_BINDING_PARTICLES 10        // SSBO: vec4 per particle (voxel coordinates, age)
#define VOXLAB_BINDING_PARTICLE_STATS 11   // SSBO: uint[4] deposited, dropped, unused, unused
#define VOXLAB_BINDING_RAY_RECORDS 12      // SSBO: RaySample[] of the probed pixel
#define VOXLAB_BINDING_RAY_RECORD_COUNT 13 // SSBO: uint number of RaySample records written
#define VOXLAB_BINDING_PHASE_SAMPLES 14    // SSBO: PhaseSample[]

#define VOXLAB_MAX_MARCH_STEPS 256
#define VOXLAB_PHASE_SAMPLES 2049          // mu = -1 .. 1 in 2048 equal intervals (Simpson)

// One sample of the probed pixel's ray (the per-pixel ray inspector).
struct RaySample {
  vec4 voxel;         // xyz: position in density-grid voxels, w: distance t from the camera (m)
  vec4 world;         // xyz: world position (m), w: start offset u of the ray (fraction of a step)
  vec4 medium;        // x: 1 lit / 0 shadowed, y: sigma_s (1/m), z: sigma_t (1/m), w: particle density (count)
  vec4 phase;         // x: mu = cos(scattering angle), y: p(mu) (1/sr), z: light irradiance E (W/m^2, luminance), w: transmittance T
  vec4 contribution;  // rgb: this sample's in-scattered radiance T sigma_s p E V dt, a: luminance of the sum so far
};

// One sample of the phase function, computed by the same GLSL the march uses.
struct PhaseSample {
  vec4 value;  // x: mu, y: Henyey-Greenstein p(mu), z: the thesis' (1-g)^2 numerator version, w: 1/(4 pi)
};

#ifdef __cplusplus
}  // namespace voxlab::gpu
#endif
#endif  // VOXLAB_VOLUMETRIC_SHARED_H
