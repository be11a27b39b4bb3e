// Comparing an image A against a reference B (same size, float RGB, linear).
//
// Definitions (over all pixels and the three channels unless stated):
//   rmse    sqrt(mean((a - b)^2))
//   psnr    20 log10(peak / rmse) dB, peak = the largest value in the reference B (1 when B has
//           no positive value); +infinity when rmse = 0
//   mae     mean |a - b|
//   mre     mean |a - b| / (|b| + 0.01)   (epsilon 0.01 keeps black reference pixels finite)
//   max_abs max |a - b|
//   ssim    mean SSIM (Wang et al. 2004) of the luminances Y = 0.2126 R + 0.7152 G + 0.0722 B,
//           each clamped to [0, 1] (dynamic range 1, so C1 = 0.01^2, C2 = 0.03^2), with an 11x11
//           Gaussian window (sigma 1.5) at every position where the window fits inside the image;
//           images smaller than 11 pixels in either direction use one window over the whole image
//           with equal weights
//   dssim   (1 - ssim) / 2, so that every "--fail-above" metric grows with the error
// Non-finite values (NaN, Inf) in either image make every metric NaN, which fails any threshold.
#pragma once
#include <string>
#include <vector>

#include "reference/image.h"

namespace voxlab::reference {

struct ImageMetrics {
  double rmse = 0.0;
  double psnr = 0.0;
  double mae = 0.0;
  double mre = 0.0;
  double maxAbs = 0.0;
  double ssim = 1.0;
  double dssim = 0.0;
  double peak = 1.0;        // the PSNR peak (max of the reference)
  size_t nonFinite = 0;     // values that were NaN or Inf in A or B
};

// Throws voxlab::Error when the sizes differ: "image sizes differ: A is WxH, B is WxH".
ImageMetrics computeMetrics(const Image& a, const Image& b);

// Names accepted by metricValue (and by "voxlab compare --fail-above/--fail-below").
std::vector<std::string> metricNames();  // rmse, psnr, mae, mre, max_abs, ssim, dssim
// Throws voxlab::Error listing metricNames() for an unknown name.
double metricValue(const ImageMetrics& m, const std::string& name);
// {"rmse": ..., ...}; an infinite PSNR is written as null (JSON has no infinity).
std::string metricsJson(const ImageMetrics& m);

// The perceptual false-colour ramp used for error images: t in [0,1] -> linear RGB. Built in
// CIELAB with lightness rising linearly from L* 12 to L* 95 while the hue turns from violet-blue
// through teal and green to yellow, so brighter always means larger error (also in grey scale).
void errorColor(float t, float rgb[3]);

// Per-pixel luminance of |a - b| mapped through errorColor with t = min(value / scale, 1).
// scale <= 0 means the 99th percentile of those values (so a few extreme pixels, e.g. at a light,
// do not turn the rest dark; the max when the percentile is 0; 1 when all are 0). The scale used
// goes to *usedScale.
Image errorImage(const Image& a, const Image& b, float scale = 0.0f, float* usedScale = nullptr);

}  // namespace voxlab::reference
