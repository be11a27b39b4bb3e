// CPU halves of the lrsm decisions (see lrsm.h); the shaders mirror these formulas.
#include <algorithm>
#include <cmath>

#include "techniques/lrsm/lrsm.h"

namespace voxlab::lrsm {

int LayerLayout::depthIntervalOf(float z) const {
  const float t = (z - zNear) / std::max(zFar - zNear, 1e-20f);
  return std::clamp(int(std::floor(t * float(depthIntervals()))), 0, depthIntervals() - 1);
}

int LayerLayout::normalIntervalOf(float ndotl) const {
  return std::clamp(int(std::floor(ndotl * float(normalIntervals()))), 0, normalIntervals() - 1);
}

void LayerLayout::rangeOf(int d, float& zMin, float& zMax) const {
  const float w = intervalWidth();
  zMin = zNear + w * float(d) - (d > 0 ? 0.5f * delta() : 0.0f);
  zMax = zNear + w * float(d + 1) + (d + 1 < depthIntervals() ? 0.5f * delta() : 0.0f);
}

float LayerLayout::warp(int d, float z) const {
  float lo, hi;
  rangeOf(d, lo, hi);
  return (z - lo) / std::max(hi - lo, 1e-20f);
}

float falloffK(float t, bool smooth) {
  t = std::clamp(t, 0.0f, 1.0f);
  return smooth ? t * t * (3.0f - 2.0f * t) : t;
}

float LayerLayout::falloff(int d, float z, bool smooth) const {
  float lo, hi;
  rangeOf(d, lo, hi);
  if (z < lo || z > hi) return 0.0f;
  const float dl = delta();
  if (dl <= 0.0f) return 1.0f;
  float f = 1.0f;
  if (d > 0 && z < lo + dl) f = std::min(f, falloffK((z - lo) / dl, smooth));
  if (d + 1 < depthIntervals() && z > hi - dl) f = std::min(f, falloffK((hi - z) / dl, smooth));
  return f;
}

float approxErf(float x) {
  // Abramowitz and Stegun 7.1.26.
  const float s = x < 0.0f ? -1.0f : 1.0f;
  x = std::fabs(x);
  const float t = 1.0f / (1.0f + 0.3275911f * x);
  const float y = 1.0f - (((((1.061405429f * t - 1.453152027f) * t) + 1.421413741f) * t - 0.284496736f) * t +
                          0.254829592f) * t * std::exp(-x * x);
  return s * y;
}

float gaussianVisibility(float zc, float rc, float mu, float sigma2) {
  const float k = 1.0f / std::sqrt(2.0f * sigma2);
  const float v = 0.5f * (approxErf((zc + rc - mu) * k) - approxErf((zc - rc - mu) * k));
  return std::clamp(v, 0.0f, 1.0f);
}

double gaussianVisibilityExact(double zc, double rc, double mu, double sigma2) {
  const double k = 1.0 / std::sqrt(2.0 * sigma2);
  return 0.5 * (std::erf((zc + rc - mu) * k) - std::erf((zc - rc - mu) * k));
}

DepthLobes depthLobes(const glm::vec4& m, float minVariance) {
  const float mu = m.x, var = m.y - mu * mu;
  DepthLobes out;
  out.count = 1;
  out.mean[0] = mu;
  out.weight[0] = 1.0f;
  out.variance[0] = std::max(var, minVariance);
  const float t = std::clamp((var - kTwoLobeVariance) / (2.0f * kTwoLobeVariance), 0.0f, 1.0f);
  const float blend = t * t * (3.0f - 2.0f * t);
  if (blend <= 0.0f) return out;
  const float c3 = m.z - 3.0f * mu * m.y + 2.0f * mu * mu * mu;
  const float c4 = m.w - 4.0f * mu * m.z + 6.0f * mu * mu * m.y - 3.0f * mu * mu * mu * mu;
  const float skew = c3 / (var * std::sqrt(var));
  const float kurtosis = std::max(c4 / (var * var), skew * skew + 1.0f);
  float lo = 0.0f, hi = 1.0f;
  for (int i = 0; i < 16; ++i) {
    const float lambda = 0.5f * (lo + hi);
    const float k = skew * skew / std::max(1.0f - lambda, 1e-6f) + 1.0f + 4.0f * lambda - 2.0f * lambda * lambda;
    (k < kurtosis ? lo : hi) = lambda;
  }
  out.lambda = 0.5f * (lo + hi);
  if (out.lambda > 0.999f) return out;
  const float rest = 1.0f - out.lambda, gamma0 = skew / (rest * std::sqrt(rest));
  const float sign = gamma0 < 0.0f ? -1.0f : (gamma0 > 0.0f ? 1.0f : 0.0f);
  const float q = std::clamp(0.5f * (1.0f - sign * std::sqrt(gamma0 * gamma0 / (gamma0 * gamma0 + 4.0f))), 1e-4f, 1.0f - 1e-4f);
  const float spread = std::sqrt(rest * var), lobeVariance = std::max(out.lambda * var, minVariance);
  out.count = 3;
  out.weight[0] = 1.0f - blend;
  out.mean[1] = mu + spread * std::sqrt((1.0f - q) / q);
  out.weight[1] = blend * q;
  out.mean[2] = mu - spread * std::sqrt(q / (1.0f - q));
  out.weight[2] = blend * (1.0f - q);
  out.variance[1] = out.variance[2] = lobeVariance;
  return out;
}

float lobeVisibility(const DepthLobes& lobes, float zc, float rc) {
  float v = 0.0f;
  for (int k = 0; k < lobes.count; ++k)
    if (lobes.weight[k] > 0.0f) v += lobes.weight[k] * gaussianVisibility(zc, rc, lobes.mean[k], lobes.variance[k]);
  return v;
}

double capCosineIntegral(double half, double tilt) {
  const double pi = 3.14159265358979323846;
  return pi * std::sin(half) * std::sin(half) * std::cos(tilt);
}

std::vector<DiffuseCone> diffuseCones() {
  const float tilt = kDiffuseAperture;  // 60 degrees from the normal: the ring touches the central cone
  std::vector<DiffuseCone> cones;
  cones.push_back({{0.0f, 0.0f, 1.0f}, 1.0f});
  for (int i = 0; i < kDiffuseCones - 1; ++i) {
    const float phi = 6.28318531f * float(i) / float(kDiffuseCones - 1);
    cones.push_back({{std::sin(tilt) * std::cos(phi), std::sin(tilt) * std::sin(phi), std::cos(tilt)}, std::cos(tilt)});
  }
  float sum = 0.0f;
  for (const auto& c : cones) sum += c.weight;
  for (auto& c : cones) c.weight *= 3.14159265f / sum;
  return cones;
}

PaperMemory paperMemory(int voxelResolution, int rsmResolution, int layers) {
  const double v = double(voxelResolution);
  const double r = double(rsmResolution);
  return {v * v * v * 8.0 / 7.0, r * r * 16.0 * 4.0 / 3.0, (r / 2) * (r / 2) * 24.0 * layers * 4.0 / 3.0};
}

std::string atlasSizeError(int rsmResolution, int layers, int maxTextureSize) {
  const long long width = (long long)(rsmResolution / 2) * layers;
  if (width <= maxTextureSize) return "";
  return "lrsm: " + std::to_string(layers) + " layers of " + std::to_string(rsmResolution / 2) + " texels need a " +
         std::to_string(width) + "-texel-wide atlas, above the GL limit of " + std::to_string(maxTextureSize) +
         "; lower rsm.resolution or lrsm.depth-splits / lrsm.normal-splits";
}

LayerBase buildLayersCpu(const LayerLayout& layout, int rsmSize, const std::vector<float>& depth,
                         const std::vector<float>& ndotl, const std::vector<glm::vec3>& normal,
                         const std::vector<glm::vec3>& radiance, const std::vector<uint8_t>& valid) {
  LayerBase out;
  out.width = rsmSize / 2;
  out.layers = layout.count();
  const size_t atlas = size_t(out.width) * out.layers * out.width;
  out.radiance.assign(atlas, glm::vec4(0.0f));
  out.normal.assign(atlas, glm::vec4(0.0f));
  out.depth.assign(atlas, glm::vec4(0.0f));
  out.layerId.assign(size_t(rsmSize) * rsmSize, uint8_t(255));
  for (int y = 0; y < rsmSize; ++y)
    for (int x = 0; x < rsmSize; ++x) {
      const size_t i = size_t(y) * rsmSize + x;
      if (!valid[i]) continue;
      const int l = layout.classify(depth[i], ndotl[i]);
      out.layerId[i] = uint8_t(l);
      const int d = l / layout.normalIntervals();
      const float z = std::clamp(layout.warp(d, depth[i]), 0.0f, 1.0f);
      const size_t a = size_t(y / 2) * out.width * out.layers + size_t(l) * out.width + size_t(x / 2);
      out.radiance[a] += glm::vec4(radiance[i], 1.0f) * 0.25f;
      out.normal[a] += glm::vec4(normal[i], 1.0f) * 0.25f;
      out.depth[a] += glm::vec4(z, z * z, z * z * z, z * z * z * z) * 0.25f;
    }
  return out;
}

}  // namespace voxlab::lrsm
