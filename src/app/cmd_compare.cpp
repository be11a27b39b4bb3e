// voxlab compare: image metrics of A against a reference B, and a false-colour error image.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "app/command.h"
#include "core/args.h"
#include "core/error.h"
#include "reference/image_io.h"
#include "reference/image_metrics.h"

namespace voxlab {
namespace {

struct Threshold {
  std::string metric;
  double value;
  bool above;  // true: fail when metric > value; false: fail when metric < value
};

Threshold parseThreshold(const std::string& option, const std::string& text, bool above) {
  auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw Error(option + " '" + text + "' is not METRIC=VALUE (e.g. rmse=0.05)");
  Threshold t{text.substr(0, eq), 0.0, above};
  std::vector<std::string> valid = above ? std::vector<std::string>{"rmse", "mae", "mre", "max_abs", "dssim"}
                                         : std::vector<std::string>{"psnr", "ssim"};
  bool ok = false;
  for (const auto& v : valid) ok = ok || v == t.metric;
  if (!ok)
    throw Error(option + ": unknown metric '" + t.metric + "'; valid metrics: " + joinNames(valid) +
                (above ? " (psnr and ssim take --fail-below)" : " (error metrics take --fail-above)"));
  char* end = nullptr;
  std::string num = text.substr(eq + 1);
  t.value = std::strtod(num.c_str(), &end);
  if (*end != '\0' || !std::isfinite(t.value))
    throw Error(option + " '" + text + "': '" + num + "' is not a number");
  return t;
}

int runCompare(const std::vector<std::string>& argv) {
  Args args("compare", argv,
            {{"--out", true, false, "false-colour error image (.exr or .png)"},
             {"--error-scale", true, false, "error mapped to the top of the colour ramp (default: 99th percentile)"},
             {"--fail-above", true, true, "METRIC=VALUE: exit 1 when rmse|mae|mre|max_abs|dssim exceeds it"},
             {"--fail-below", true, true, "METRIC=VALUE: exit 1 when psnr|ssim is below it"},
             {"--json", false, false, "print the metrics as one JSON object"}},
            2);
  if (args.positional().size() != 2) throw Error("'compare' needs two images: A (test) and B (reference)");
  std::vector<Threshold> thresholds;
  for (const auto& t : args.all("--fail-above")) thresholds.push_back(parseThreshold("--fail-above", t, true));
  for (const auto& t : args.all("--fail-below")) thresholds.push_back(parseThreshold("--fail-below", t, false));
  float scale = 0.0f;
  if (args.has("--error-scale")) {
    std::string s = args.get("--error-scale");
    char* end = nullptr;
    scale = std::strtof(s.c_str(), &end);
    if (s.empty() || *end != '\0' || !(scale > 0.0f))
      throw Error("--error-scale '" + s + "' is not a positive number");
  }
  const std::string& pathA = args.positional()[0];
  const std::string& pathB = args.positional()[1];
  reference::Image a = reference::readImage(pathA);
  reference::Image b = reference::readImage(pathB);
  reference::ImageMetrics m = reference::computeMetrics(a, b);

  float usedScale = 0.0f;
  if (args.has("--out")) {
    reference::Image err = reference::errorImage(a, b, scale, &usedScale);
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", usedScale);
    reference::writeImage(args.get("--out"), err,
                          {{"voxlab:error_scale", buf, false},
                           {"voxlab:content", "luminance of |A-B| through the voxlab error colour ramp", false}});
  }

  if (args.has("--json")) {
    std::printf("%s\n", reference::metricsJson(m).c_str());
  } else {
    std::printf("A: %s\nB: %s (reference)\n", pathA.c_str(), pathB.c_str());
    std::printf("rmse     %.6g\n", m.rmse);
    if (std::isinf(m.psnr))
      std::printf("psnr     inf (identical; peak %.6g)\n", m.peak);
    else
      std::printf("psnr     %.3f dB (peak %.6g)\n", m.psnr, m.peak);
    std::printf("mae      %.6g\nmre      %.6g\nmax_abs  %.6g\nssim     %.6f\ndssim    %.6g\n", m.mae, m.mre,
                m.maxAbs, m.ssim, m.dssim);
    if (m.nonFinite) std::printf("non-finite values: %zu (every metric is NaN)\n", m.nonFinite);
    if (args.has("--out")) std::printf("error image: %s (scale %g)\n", args.get("--out").c_str(), usedScale);
  }

  int rc = 0;
  for (const auto& t : thresholds) {
    double v = reference::metricValue(m, t.metric);
    bool pass = t.above ? v <= t.value : v >= t.value;  // NaN fails both
    if (!pass) {
      std::fprintf(stderr, "compare: %s = %.6g is %s the limit %.6g\n", t.metric.c_str(), v,
                   t.above ? "above" : "below", t.value);
      rc = 1;
    }
  }
  return rc;
}

}  // namespace

VOXLAB_REGISTER_COMMAND("compare",
                         "voxlab compare A B [--out diff.exr|diff.png] [--error-scale S] "
                         "[--fail-above METRIC=VALUE]... [--fail-below METRIC=VALUE]... [--json]",
                         "image metrics (rmse, psnr, mae, mre, ssim) of A against reference B",
                         &runCompare);

}  // namespace voxlab
