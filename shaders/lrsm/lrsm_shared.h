// Structs and binding points of the lrsm technique, included by C++ and GLSL (the pattern of
// shaders/common/shared.h). std430-compatible: vec4 members only.
#ifndef VOXLAB_LRSM_SHARED_H
#define VOXLAB_LRSM_SHARED_H

#ifdef __cplusplus
#include <glm/glm.hpp>
namespace voxlab::gpu {
using vec4 = glm::vec4;
#endif

#define LRSM_MAX_LAYERS 16            // (depth splits + 1) * (normal splits + 1), splits <= 3 each
#define LRSM_MAX_CONES 8              // 6 diffuse + 1 specular + 1 shadow
#define LRSM_MAX_STEPS 64             // sphere samples per cone
#define LRSM_MAX_GATHER_RECORDS (7 * LRSM_MAX_STEPS * 4)  // kept per probe; more are counted, not stored
#define LRSM_EMPTY_LAYER 255u         // layer id of an RSM texel that sees nothing
#define LRSM_ESTIMATOR_COVERAGE 0     // lrsm.estimator=coverage: T_i * sum_l A*R V <n.v> / <n.l>
#define LRSM_ESTIMATOR_PAPER 1        // lrsm.estimator=paper: T_i * alpha_i * sum_l f A*R V N (Algorithm 1)
#define LRSM_MIN_NDOTL 0.1            // floor of <n_mean . l> in the coverage estimator's Jacobian
#define LRSM_TWO_LOBE_VARIANCE 0.01   // sigma^2 (warped) from which two depth lobes are blended in (lrsm::kTwoLobeVariance)
#define LRSM_HORIZON_VOXELS 2.0       // a layer's mean surface point must lie this far above the receiver's plane

#define LRSM_BINDING_GATHER 12        // SSBO: LrsmGatherRecord[] of the probed pixel
#define LRSM_BINDING_GATHER_COUNT 13  // SSBO: uint records attempted (may exceed the capacity)
#define LRSM_BINDING_CONE_RESULTS 14  // SSBO: LrsmConeResult[LRSM_MAX_CONES + 1] (last = final sum)

// One layer of Algorithm 1 for one sphere sample of the probed pixel's cones.
struct LrsmGatherRecord {
  vec4 centre;        // xyz: sample centre x_c (world), w: radius r_c (m)
  vec4 cone;          // x: cone index, y: sample index, z: voxel mip, w: alpha_i (step-corrected)
  vec4 march;         // x: transmittance before this sample, y, z: RSM uv of x_c, w: LRSM level (fractional)
  vec4 layer;         // x: layer id, y: 1 = layer read (f > 0), z: weight f (Eq. 15, or 1 for a layer in the window),
                      // w: N = <n_mean . v> (v toward the receiver from x_c, or from the layer's mean surface point)
  vec4 moments;       // x: mu, y: sigma^2 (floored), z: V (Eq. 12), w: z_c warped into the layer (z')
  vec4 coverage;      // rgb: A*R (premultiplied radiance at the mip), a: alpha of the layer at the mip
  vec4 contribution;  // rgb: f * A*R * V * N * J (0 when skipped), a: half the depth window warped into the layer (r')
  vec4 footprint;     // x: d_circle (LRSM base texels), y: z_c (light depth, m), z: J = 1 / max(<n_mean . l>, 0.1)
                      // (coverage estimator; 1 for Algorithm 1), w: 1 = record valid
};

// One cone of the probed pixel (index LRSM_MAX_CONES: the final sum).
struct LrsmConeResult {
  vec4 direction;  // xyz: cone axis (world), w: weight (diffuse: sums to pi)
  vec4 result;     // rgb: I (Eq. 1), a: accumulated opacity
  vec4 info;       // x: cone index, y: samples taken, z: aperture (radians, full angle), w: 0 diffuse, 1 specular, 2 shadow, 3 sum
};

#ifdef __cplusplus
}  // namespace voxlab::gpu
#endif
#endif  // VOXLAB_LRSM_SHARED_H
