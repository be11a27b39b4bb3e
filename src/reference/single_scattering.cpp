#include "reference/single_scattering.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>

#include "core/error.h"
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

struct SingleScatteringReference::Impl {
  const Scene& scene;
  RTCDevice device = nullptr;
  RTCScene rtc = nullptr;

  explicit Impl(const Scene& s) : scene(s) {
    device = rtcNewDevice(nullptr);
    if (!device) throw Error("cannot create an Embree device");
    rtc = rtcNewScene(device);
    rtcSetSceneFlags(rtc, RTC_SCENE_FLAG_ROBUST);
    const size_t nv = s.positions.size(), nt = s.triangleCount();
    if (nt > 0) {
      RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
      auto* vb = static_cast<float*>(
          rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
      auto* ib = static_cast<unsigned*>(
          rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nt));
      for (size_t i = 0; i < nv; ++i)
        for (int k = 0; k < 3; ++k) vb[3 * i + k] = s.positions[i][k];
      std::copy(s.indices.begin(), s.indices.begin() + 3 * nt, ib);
      rtcCommitGeometry(g);
      rtcAttachGeometry(rtc, g);
      rtcReleaseGeometry(g);
    }
    rtcCommitScene(rtc);
    if (rtcGetDeviceError(device) != RTC_ERROR_NONE) throw Error("Embree could not build the scene '" + s.name + "'");
  }
  ~Impl() {
    if (rtc) rtcReleaseScene(rtc);
    if (device) rtcReleaseDevice(device);
  }

  // Distance to the first surface along the ray (infinity when none).
  float firstHit(const glm::vec3& o, const glm::vec3& d) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh{};
    rh.ray.org_x = o.x; rh.ray.org_y = o.y; rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x; rh.ray.dir_y = d.y; rh.ray.dir_z = d.z;
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = INFINITY;
    rh.ray.mask = 0xffffffffu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(rtc, &ctx, &rh);
    return rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? INFINITY : rh.ray.tfar;
  }

  bool occluded(const glm::vec3& o, const glm::vec3& d, float tfar) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay r{};
    r.org_x = o.x; r.org_y = o.y; r.org_z = o.z;
    r.dir_x = d.x; r.dir_y = d.y; r.dir_z = d.z;
    r.tnear = 0.0f;
    r.tfar = tfar;
    r.mask = 0xffffffffu;
    rtcOccluded1(rtc, &ctx, &r);
    return r.tfar < 0.0f;
  }
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
