// CPU reference for the volumetric technique: the single-scattering integral along camera rays
// through a homogeneous medium filling a box, with exact visibility (the path tracer's Embree
// occlusion rays towards the light, alpha masks included), the light model of scene/light_model.h and
// Henyey-Greenstein scattering. Also the phase functions and the Bayer matrix the tests check.
//
// For a camera ray x(t) = o + t d, the part [t0, t1] of it inside the medium box and before the
// first surface (t1 = min(box exit, hit distance)):
//   L_in = int_{t0}^{t1} exp(-sigma_t (t - t0)) sigma_s p(mu(t)) E(x(t)) V(x(t)) dt,
//   T    = exp(-sigma_t (t1 - t0)),
// with mu = dot(d, unit vector to the light), E the light's irradiance at normal incidence and V
// 1 when nothing lies between x(t) and the light. The integral is a midpoint rule with 'samples'
// intervals (exact visibility per sample; the only approximation is where V or E change within
// an interval). Like the GPU technique, light on its way to a sample is not attenuated.
#pragma once
#include <functional>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace voxlab::reference {

// Henyey-Greenstein p(mu) = (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^1.5), 1/sr; |g| < 1.
double henyeyGreenstein(double mu, double g);
// Seed 000 Eq. 1 / Listing 4.53: (1 - g)^2 in the numerator (integrates to (1 - g)/(1 + g)).
double thesisPhase(double mu, double g);

// The 4x4 Bayer start offsets (fractions of a step), entry [x][y] at 4 * x + y: voxlab's and the
// thesis' (0.22 at [1][1]).
std::vector<double> bayerOffsets();
std::vector<double> thesisBayerOffsets();

struct HomogeneousMedium {
  glm::vec3 boxMin{0.0f}, boxMax{0.0f};  // the medium fills this box (e.g. the density grid)
  double sigmaS = 0.0;                   // scattering coefficient, 1/m
  double sigmaT = 0.0;                   // extinction coefficient, 1/m
  double g = 0.0;                        // Henyey-Greenstein anisotropy
  // Optional: a scattering coefficient added at each point (e.g. smoke particles' sigma_s,
  // 1/m), with extinction extinctionRatio times it. The medium is then not homogeneous: the
  // transmittance integrates sigma_t along the ray with the same midpoint samples.
  std::function<double(const glm::vec3&)> extraScattering;
  double extinctionRatio = 1.0;
};

struct SingleScatteringResult {
  glm::dvec3 inscatter{0.0};  // W/(m^2 sr)
  double transmittance = 1.0;
  double length = 0.0;        // t1 - t0
  bool hitSurface = false;
};

class SingleScatteringReference {
 public:
  // Traces with the path tracer's Embree scene (ReferenceTracer: alpha-masked texels let rays
  // through); uses the scene's first light (none: zero).
  explicit SingleScatteringReference(const Scene& scene);
  ~SingleScatteringReference();
  SingleScatteringReference(const SingleScatteringReference&) = delete;
  SingleScatteringReference& operator=(const SingleScatteringReference&) = delete;

  SingleScatteringResult integrate(const glm::vec3& origin, const glm::vec3& unitDir, const HomogeneousMedium& medium,
                                   int samples) const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace voxlab::reference
