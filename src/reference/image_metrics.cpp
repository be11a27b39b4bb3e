#include "reference/image_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/error.h"

namespace voxlab::reference {

namespace {

void checkSizes(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height)
    throw Error("image sizes differ: A is " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                ", B is " + std::to_string(b.width) + "x" + std::to_string(b.height));
  if (a.rgb.size() != a.pixelCount() * 3 || b.rgb.size() != b.pixelCount() * 3)
    throw Error("image has a wrong number of values for its size");
  if (a.pixelCount() == 0) throw Error("images have no pixels");
}

std::vector<double> clampedLuminance(const Image& img) {
  std::vector<double> y(img.pixelCount());
  for (size_t i = 0; i < y.size(); ++i)
    y[i] = std::clamp(double(luminance(&img.rgb[i * 3])), 0.0, 1.0);
  return y;
}

double ssimLuminance(const Image& a, const Image& b) {
  const double C1 = 0.01 * 0.01, C2 = 0.03 * 0.03;
  std::vector<double> x = clampedLuminance(a), y = clampedLuminance(b);
  int W = a.width, H = a.height;
  auto ssimOf = [&](double mx, double my, double sxx, double syy, double sxy) {
    return ((2 * mx * my + C1) * (2 * sxy + C2)) / ((mx * mx + my * my + C1) * (sxx + syy + C2));
  };
  constexpr int K = 11;
  if (W < K || H < K) {
    double n = double(x.size()), mx = 0, my = 0;
    for (size_t i = 0; i < x.size(); ++i) { mx += x[i]; my += y[i]; }
    mx /= n; my /= n;
    double sxx = 0, syy = 0, sxy = 0;
    for (size_t i = 0; i < x.size(); ++i) {
      sxx += (x[i] - mx) * (x[i] - mx);
      syy += (y[i] - my) * (y[i] - my);
      sxy += (x[i] - mx) * (y[i] - my);
    }
    return ssimOf(mx, my, sxx / n, syy / n, sxy / n);
  }
  double w[K], wsum = 0;
  for (int i = 0; i < K; ++i) { w[i] = std::exp(-0.5 * (i - 5) * (i - 5) / (1.5 * 1.5)); wsum += w[i]; }
  for (double& v : w) v /= wsum;
  // Separable filtering, 'valid' region only: first along x (for every row), then along y.
  int Wv = W - K + 1, Hv = H - K + 1;
  const int F = 5;  // x, y, xx, yy, xy
  std::vector<double> rows(size_t(F) * Wv * H);
  for (int r = 0; r < H; ++r)
    for (int c = 0; c < Wv; ++c) {
      double acc[F] = {0, 0, 0, 0, 0};
      for (int k = 0; k < K; ++k) {
        size_t i = size_t(r) * W + c + k;
        double xv = x[i], yv = y[i];
        acc[0] += w[k] * xv; acc[1] += w[k] * yv;
        acc[2] += w[k] * xv * xv; acc[3] += w[k] * yv * yv; acc[4] += w[k] * xv * yv;
      }
      for (int f = 0; f < F; ++f) rows[(size_t(f) * H + r) * Wv + c] = acc[f];
    }
  double total = 0;
  for (int r = 0; r < Hv; ++r)
    for (int c = 0; c < Wv; ++c) {
      double m[F] = {0, 0, 0, 0, 0};
      for (int k = 0; k < K; ++k)
        for (int f = 0; f < F; ++f) m[f] += w[k] * rows[(size_t(f) * H + r + k) * Wv + c];
      total += ssimOf(m[0], m[1], m[2] - m[0] * m[0], m[3] - m[1] * m[1], m[4] - m[0] * m[1]);
    }
  return total / (double(Wv) * Hv);
}

double labF(double t) {  // inverse of the CIELAB companding function
  const double d = 6.0 / 29.0;
  return t > d ? t * t * t : 3 * d * d * (t - 4.0 / 29.0);
}

}  // namespace

ImageMetrics computeMetrics(const Image& a, const Image& b) {
  checkSizes(a, b);
  ImageMetrics m;
  size_t n = a.rgb.size();
  double se = 0, ae = 0, re = 0, mx = 0, peak = 0;
  for (size_t i = 0; i < n; ++i) {
    double av = a.rgb[i], bv = b.rgb[i];
    if (!std::isfinite(av) || !std::isfinite(bv)) { ++m.nonFinite; continue; }
    double d = std::abs(av - bv);
    se += d * d;
    ae += d;
    re += d / (std::abs(bv) + 0.01);
    mx = std::max(mx, d);
    peak = std::max(peak, bv);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  m.peak = peak > 0 ? peak : 1.0;
  if (m.nonFinite) {
    m.rmse = m.psnr = m.mae = m.mre = m.maxAbs = m.ssim = m.dssim = nan;
    return m;
  }
  m.rmse = std::sqrt(se / double(n));
  m.mae = ae / double(n);
  m.mre = re / double(n);
  m.maxAbs = mx;
  m.psnr = m.rmse > 0 ? 20.0 * std::log10(m.peak / m.rmse) : std::numeric_limits<double>::infinity();
  m.ssim = ssimLuminance(a, b);
  m.dssim = (1.0 - m.ssim) / 2.0;
  return m;
}

std::vector<std::string> metricNames() { return {"rmse", "psnr", "mae", "mre", "max_abs", "ssim", "dssim"}; }

double metricValue(const ImageMetrics& m, const std::string& name) {
  if (name == "rmse") return m.rmse;
  if (name == "psnr") return m.psnr;
  if (name == "mae") return m.mae;
  if (name == "mre") return m.mre;
  if (name == "max_abs") return m.maxAbs;
  if (name == "ssim") return m.ssim;
  if (name == "dssim") return m.dssim;
  throw Error("unknown metric '" + name + "'; valid metrics: " + joinNames(metricNames()));
}

std::string metricsJson(const ImageMetrics& m) {
  auto num = [](double v) {
    if (!std::isfinite(v)) return std::string("null");
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return std::string(buf);
  };
  return "{\"rmse\": " + num(m.rmse) + ", \"psnr\": " + num(m.psnr) + ", \"mae\": " + num(m.mae) +
         ", \"mre\": " + num(m.mre) + ", \"max_abs\": " + num(m.maxAbs) + ", \"ssim\": " + num(m.ssim) +
         ", \"dssim\": " + num(m.dssim) + ", \"psnr_peak\": " + num(m.peak) +
         ", \"non_finite\": " + std::to_string(m.nonFinite) + "}";
}

void errorColor(float t, float rgb[3]) {
  double s = std::clamp(double(t), 0.0, 1.0);
  const double pi = 3.14159265358979323846;
  double L = 12.0 + 83.0 * s;
  double hue = (290.0 - 195.0 * s) * pi / 180.0;  // 290 deg (violet-blue) -> 95 deg (yellow)
  double C = 40.0 + 25.0 * s;
  double A = C * std::cos(hue), B = C * std::sin(hue);
  double fy = (L + 16.0) / 116.0, fx = fy + A / 500.0, fz = fy - B / 200.0;
  double X = 0.95047 * labF(fx), Y = labF(fy), Z = 1.08883 * labF(fz);  // D65 white
  double r = 3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z;
  double g = -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z;
  double b = 0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z;
  rgb[0] = float(std::clamp(r, 0.0, 1.0));
  rgb[1] = float(std::clamp(g, 0.0, 1.0));
  rgb[2] = float(std::clamp(b, 0.0, 1.0));
}

Image errorImage(const Image& a, const Image& b, float scale, float* usedScale) {
  checkSizes(a, b);
  Image out(a.width, a.height);
  std::vector<float> e(a.pixelCount());
  float mx = 0.0f;
  for (size_t i = 0; i < e.size(); ++i) {
    float d[3];
    for (int c = 0; c < 3; ++c) d[c] = std::abs(a.rgb[i * 3 + c] - b.rgb[i * 3 + c]);
    e[i] = luminance(d);
    if (std::isfinite(e[i])) mx = std::max(mx, e[i]);
  }
  float s = scale;
  if (!(s > 0.0f)) {  // default: the 99th percentile of the finite errors (else max, else 1)
    std::vector<float> finite;
    finite.reserve(e.size());
    for (float v : e)
      if (std::isfinite(v)) finite.push_back(v);
    s = 0.0f;
    if (!finite.empty()) {
      size_t k = std::min(finite.size() - 1, size_t(0.99 * double(finite.size())));
      std::nth_element(finite.begin(), finite.begin() + long(k), finite.end());
      s = finite[k];
    }
    if (!(s > 0.0f)) s = mx > 0.0f ? mx : 1.0f;
  }
  if (usedScale) *usedScale = s;
  for (size_t i = 0; i < e.size(); ++i) {
    float t = std::isfinite(e[i]) ? e[i] / s : 1.0f;  // non-finite differences show as maximal
    errorColor(t, &out.rgb[i * 3]);
  }
  return out;
}

}  // namespace voxlab::reference
