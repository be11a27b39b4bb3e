#include "reference/single_scattering.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "reference/path_tracer.h"
#include "scene/light_model.h"
#include "volumetric/volumetric_shared.h"

namespace voxlab::reference {

double henyeyGreenstein(double mu, double g) {
  double base = 1.0 + g * g - 2.0 * g * mu;
  return (1.0 - g * g) / (4.0 * M_PI * base * std::sqrt(base));
}

double thesisPhase(double mu, double g) {
  double base = 1.0 + g * g - 2.0 * g * mu;
  return (1.0 - g) * (1.0 - g) / (4.0 * M_PI * base * std::sqrt(base));
}

std::vector<double> bayerOffsets() {
  const int x16[16] = {VOXLAB_BAYER4_X16};
  std::vector<double> out;
  for (int v : x16) out.push_back(v / 16.0);
  return out;
}

std::vector<double> thesisBayerOffsets() {
  std::vector<double> out = bayerOffsets();
  out[4 * 1 + 1] = VOXLAB_THESIS_BAYER_11;
  return out;
}

// The camera and shadow rays are the path tracer's (the same Embree scene, alpha-masked texels
// cut away: a MASK material's leaves neither end a camera ray nor shadow a sample).
struct SingleScatteringReference::Impl {
  const Scene& scene;
  ReferenceTracer tracer;
  explicit Impl(const Scene& s) : scene(s), tracer(s) {}
  float firstHit(const glm::vec3& o, const glm::vec3& d) const { return tracer.firstHit(o, d); }
  bool occluded(const glm::vec3& o, const glm::vec3& d, float tfar) const { return tracer.occluded(o, d, tfar); }
};

SingleScatteringReference::SingleScatteringReference(const Scene& scene) : impl_(std::make_unique<Impl>(scene)) {}
SingleScatteringReference::~SingleScatteringReference() = default;

SingleScatteringResult SingleScatteringReference::integrate(const glm::vec3& origin, const glm::vec3& dir,
                                                            const HomogeneousMedium& m, int samples) const {
  SingleScatteringResult r;
  // Clip to the medium's box (slab test) and to the first surface.
  double t0 = 0.0, t1 = INFINITY;
  for (int k = 0; k < 3; ++k) {
    double inv = 1.0 / (std::abs(dir[k]) > 1e-8f ? double(dir[k]) : 1e-8);
    double a = (m.boxMin[k] - origin[k]) * inv, b = (m.boxMax[k] - origin[k]) * inv;
    t0 = std::max(t0, std::min(a, b));
    t1 = std::min(t1, std::max(a, b));
  }
  float hit = impl_->firstHit(origin, dir);
  r.hitSurface = std::isfinite(hit);
  t1 = std::min(t1, double(hit));
  r.length = std::max(t1 - t0, 0.0);
  r.transmittance = std::exp(-m.sigmaT * r.length);
  if (r.length <= 0.0 || samples <= 0) return r;
  const double dt = r.length / samples;
  double depth = 0.0;  // optical depth of the extra medium up to the current interval's start
  for (int i = 0; i < samples; ++i) {
    double t = t0 + (i + 0.5) * dt;
    glm::vec3 x = origin + float(t) * dir;
    double extra = m.extraScattering ? m.extraScattering(x) : 0.0;
    double extraDepth = depth + 0.5 * m.extinctionRatio * extra * dt;  // to the interval's midpoint
    depth += m.extinctionRatio * extra * dt;
    if (impl_->scene.lights.empty()) continue;
    const Light& light = impl_->scene.lights[0];
    LightSample ls = sampleLight(light, x);
    glm::vec3 irradiance = ls.irradianceAtNormalIncidence;
    if (irradiance == glm::vec3(0.0f)) continue;
    // Shadow ray: up to the light (a sun: to infinity), starting a hair off the sample.
    float reach = std::isfinite(ls.distance) ? ls.distance * (1.0f - 1e-4f) : INFINITY;
    if (impl_->occluded(x, ls.toLight, reach)) continue;
    double mu = glm::dot(glm::dvec3(dir), glm::dvec3(ls.toLight));
    double w = std::exp(-m.sigmaT * (t - t0) - extraDepth) * (m.sigmaS + extra) *
               henyeyGreenstein(std::clamp(mu, -1.0, 1.0), m.g) * dt;
    r.inscatter += w * glm::dvec3(irradiance);
  }
  r.transmittance *= std::exp(-depth);
  return r;
}

}  // namespace voxlab::reference
