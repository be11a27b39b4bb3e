#include "run/temporal_reference.h"

#include <chrono>
#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "reference/image_io.h"
#include "reference/path_tracer.h"
#include "scene/animation.h"
#include "scene/scene.h"

namespace voxlab {

namespace {

namespace fs = std::filesystem;

double meanOf(const reference::Image& img) {
  double sum = 0.0;
  for (float v : img.rgb) sum += double(v);
  return img.rgb.empty() ? 0.0 : sum / double(img.rgb.size());
}

double meanAbsoluteChange(const reference::Image& a, const reference::Image& b) {
  double sum = 0.0;
  const size_t n = std::min(a.rgb.size(), b.rgb.size());
  for (size_t i = 0; i < n; ++i) sum += std::abs(double(a.rgb[i]) - double(b.rgb[i]));
  return n ? sum / double(n) : 0.0;
}

}  // namespace

TemporalReference temporalReference(const std::string& sceneArgument, int frames, int width, int height, int spp,
                                    const std::string& cacheDir) {
  if (frames < 1) throw Error("the reference animation needs 1 frame or more");
  SceneAnimation animation;
  Scene scene = loadScene(resolveScenePath(sceneArgument), animation);
  TemporalReference ref;
  ref.scene = scene.name;
  ref.width = width;
  ref.height = height;
  ref.spp = spp;
  ref.frames = frames;
  const fs::path dir = fs::path(cacheDir) / scene.name /
                       (std::to_string(width) + "x" + std::to_string(height) + "-" + std::to_string(spp) + "spp-" +
                        std::to_string(frames) + "frames");
  fs::create_directories(dir);
  const auto start = std::chrono::steady_clock::now();
  bool rendered = false;
  // Frame k (seed 0), or frame 0 with seed 1 for the noise floor: from the cache, else rendered.
  auto frame = [&](int k, uint64_t seed) {
    const fs::path file = dir / ((k < 10 ? "000" : k < 100 ? "00" : "0") + std::to_string(k) +
                                 (seed ? "-seed" + std::to_string(seed) : "") + ".exr");
    if (fs::exists(file)) return reference::readExr(file.string());
    const double t = frames > 1 ? double(animation.duration) * double(k) / double(frames - 1) : 0.0;
    poseScene(scene, animation, float(t));
    reference::ReferenceTracer tracer(scene);
    tracer.setSkyRadiance(glm::vec3(scene.skyRadiance));
    reference::ReferenceSettings st;
    st.width = width;
    st.height = height;
    st.spp = spp;
    st.seed = seed;
    st.computeStdErr = false;
    reference::Image img = tracer.render(st);
    reference::writeExr(file.string(), img, {{"voxlab:scene", scene.name, false}, {"voxlab:spp", std::to_string(spp), true},
                                             {"voxlab:seed", std::to_string(seed), true}, {"voxlab:time", std::to_string(t), false}});
    rendered = true;
    return img;
  };
  reference::Image previous;
  double flickerSum = 0.0;
  for (int k = 0; k < frames; ++k) {
    reference::Image img = frame(k, 0);
    ref.energy.push_back(meanOf(img));
    if (k > 0) {
      ref.flicker.push_back(meanAbsoluteChange(img, previous));
      flickerSum += ref.flicker.back();
    }
    if (k == 0) ref.noiseFloor = meanAbsoluteChange(img, frame(0, 1));
    previous = std::move(img);
  }
  ref.meanFlicker = ref.flicker.empty() ? 0.0 : flickerSum / double(ref.flicker.size());
  if (rendered) ref.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return ref;
}

}  // namespace voxlab
