// The constant sky: an environment radiance L that every ray or cone leaving the
// scene sees. The reference path tracer is validated with the sky furnace (an albedo-1 object
// under a uniform sky L has radiance L everywhere: whatever a path hits reflects all of it, and
// every path ends in the sky); vct-grid's cones, whose escaping transmittance sees L
// (shaders/common/cone_trace.glsl), are checked against the tracer's once-reflected sky.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "core/paths.h"
#include "graph/reference_mode.h"
#include "graph/technique.h"
#include "reference/analytic_scenes.h"
#include "reference/path_tracer.h"
#include "scene/scene.h"
#include "techniques/common/sky.h"
#include "test_support.h"

namespace voxlab {
namespace {

constexpr float kPi = 3.14159265358979f;
const glm::vec3 kSky(0.7f, 0.4f, 0.2f);  // a colour, so each channel is its own check

// An albedo-`rho` floor (2 x 2 m) with a closed 0.6 m box on it, both reflecting on both sides:
// the box's walls and the floor see each other (paths of many reflections), and the camera sees
// the sky around them. No lights: the sky is the only emitter.
Scene floorAndBox(float rho) {
  reference::analytic::SceneBuilder b("sky-furnace");
  uint32_t m = b.material("white", glm::vec3(rho));
  const glm::vec3 up(0, 1, 0);
  b.quad({-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}, m, up);
  const glm::vec3 lo(-0.3f, 0.0f, -0.3f), hi(0.3f, 0.6f, 0.3f);
  b.quad({lo.x, hi.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}, m, up);
  b.quad({lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}, m, {0, 0, 1});
  b.quad({lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z}, m, {0, 0, -1});
  b.quad({hi.x, lo.y, lo.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {hi.x, hi.y, lo.z}, m, {1, 0, 0});
  b.quad({lo.x, lo.y, lo.z}, {lo.x, lo.y, hi.z}, {lo.x, hi.y, hi.z}, {lo.x, hi.y, lo.z}, m, {-1, 0, 0});
  b.camera("camera", {0.0f, 1.4f, 2.2f}, glm::normalize(glm::vec3(0.0f, -1.1f, -2.2f)), up, 0.9f);
  return b.build();
}

reference::Image render(const reference::ReferenceTracer& tracer, reference::Mode mode, int spp) {
  reference::ReferenceSettings st;
  st.mode = mode;
  st.spp = spp;
  st.width = st.height = 24;
  st.threads = 2;
  return tracer.render(st);
}

TEST(Sky, ReferenceFurnaceAlbedoOneHasRadianceLEverywhere) {
  Scene scene = floorAndBox(1.0f);
  ASSERT_TRUE(scene.lights.empty());
  reference::ReferenceTracer tracer(scene);
  tracer.setSkyRadiance(kSky);
  reference::Image full = render(tracer, reference::Mode::Full, 64);
  // Every pixel and channel within 5 standard errors of L (plus float rounding). The estimate's
  // noise comes from Russian roulette (albedo 1: continuation 0.95, weight 1/0.95) on paths that
  // bounce between the box and the floor; the sky itself is carried exactly by cosine sampling.
  // Measured (24x24, 64 spp): 225 of the 1728 values have any noise, worst |mean - L| / stderr
  // 2.17 among them, mean stderr 1e-4; the others are L to float rounding (1e-5 relative).
  double worstZ = 0.0, sumErr = 0.0;
  size_t noisy = 0;
  for (int y = 0; y < full.height; ++y)
    for (int x = 0; x < full.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const size_t i = (size_t(y) * full.width + x) * 3 + c;
        const double err = std::abs(double(full.rgb[i]) - kSky[c]);
        const double se = full.stdErr[i];
        sumErr += se;
        if (se > 0.0) {
          ++noisy;
          worstZ = std::max(worstZ, err / se);
        }
        EXPECT_LE(err, 5.0 * se + 1e-5 * kSky[c]) << "pixel " << x << "," << y << " channel " << c;
      }
  std::printf("sky furnace: worst |mean - L| / stderr %.2f over %zu noisy values, mean stderr %.4f\n", worstZ, noisy,
              sumErr / double(full.rgb.size()));
  // The check is not vacuous: many pixels see the box and floor, and once-reflected sky (counted
  // as indirect-1: the sky is light already reflected once) is darker than L wherever the box
  // hides part of the sky, so the rest of L comes from paths of several reflections.
  reference::Image direct = render(tracer, reference::Mode::IndirectOne, 64);
  size_t darker = 0;
  for (size_t i = 0; i < direct.rgb.size(); i += 3)
    if (direct.rgb[i] < kSky.x - 5.0f * direct.stdErr[i] - 1e-3f) ++darker;
  // Measured: 29 of 576 pixels (the floor around the box, the box's lower walls).
  EXPECT_GE(darker, 20u) << "pixels whose one reflection sees less than the whole sky";
  // An open surface above everything receives E = pi L (cosine sampling: every ray escapes).
  reference::Estimate e = tracer.estimateIrradiance({0.0f, 2.0f, 0.0f}, {0, 1, 0}, reference::Mode::Full, 256);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(e.mean[c], kPi * kSky[c], 1e-5 * kPi * kSky[c]);
  // And albedo 0.5 is darker than L: the furnace answer is albedo 1's.
  Scene grey = floorAndBox(0.5f);
  reference::ReferenceTracer greyTracer(grey);
  greyTracer.setSkyRadiance(kSky);
  reference::Estimate floor = greyTracer.estimateRadiance({0.0f, 1.4f, 2.2f}, glm::vec3(0.0f, 0.0f, 0.5f) - glm::vec3(0.0f, 1.4f, 2.2f),
                                                          reference::Mode::Full, 4096);
  EXPECT_LT(floor.mean.x, 0.5 * kSky.x + 1e-3);
}

TEST(Sky, ReferenceWithoutSkyIsUnchanged) {
  Scene scene = floorAndBox(1.0f);
  reference::ReferenceTracer tracer(scene);
  EXPECT_EQ(tracer.skyRadiance(), glm::vec3(0.0f));
  reference::Image full = render(tracer, reference::Mode::Full, 4);
  for (float v : full.rgb) EXPECT_EQ(v, 0.0f);  // no emitter at all
  EXPECT_THROW(tracer.setSkyRadiance(glm::vec3(-1.0f)), Error);
}

// vct-grid on the lightless blocks with the light switched off: the only light is the sky, which
// the diffuse cones see once (indirect-diffuse = albedo x the cone-weighted escaping sky). The
// reference's indirect-1 mode is the same quantity exactly: the sky reflected once (the tracer
// counts the sky as light already reflected once, as the cones gather it).
TEST(Sky, VctGridConesSeeTheSkyTheReferenceSees) {
  const float L = 0.5f;
  RunRequest r;
  r.technique = "vct-grid";
  r.scene = projectPath("tests/data/scenes/no-light-blocks.gltf");
  r.width = r.height = 64;
  r.sets = {"voxel.resolution=64", "cone.resolution=full", "light.0.intensity=0", "sky.radiance=0.5"};
  r.lookFrom = glm::vec3(0.0f, 2.2f, 2.2f);  // from above at 45 degrees: mostly floor and block tops
  r.lookAt = glm::vec3(0.0f);
  // One session at a time: capture everything from one before the next starts.
  HeadlessSession& s = testing_support::session(r);
  const LevelData P = testing_support::capture(s, "gbuffer", "position").levels.at(0);
  const LevelData N = testing_support::capture(s, "gbuffer", "normal").levels.at(0);
  const LevelData I = testing_support::capture(s, "cone-trace", "indirect-diffuse").levels.at(0);
  RunRequest dark = r;
  dark.sets = {"voxel.resolution=64", "cone.resolution=full", "light.0.intensity=0"};
  HeadlessSession& d = testing_support::session(dark);
  const LevelData I0 = testing_support::capture(d, "cone-trace", "indirect-diffuse").levels.at(0);

  Scene scene = loadScene(r.scene);
  for (Light& l : scene.lights) l.intensity = 0.0f;
  reference::ReferenceTracer tracer(scene);
  tracer.setSkyRadiance(glm::vec3(L));
  const Camera cam = requestCamera(scene, r);
  double gpu = 0.0, ref = 0.0, worst = 0.0;
  int points = 0;
  for (int y = 2; y < P.size.y; y += 4)
    for (int x = 2; x < P.size.x; x += 4) {
      if (P.at(x, y, 0, 3) < 0.5f) continue;  // background
      EXPECT_EQ(I0.at(x, y, 0, 0), 0.0f) << "without the sky there is no light";
      const glm::vec3 p(P.at(x, y, 0, 0), P.at(x, y, 0, 1), P.at(x, y, 0, 2));
      const glm::vec3 n(N.at(x, y, 0, 0), N.at(x, y, 0, 1), N.at(x, y, 0, 2));
      if (glm::dot(n, cam.position - p) <= 0.0f) continue;
      // The tracer's once-reflected sky at the surface point the pixel sees (its ray from the
      // camera through p), red channel.
      reference::Estimate e = tracer.estimateRadiance(cam.position, p - cam.position, reference::Mode::IndirectOne, 256,
                                                      uint64_t(y * 64 + x));
      const double g = I.at(x, y, 0, 0), t = e.mean.x;
      gpu += g;
      ref += t;
      worst = std::max(worst, std::abs(g - t) / std::max(t, 1e-3));
      ++points;
    }
  ASSERT_GT(points, 100);
  const double ratio = gpu / ref;
  std::printf("vct-grid sky vs reference (once reflected): %d points, mean ratio %.3f, worst relative %.3f\n", points,
              ratio, worst);
  // Cones approximate the visible sky. Measured (64^3, 126 points): mean ratio 1.028 at vct-grid's
  // defaults (HDR voxels, anisotropic volumes showing only their surfaces' fronts), worst point 40 %
  // off; 0.813 when the directional volumes showed every voxel in every direction (grazing cones
  // found the floor they leave opaque); 1.058 with isotropic mips; 1.031 with the former defaults
  // (isotropic, six 60-degree cones, one edge). The ratio is deterministic (the tracer's seeds are
  // fixed per pixel, the cones have no noise), so the band is +-0.055 around it: room for small
  // changes of the cones, but it fails a missing or doubled escape term (ratio 0 or about 2) and an
  // escape counted only once a cone's whole sample has left the volume (0.171 when measured at
  // 0.813); the sky added without the cone's remaining transmittance gave 1.142 then, not
  // re-measured since.
  EXPECT_GT(ratio, 0.973);
  EXPECT_LT(ratio, 1.083);
}


// Every technique that has the sky (a stage declares sky.radiance; found from the registry, no
// technique named) on the lightless blocks, light off, sky L = 0.5, seen from above: the only
// light is the sky. Its indirect term (the last output, in stage order, that approximates an
// "indirect" reference mode) against the tracer at the surface points the G-buffer sees; the
// background of its combined and final images against L; and without the sky, nothing at all.
// The tracer counts the sky as light already reflected once, as the techniques gather it, so each
// term is compared with the tracer in the term's own mode: "indirect-1" (one gather) holds the
// sky reflected once, "indirect-K" (voxel-path-tracing's paths of K bounces) the sky reflected
// 1..K times.
struct SkyTerm {
  int stage = -1;
  const OutputDesc* output = nullptr;
};
SkyTerm indirectTerm(const Technique& t) {
  SkyTerm term;
  for (int i = 0; i < t.stageCount(); ++i)
    for (const OutputDesc& o : t.decl(i).outputs)
      if (o.kind == OutputKind::Image2D && o.referenceMode.rfind("indirect", 0) == 0) term = {i, &o};
  return term;
}
const OutputDesc* finalStageOutput(const Technique& t, const std::string& referenceMode) {
  for (const OutputDesc& o : t.decl(t.stageIndex(t.finalStage())).outputs)
    if (o.referenceMode == referenceMode) return &o;
  return nullptr;
}
bool declaresSky(const Technique& t) {
  for (int i = 0; i < t.stageCount(); ++i)
    for (const ParamDesc& p : t.decl(i).params)
      if (p.name == kSkyRadiance) return true;
  return false;
}

TEST(Sky, EveryTechniqueWithTheSkySeesTheSkyTheReferenceSees) {
  const float L = 0.5f;
  const std::string scenePath = projectPath("tests/data/scenes/no-light-blocks.gltf");
  Scene scene = loadScene(scenePath);
  for (Light& l : scene.lights) l.intensity = 0.0f;
  reference::ReferenceTracer tracer(scene);
  tracer.setSkyRadiance(glm::vec3(L));
  std::map<std::pair<int, std::string>, double> referenceAt;  // (pixel index, mode name) -> red channel
  std::vector<std::string> withSky;
  for (const std::string& id : techniqueIds()) {
    auto technique = createTechnique(id);
    if (!declaresSky(*technique)) continue;
    withSky.push_back(id);
    SCOPED_TRACE(id);
    const SkyTerm term = indirectTerm(*technique);
    ASSERT_NE(term.output, nullptr) << "a technique with the sky has an output approximating an indirect mode";
    const OutputDesc* combinedDesc = finalStageOutput(*technique, "full");
    ASSERT_NE(combinedDesc, nullptr) << "the final stage has the combined (full) image";
    const std::string termStage = technique->stage(term.stage).id();
    const std::string finalStage = technique->finalStage();
    const ParamSet defaults = technique->defaultParams();
    // The term's mode at the defaults the run uses (voxel-path-tracing: indirect-{paths.bounces}).
    const reference::Mode mode = reference::parseMode(referenceModeUnder(*term.output, defaults));
    const float exposure = defaults.has("composite.exposure") ? defaults.getFloat("composite.exposure") : 1.0f;

    RunRequest r;
    r.technique = id;
    r.scene = scenePath;
    r.width = r.height = 64;
    r.sets = {"light.0.intensity=0", std::string(kSkyRadiance) + "=0.5"};
    r.lookFrom = glm::vec3(0.0f, 2.2f, 2.2f);  // from above at 45 degrees: floor, block tops, background
    r.lookAt = glm::vec3(0.0f);
    HeadlessSession& s = testing_support::session(r);
    const LevelData P = testing_support::capture(s, "gbuffer", "position").levels.at(0);
    const LevelData N = testing_support::capture(s, "gbuffer", "normal").levels.at(0);
    const LevelData I = testing_support::capture(s, termStage, term.output->name).levels.at(0);
    const LevelData C = testing_support::capture(s, finalStage, combinedDesc->name).levels.at(0);
    const LevelData F = testing_support::capture(s, finalStage, technique->finalOutput()).levels.at(0);
    RunRequest dark = r;
    dark.sets = {"light.0.intensity=0"};
    HeadlessSession& d = testing_support::session(dark);
    const LevelData I0 = testing_support::capture(d, termStage, term.output->name).levels.at(0);
    const LevelData F0 = testing_support::capture(d, finalStage, technique->finalOutput()).levels.at(0);
    // Colour channels only (alpha is 1 where written).
    auto black = [](const LevelData& image) {
      for (size_t i = 0; i < image.values.size(); ++i)
        if (int(i % size_t(image.channels)) < 3 && image.values[i] != 0.0f) return false;
      return true;
    };
    EXPECT_TRUE(black(I0)) << "without the sky there is no light";
    EXPECT_TRUE(black(F0)) << "without the sky the final image is black";

    // The traced image may be smaller (half resolution): traced pixel (x, y) shades G-buffer
    // pixel (x, y) * scale.
    const int scale = P.size.x / I.size.x;
    ASSERT_EQ(P.size.x, I.size.x * scale);
    const Camera cam = requestCamera(scene, r);
    double gpu = 0.0, ref = 0.0;
    int points = 0, background = 0;
    for (int y = 2; y < P.size.y; y += 4)
      for (int x = 2; x < P.size.x; x += 4) {
        if (P.at(x, y, 0, 3) < 0.5f) {
          // The background: L in the combined image, tonemapped in the final one (8 bits).
          ++background;
          EXPECT_NEAR(C.at(x, y, 0, 0), L, 1e-3f) << "background pixel " << x << "," << y;
          const float mapped = exposure * L;
          EXPECT_NEAR(F.at(x, y, 0, 0), mapped / (1.0f + mapped), 1.0f / 255.0f) << "background pixel " << x << "," << y;
          continue;
        }
        if ((x / scale) * scale != x || (y / scale) * scale != y) continue;  // not a traced pixel's surface
        const glm::vec3 p(P.at(x, y, 0, 0), P.at(x, y, 0, 1), P.at(x, y, 0, 2));
        const glm::vec3 n(N.at(x, y, 0, 0), N.at(x, y, 0, 1), N.at(x, y, 0, 2));
        if (glm::dot(n, cam.position - p) <= 0.0f) continue;
        const int pixel = y * P.size.x + x;
        auto cached = referenceAt.find({pixel, reference::modeName(mode)});
        if (cached == referenceAt.end()) {
          reference::Estimate e =
              tracer.estimateRadiance(cam.position, p - cam.position, mode, 256, uint64_t(pixel));
          cached = referenceAt.emplace(std::make_pair(pixel, reference::modeName(mode)), double(e.mean.x)).first;
        }
        gpu += I.at(x / scale, y / scale, 0, 0);
        ref += cached->second;
        ++points;
      }
    ASSERT_GT(points, 20);
    ASSERT_GT(background, 20);
    const double ratio = gpu / ref;
    std::printf("%s: sky in %s/%s vs reference %s: %d points, mean ratio %.3f\n", id.c_str(), termStage.c_str(),
                term.output->name.c_str(), reference::modeName(mode).c_str(), points, ratio);
    // Each technique approximates the visible sky its own way. Measured (64x64 at the defaults,
    // 126 points, mean ratio): clipmap 0.991, lrsm 0.913, near-field 0.765 (rays that end at the
    // radius inside the scene's bounds see no sky: the far field), svo 1.102 (isotropic mips),
    // vct-grid 0.812 (anisotropic mips, see the test above), voxel-path-tracing 0.981 (against
    // indirect-2: the sky reflected once or twice). One band for all: it fails a missing sky
    // (0), a doubled one (1.5 or more) and, for the cone tracers, a cone that sees the sky only
    // once its whole sample has left the volume (vct-grid 0.171; clipmap 0.560 when a cone that
    // ends at its full length outside the scene's bounds sees none).
    EXPECT_GT(ratio, 0.7);
    EXPECT_LT(ratio, 1.2);
  }
  std::printf("techniques with the sky: %zu\n", withSky.size());
  EXPECT_GE(withSky.size(), 2u) << "vct-grid and at least one more technique declare the sky";
}

}  // namespace
}  // namespace voxlab
