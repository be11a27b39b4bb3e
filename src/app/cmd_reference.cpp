// voxlab reference: the CPU reference path tracer (ground truth for every technique).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "app/command.h"
#include "core/args.h"
#include "core/error.h"
#include "core/progress.h"
#include "reference/image_io.h"
#include "reference/path_tracer.h"
#include "scene/scene.h"

namespace voxlab {
namespace {

float parseRadius(const std::string& text) {
  if (text == "inf" || text == "infinite") return INFINITY;
  char* end = nullptr;
  float v = std::strtof(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !(v > 0.0f))
    throw Error("--ao-radius '" + text + "' is not a positive number or 'inf'");
  return v;
}

// --sky L: a constant environment radiance (W/(m^2 sr)), grey, not negative.
float parseSky(const std::string& text) {
  char* end = nullptr;
  float v = std::strtof(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !(v >= 0.0f) || !std::isfinite(v))
    throw Error("--sky '" + text + "' is not valid; valid: a radiance >= 0 in W/(m^2 sr) (0 = no sky)");
  return v;
}

int runReference(const std::vector<std::string>& argv) {
  Args args("reference", argv,
            {{"--scene", true, false, "scene name in scenes/ or a .gltf/.glb path"},
             {"--camera", true, false, "camera name (default: the scene's first camera)"},
             {"--size", true, false, "image size WxH (default 512x512)"},
             {"--spp", true, false, "samples per pixel, 1..1000000"},
             {"--mode", true, false, "full, direct, one-bounce, two-bounce, indirect, indirect-K (K = 1..8 indirect bounces) or ao (default full)"},
             {"--ao-radius", true, false, "ao mode: maximum occluder distance (default inf)"},
             {"--sky", true, false, "constant sky radiance seen by rays that leave the scene, W/(m^2 sr) (default: the scene's own, 0 unless its glTF scene extras set sky_radiance)"},
             {"--threads", true, false, "worker threads (default: $VOXLAB_THREADS or all cores)"},
             {"--seed", true, false, "random sequence, 0..2^31-1 (default 0)"},
             {"--jitter", false, false, "jitter rays within each pixel instead of the centre"},
             {"--no-stderr", false, false, "do not write FILE.stderr.exr"},
             {"--half", false, false, "store half floats (16-bit) in the EXR files instead of 32-bit floats"},
             {"--quiet", false, false, "no progress output"},
             {"--out", true, false, "output EXR file"}});
  std::string sceneArg = args.require("--scene");
  std::string out = args.require("--out");
  if (out.size() < 4 || out.compare(out.size() - 4, 4, ".exr") != 0)
    throw Error("--out '" + out + "' must end in .exr");
  reference::ReferenceSettings st;
  st.spp = Args::parseInt("--spp", args.require("--spp"), 1, 1000000);
  st.mode = reference::parseMode(args.get("--mode", "full"));
  if (args.has("--size")) Args::parseSize(args.get("--size"), st.width, st.height);
  if (args.has("--ao-radius")) {
    if (st.mode != reference::Mode::AO) throw Error("--ao-radius only applies to --mode ao");
    st.aoRadius = parseRadius(args.get("--ao-radius"));
  }
  if (args.has("--threads")) st.threads = Args::parseInt("--threads", args.get("--threads"), 1, 4096);
  if (args.has("--seed")) st.seed = uint64_t(Args::parseInt("--seed", args.get("--seed"), 0, 2147483647));
  st.pixelJitter = args.has("--jitter");
  st.computeStdErr = !args.has("--no-stderr");

  Scene scene = loadScene(resolveScenePath(sceneArg));
  if (auto cam = args.find("--camera")) {
    std::vector<std::string> names;
    int found = -1;
    for (size_t i = 0; i < scene.cameras.size(); ++i) {
      names.push_back(scene.cameras[i].name);
      if (scene.cameras[i].name == *cam && found < 0) found = int(i);
    }
    if (found < 0)
      throw Error("scene '" + scene.name + "' has no camera '" + *cam + "'; its cameras: " + joinNames(names));
    st.cameraIndex = found;
  }
  ProgressBar progress("reference", true);
  if (!args.has("--quiet")) st.progress = [&](double f) { progress.update(f); };

  const float sky = args.has("--sky") ? parseSky(args.get("--sky")) : scene.skyRadiance;
  reference::ReferenceTracer tracer(scene);
  tracer.setSkyRadiance(glm::vec3(sky));
  reference::RenderStats stats;
  reference::Image img = tracer.render(st, &stats);
  if (!args.has("--quiet")) progress.finish();

  std::string camName = scene.cameras[size_t(st.cameraIndex)].name;
  // Mean of the per-pixel standard error over every pixel and channel: the noise level of the
  // image in one number (the comparison tolerances are set well above it).
  // The RMS is what adds (in quadrature) to an RMSE measured against this image.
  double meanStdErr = 0.0, msStdErr = 0.0;
  for (float v : img.stdErr) {
    meanStdErr += double(v);
    msStdErr += double(v) * double(v);
  }
  if (!img.stdErr.empty()) {
    meanStdErr /= double(img.stdErr.size());
    msStdErr /= double(img.stdErr.size());
  }
  char meanBuf[32], rmsBuf[32];
  std::snprintf(meanBuf, sizeof meanBuf, "%.6g", meanStdErr);
  std::snprintf(rmsBuf, sizeof rmsBuf, "%.6g", std::sqrt(msStdErr));
  reference::ImageAttributes attrs = {
      {"voxlab:spp", std::to_string(st.spp), true},
      {"voxlab:mode", reference::modeName(st.mode), false},
      {"voxlab:scene", scene.name, false},
      {"voxlab:camera", camName, false},
      {"voxlab:camera_index", std::to_string(st.cameraIndex), true},
      {"voxlab:seed", std::to_string(st.seed), true},
      {"voxlab:pixel_filter", st.pixelJitter ? "box (jittered)" : "centre", false}};
  if (sky > 0.0f) attrs.push_back({"voxlab:sky_radiance", std::to_string(sky), false});
  if (st.mode == reference::Mode::AO)
    attrs.push_back({"voxlab:ao_radius", std::isinf(st.aoRadius) ? "inf" : std::to_string(st.aoRadius), false});
  if (st.computeStdErr && st.spp > 1) {
    attrs.push_back({"voxlab:mean_stderr", meanBuf, false});
    attrs.push_back({"voxlab:rms_stderr", rmsBuf, false});
  }
  const bool half = args.has("--half");
  reference::writeExr(out, img, attrs, half);
  std::string errPath;
  if (st.computeStdErr) {
    reference::Image se(img.width, img.height);
    se.rgb = img.stdErr;
    auto seAttrs = attrs;
    seAttrs.push_back({"voxlab:content", "standard error of the mean per pixel", false});
    errPath = reference::stdErrPathFor(out);
    reference::writeExr(errPath, se, seAttrs, half);
  }
  std::printf("wrote %s (%dx%d, %d spp, mode %s, camera '%s')%s%s\n", out.c_str(), img.width,
              img.height, st.spp, reference::modeName(st.mode).c_str(), camName.c_str(),
              errPath.empty() ? "" : " and ", errPath.c_str());
  if (st.computeStdErr && st.spp > 1)
    std::printf("standard error over every pixel and channel: mean %s, rms %s\n", meanBuf, rmsBuf);
  std::printf("%.2f s on %d threads, %.3g rays, %.2f Mrays/s, %.3f s per spp\n", stats.seconds,
              stats.threads, double(stats.rays), stats.raysPerSecond() / 1e6, stats.seconds / st.spp);
  return 0;
}

}  // namespace

VOXLAB_REGISTER_COMMAND("reference",
                         "voxlab reference --scene S [--camera NAME] [--size WxH] --spp N "
                         "[--mode full|direct|one-bounce|two-bounce|indirect|indirect-K|ao] [--ao-radius R] [--threads N] "
                         "[--seed N] [--jitter] [--no-stderr] [--half] [--quiet] --out FILE.exr",
                         "render a ground-truth image with the CPU reference path tracer (Embree)",
                         &runReference);

}  // namespace voxlab
