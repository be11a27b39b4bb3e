// Physics-tier validation of the CPU reference path tracer (src/reference) against analytic
// answers (/work/shared/guide/reference-data.md), plus unit checks of the image metrics and I/O.
//
// Monte Carlo checks assert |estimate - expected| <= 3 standard errors (the estimator's own,
// per channel) + a stated allowance for geometric discretisation. The random numbers are a pure
// function of (key, sample, reflection, dimension), so every estimate here is reproducible
// bit for bit: a 3-sigma check cannot flake; it either holds for this sequence or it does not.
// The measured estimates and standard errors are quoted next to each check (2-core machine).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "core/error.h"
#include "reference/analytic_scenes.h"
#include "reference/image_io.h"
#include "reference/image_metrics.h"
#include "reference/path_tracer.h"

using namespace voxlab;
using namespace voxlab::reference;
namespace an = voxlab::reference::analytic;

namespace {

constexpr double kPi = 3.14159265358979323846;
const int kThreads = 2;

// Per channel: |mean - expected| <= 3 SE + allowance. Prints the numbers for the record.
void expectWithin(const char* what, const Estimate& e, glm::dvec3 expected, double allowance = 0.0) {
  for (int c = 0; c < 3; ++c) {
    double err = std::abs(e.mean[c] - expected[c]);
    std::printf("  %-34s ch%d: estimate %.6f expected %.6f |diff| %.2e SE %.2e (%.2f SE)\n", what, c,
                e.mean[c], expected[c], err, e.stdErr[c], e.stdErr[c] > 0 ? err / e.stdErr[c] : 0.0);
    EXPECT_LE(err, 3.0 * e.stdErr[c] + allowance)
        << what << " channel " << c << ": estimate " << e.mean[c] << " expected " << expected[c]
        << " SE " << e.stdErr[c];
  }
}
void expectWithin(const char* what, const Estimate& e, double expected, double allowance = 0.0) {
  expectWithin(what, e, glm::dvec3(expected), allowance);
}

}  // namespace

// ---- White furnace ------------------------------------------------------------------------------

// Closed box, albedo rho, emission Le on every face: radiance is Le (1 - rho^(k+1)) / (1 - rho)
// after k reflections. Checked for each mode's reflection window from the box centre.
TEST(ReferenceFurnace, ModesMatchPartialSums) {
  const float rho = 0.5f;
  const glm::vec3 le(1.0f, 0.5f, 0.25f);
  Scene s = an::furnaceBox(rho, le);
  ReferenceTracer tracer(s);
  glm::vec3 dir = glm::normalize(glm::vec3(0.3f, -0.2f, -1.0f));
  struct Case { Mode mode; int kMin, kMax; };  // reflections counted: [kMin, kMax], -1 = all
  for (Case c : {Case{Mode::Direct, 0, 1}, Case{Mode::OneBounce, 0, 2}, Case{Mode::Indirect, 2, -1},
                 Case{Mode::IndirectOne, 2, 2}, Case{Mode::Full, 0, -1}, Case{Mode::TwoBounce, 0, 3},
                 Case{Mode::IndirectTwo, 2, 3}}) {
    double total = an::furnaceRadiance(rho, 1.0, c.kMax);
    double below = c.kMin == 0 ? 0.0 : an::furnaceRadiance(rho, 1.0, c.kMin - 1);
    glm::dvec3 expected = glm::dvec3(le) * (total - below);
    // 40000 paths. Measured (red channel, Le 1): direct 1.49955 +- 6.9e-4 (0.65 SE off),
    // one-bounce 1.75000 +- 8.0e-4 (0.00 SE), indirect 0.49921 +- 8.9e-4 (0.89 SE),
    // full 1.99865 +- 1.1e-3 (1.20 SE). The box is exact geometry: no allowance. (Separately
    // checked with 2e6 paths and 4 keys: direct within 1.8 SE, no visible bias at 1e-4.)
    Estimate e = tracer.estimateRadiance(glm::vec3(0.0f), dir, c.mode, 40000, 11, INFINITY, kThreads);
    expectWithin(("furnace rho 0.5 " + modeName(c.mode)).c_str(), e, expected);
  }
}

// indirect-K for every K in 1..8: r in {2, ..., K+1}, furnace Le (rho^2 + ... + rho^(K+1)). rho 0.8,
// so the last reflection a mode counts, Le rho^(K+1), is still 0.13 Le at K = 8 and a window one
// reflection short or long is far outside 3 SE at every K (checked by changing the range's upper
// end in path_tracer.cpp: to K, every K failed by 26..491 SE, K = 1 reading 0; to K+2, by 18..376 SE).
TEST(ReferenceFurnace, IndirectBouncesMatchPartialSums) {
  const float rho = 0.8f;
  const glm::vec3 le(1.0f, 0.5f, 0.25f);
  Scene s = an::furnaceBox(rho, le);
  ReferenceTracer tracer(s);
  glm::vec3 dir = glm::normalize(glm::vec3(0.3f, -0.2f, -1.0f));
  for (int k = 1; k <= Mode::kMaxIndirectBounces; ++k) {
    const Mode mode = Mode::indirect(k);
    EXPECT_EQ(modeName(mode), "indirect-" + std::to_string(k));
    EXPECT_EQ(parseMode("indirect-" + std::to_string(k)), mode);
    double expected = an::furnaceRadiance(rho, 1.0, k + 1) - an::furnaceRadiance(rho, 1.0, 1);
    // 40000 paths per K, no allowance (exact geometry). Measured (red channel, Le 1): within
    // 0.15..1.45 SE of the partial sum; the SE grows with K from 1.05e-3 (K = 1) to 5.7e-3 (K = 8).
    Estimate e = tracer.estimateRadiance(glm::vec3(0.0f), dir, mode, 40000, 60 + uint64_t(k), INFINITY, kThreads);
    expectWithin(("furnace rho 0.8 " + modeName(mode)).c_str(), e, glm::dvec3(le) * expected);
  }
  EXPECT_EQ(Mode::IndirectOne, Mode::indirect(1));
  EXPECT_EQ(Mode::IndirectTwo, Mode::indirect(2));
  EXPECT_TRUE(Mode::indirect(5).indirectOnly());
  EXPECT_FALSE(Mode(Mode::TwoBounce).indirectOnly());
}

// Full mode with a bright furnace exercises Russian roulette over long paths (mean path ~5+).
TEST(ReferenceFurnace, FullModeHighAlbedo) {
  const float rho = 0.8f;
  Scene s = an::furnaceBox(rho, glm::vec3(1.0f));
  ReferenceTracer tracer(s);
  // 40000 paths: measured 4.9881 +- 0.0111 (0.22 % of Le/(1-rho) = 5; 1.08 SE off).
  Estimate e = tracer.estimateRadiance(glm::vec3(0.1f, 0.2f, -0.1f), glm::vec3(1, 1, 0.5f), Mode::Full,
                                       40000, 12, INFINITY, kThreads);
  expectWithin("furnace rho 0.8 full", e, an::furnaceRadiance(rho, 1.0, -1));
}

// Irradiance at a virtual point inside the furnace: E = pi L everywhere, L = Le / (1 - rho)
// (direct part pi Le: the virtual surface itself does not reflect into the estimate).
TEST(ReferenceFurnace, IrradianceInside) {
  const float rho = 0.5f;
  Scene s = an::furnaceBox(rho, glm::vec3(1.0f));
  ReferenceTracer tracer(s);
  glm::vec3 p(0.2f, -0.1f, 0.3f), n = glm::normalize(glm::vec3(1, 2, 3));
  // 40000 samples: measured direct 3.13818 +- 3.8e-3 (0.91 SE off), full 6.28528 +- 6.7e-3
  // (0.31 SE off).
  expectWithin("furnace irradiance direct", tracer.estimateIrradiance(p, n, Mode::Direct, 40000, 13, kThreads), kPi);
  expectWithin("furnace irradiance full", tracer.estimateIrradiance(p, n, Mode::Full, 40000, 14, kThreads),
               kPi / (1.0 - rho));
}

// The camera path (render) agrees with the point estimator: the mean over a small full-mode image
// inside the furnace is Le / (1 - rho). SE of the image mean = sqrt(sum SE_pixel^2) / pixels.
TEST(ReferenceFurnace, RenderedImageMean) {
  const float rho = 0.5f;
  Scene s = an::furnaceBox(rho, glm::vec3(1.0f));
  ReferenceTracer tracer(s);
  ReferenceSettings st;
  st.width = 24;
  st.height = 16;
  st.spp = 32;
  st.threads = kThreads;
  Image img = tracer.render(st);
  ASSERT_EQ(img.stdErr.size(), img.rgb.size());
  Estimate e;
  for (size_t i = 0; i < img.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) {
      e.mean[c] += img.rgb[i * 3 + c];
      e.stdErr[c] += double(img.stdErr[i * 3 + c]) * img.stdErr[i * 3 + c];
    }
  e.mean /= double(img.pixelCount());
  e.stdErr = glm::sqrt(e.stdErr) / double(img.pixelCount());
  // 384 pixels x 32 spp: measured 1.99814 +- 2.1e-3 (0.88 SE off).
  expectWithin("furnace image mean", e, 2.0);
}

// A base colour texture is sRGB-decoded: a 2x2 texture of byte 188 under baseColor 1 is albedo
// ((188/255 + 0.055)/1.055)^2.4 = 0.5029; the furnace then gives Le / (1 - 0.5029).
TEST(ReferenceFurnace, TexturedAlbedoIsSrgbDecoded) {
  Scene s = an::furnaceBox(1.0f, glm::vec3(1.0f));
  TextureImage t;
  t.name = "grey188";
  t.width = t.height = 2;
  t.rgba8.assign(16, 188);
  s.textures.push_back(t);
  s.materials[0].baseColorTexture = 0;
  double albedo = std::pow((188.0 / 255.0 + 0.055) / 1.055, 2.4);
  ReferenceTracer tracer(s);
  // 40000 paths: measured 2.01031 +- 1.1e-3 against 2.01161 (1.18 SE off).
  Estimate e = tracer.estimateRadiance(glm::vec3(0.0f), glm::vec3(0, 0, 1), Mode::Full, 40000, 15, INFINITY, kThreads);
  expectWithin("furnace textured albedo full", e, 1.0 / (1.0 - albedo));
}

// ---- Ambient occlusion -------------------------------------------------------------------------

// Floor point next to a long wall of height h at distance d: V = 1/2 (1 + d / sqrt(d^2 + h^2)) for
// an infinitely long wall. The scene's wall has half-length L; its exact V (closed form, see
// analytic_scenes.h) differs from the infinite one by the residual printed and bounded below.
TEST(ReferenceAO, NextToWall) {
  struct Case { float d, h, L; };
  for (Case c : {Case{1.0f, 2.0f, 1000.0f}, Case{0.5f, 200.0f, 1.0e4f}}) {
    Scene s = an::floorAndWall(c.d, c.h, c.L, 2.0f * c.L);
    ReferenceTracer tracer(s);
    double vInf = an::aoNextToInfiniteWall(c.d, c.h);
    double vFinite = an::aoNextToFiniteWall(c.d, c.h, c.L);
    std::printf("  wall d=%g h=%g L=%g: V_inf %.6f V_finite %.6f residual %.1e\n", c.d, c.h, c.L, vInf,
                vFinite, vFinite - vInf);
    // The finite-length residual V_finite - V_inf is 4e-10 (first case) and 2e-9 (second): the
    // 1/L terms cancel, it falls as 1/L^3. Allowance against V_inf: 1e-5. Measured at 1e6 rays:
    // 0.723542 +- 4.5e-4 (0.14 SE off) and 0.501147 +- 5.0e-4 (0.21 SE off).
    Estimate e = tracer.estimateAO(glm::vec3(0.0f), glm::vec3(0, 1, 0), 1000000, INFINITY, 21, kThreads);
    EXPECT_LT(std::abs(vFinite - vInf), 1e-5);
    expectWithin("AO next to wall (vs infinite)", e, vInf, 1e-5);
    expectWithin("AO next to wall (vs finite exact)", e, vFinite);
  }
}

// The AO radius bounds occluder distance: with the wall (at distance 1) beyond the radius V = 1
// exactly; with an intermediate radius V lies strictly between the unbounded value and 1.
TEST(ReferenceAO, RadiusLimitsOccluders) {
  Scene s = an::floorAndWall(1.0f, 2.0f, 1000.0f, 2000.0f);
  ReferenceTracer tracer(s);
  Estimate near = tracer.estimateAO(glm::vec3(0.0f), glm::vec3(0, 1, 0), 20000, 0.99f, 22, kThreads);
  EXPECT_EQ(near.mean.x, 1.0);  // exact: no ray can reach the wall
  Estimate mid = tracer.estimateAO(glm::vec3(0.0f), glm::vec3(0, 1, 0), 100000, 1.5f, 23, kThreads);
  double vInf = an::aoNextToInfiniteWall(1.0, 2.0);
  std::printf("  AO radius 1.5 next to wall: %.6f +- %.1e (unbounded %.6f)\n", mid.mean.x, mid.stdErr.x, vInf);
  // Measured: V(1.5) = 0.89091 +- 9.9e-4; the unbounded value is 0.72361 (both margins > 100 SE).
  EXPECT_GT(mid.mean.x, vInf + 10 * mid.stdErr.x);
  EXPECT_LT(mid.mean.x, 1.0 - 10 * mid.stdErr.x);
}

// Floor point under a sphere of radius r centred at height H: V = 1 - (r/H)^2.
TEST(ReferenceAO, UnderSphere) {
  const float r = 0.5f, H = 1.0f;
  // 256 segments x 128 rings, vertices on the sphere: the inscribed polyhedron occludes less than
  // the sphere, so V is high by a residual falling as 1/N^2. Measured with 4e6 rays (SE 2.2e-4):
  // 16x8 +8.7e-3, 32x16 +2.3e-3, 64x32 +4.5e-4, i.e. ~3e-5 extrapolated to 256x128;
  // allowance 1e-4.
  Scene s = an::floorAndSphere(r, H, 256, 128);
  ReferenceTracer tracer(s);
  // 1e6 rays: measured 0.750385 +- 4.3e-4 (0.89 SE off).
  Estimate e = tracer.estimateAO(glm::vec3(0.0f), glm::vec3(0, 1, 0), 1000000, INFINITY, 31, kThreads);
  expectWithin("AO under sphere", e, an::aoUnderSphere(r, H), 1e-4);
}

// ---- Direct lighting ---------------------------------------------------------------------------

// Irradiance under a rectangular Lambertian emitter: E = pi Le F, F = sum of four corner terms.
TEST(ReferenceDirect, RectangleEmitterIrradiance) {
  const glm::vec3 le(2.0f, 1.0f, 0.5f);
  Scene s = an::rectEmitterOverFloor(-0.5f, 0.5f, -0.5f, 0.5f, 1.0f, le);
  ReferenceTracer tracer(s);
  // Cross-check of the corner formula: unit square, point under the centre, c = 1 -> 0.2395;
  // under a corner of a 1x1 square at c=1: F = 0.1385 (reference-data.md's corner formula).
  EXPECT_NEAR(an::cornerFormFactor(1, 1, 1), 0.13853, 1e-5);
  for (glm::vec2 q : {glm::vec2(0.0f, 0.0f), glm::vec2(0.3f, -0.2f), glm::vec2(-0.45f, 0.4f)}) {
    double F = an::formFactorUnderRectangle(q.x, q.y, -0.5, 0.5, -0.5, 0.5, 1.0);
    glm::dvec3 expected = kPi * glm::dvec3(le) * F;
    // 40000 samples with light sampling + MIS: measured SE 0.09 % / 0.15 % / 0.21 % of E at the
    // three points, estimates 1.97 / 0.45 / 0.58 SE off (4e6 samples at the centre: 0.58 SE).
    Estimate e = tracer.estimateIrradiance(glm::vec3(q.x, 0.0f, q.y), glm::vec3(0, 1, 0), Mode::Direct,
                                           40000, 41, kThreads);
    expectWithin("rect emitter direct E", e, expected);
  }
  // Full mode adds nothing here (the point sees only the black emitter's front), and indirect is
  // exactly zero: checks the mode windows and Russian roulette on a case with a known zero.
  Estimate full = tracer.estimateIrradiance(glm::vec3(0.0f), glm::vec3(0, 1, 0), Mode::Full, 40000, 42, kThreads);
  expectWithin("rect emitter full E", full,
               kPi * glm::dvec3(le) * an::formFactorUnderRectangle(0, 0, -0.5, 0.5, -0.5, 0.5, 1.0));
  Estimate ind = tracer.estimateIrradiance(glm::vec3(0.0f), glm::vec3(0, 1, 0), Mode::Indirect, 2000, 43, kThreads);
  EXPECT_EQ(ind.mean, glm::dvec3(0.0));
}

// Punctual lights use scene/light_model.h exactly: a point light of intensity I at height 2
// gives E = I cos / d^2 (no noise: no area lights, so direct mode traces only shadow rays).
TEST(ReferenceDirect, PunctualLightsFollowLightModel) {
  Scene s = an::rectEmitterOverFloor(10.0f, 11.0f, 10.0f, 11.0f, 1.0f, glm::vec3(0.0f));  // black
  Light point;
  point.type = LightType::Point;
  point.position = glm::vec3(0.0f, 2.0f, 0.0f);
  point.intensity = 10.0f;
  s.lights.push_back(point);
  ReferenceTracer tracer(s);
  Estimate e0 = tracer.estimateIrradiance(glm::vec3(0.0f), glm::vec3(0, 1, 0), Mode::Direct, 4, 51);
  EXPECT_NEAR(e0.mean.x, 10.0 / 4.0, 1e-5);  // float rounding only
  Estimate e1 = tracer.estimateIrradiance(glm::vec3(1.0f, 0.0f, 0.0f), glm::vec3(0, 1, 0), Mode::Direct, 4, 52);
  EXPECT_NEAR(e1.mean.x, 10.0 * (2.0 / std::sqrt(5.0)) / 5.0, 1e-5);
  // A spot light pointing down with outer 60 deg, inner 0: at 45 deg off-axis
  // t = (cos45 - cos60) / (1 - cos60), falloff t^2.
  Scene s2 = s;
  s2.lights[0].type = LightType::Spot;
  s2.lights[0].direction = glm::vec3(0, -1, 0);
  s2.lights[0].innerConeAngle = 0.0f;
  s2.lights[0].outerConeAngle = float(kPi / 3.0);
  ReferenceTracer spot(s2);
  double t = (std::cos(kPi / 4) - 0.5) / 0.5;
  double d2 = 8.0, cosS = 2.0 / std::sqrt(8.0);
  Estimate e2 = spot.estimateIrradiance(glm::vec3(2.0f, 0.0f, 0.0f), glm::vec3(0, 1, 0), Mode::Direct, 4, 53);
  EXPECT_NEAR(e2.mean.x, 10.0 * t * t * cosS / d2, 1e-5);
  // Occluded: a floor point under the (black) rectangle at (10.5, 0, 10.5) with the light moved
  // above the rectangle sees nothing.
  Scene s3 = s;
  s3.lights[0].position = glm::vec3(10.5f, 3.0f, 10.5f);
  ReferenceTracer occl(s3);
  EXPECT_EQ(occl.estimateIrradiance(glm::vec3(10.5f, 0.0f, 10.5f), glm::vec3(0, 1, 0), Mode::Direct, 4, 54).mean,
            glm::dvec3(0.0));
}

// ---- Camera, threads, settings -----------------------------------------------------------------

// Rows are stored top first and +x is to the right: an emissive red ceiling appears in the top
// row, an emissive green wall on the right in the right column, the black floor at the bottom.
TEST(ReferenceRender, CameraOrientationTopRowFirst) {
  an::SceneBuilder b("orientation");
  uint32_t red = b.material("red-ceiling", glm::vec3(0.0f), glm::vec3(1, 0, 0));
  uint32_t green = b.material("green-wall", glm::vec3(0.0f), glm::vec3(0, 1, 0));
  uint32_t black = b.material("floor", glm::vec3(0.0f));
  b.quad({-100, 1, -100}, {1, 1, -100}, {1, 1, 100}, {-100, 1, 100}, red, {0, -1, 0});
  b.quad({1, -100, -100}, {1, 100, -100}, {1, 100, 100}, {1, -100, 100}, green, {-1, 0, 0});
  b.quad({-100, -1, -100}, {1, -1, -100}, {1, -1, 100}, {-100, -1, 100}, black, {0, 1, 0});
  b.camera("front", {0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 1.0f);
  Scene s = b.build();
  ReferenceTracer tracer(s);
  ReferenceSettings st;
  st.width = 33;
  st.height = 21;
  st.spp = 1;
  st.mode = Mode::Direct;
  Image img = tracer.render(st);
  const float* top = img.at(16, 0);
  const float* right = img.at(32, 10);
  const float* bottom = img.at(16, 20);
  EXPECT_EQ(top[0], 1.0f);
  EXPECT_EQ(top[1], 0.0f);
  EXPECT_EQ(right[0], 0.0f);
  EXPECT_EQ(right[1], 1.0f);
  EXPECT_EQ(bottom[0], 0.0f);
  EXPECT_EQ(bottom[1], 0.0f);
}

// Results do not depend on the thread count: bit-identical images for 1, 2 and 3 threads.
TEST(ReferenceRender, ThreadCountDoesNotChangeTheImage) {
  Scene s = an::furnaceBox(0.7f, glm::vec3(1.0f, 0.8f, 0.6f));
  ReferenceTracer tracer(s);
  ReferenceSettings st;
  st.width = 20;
  st.height = 13;
  st.spp = 4;
  st.threads = 1;
  Image a = tracer.render(st);
  st.threads = 2;
  Image b = tracer.render(st);
  st.threads = 3;
  Image c = tracer.render(st);
  EXPECT_EQ(a.rgb, b.rgb);
  EXPECT_EQ(a.rgb, c.rgb);
  EXPECT_EQ(a.stdErr, c.stdErr);
  Estimate e1 = tracer.estimateAO(glm::vec3(0.0f), glm::vec3(0, 0, 1), 5000, 0.3f, 7, 1);
  Estimate e3 = tracer.estimateAO(glm::vec3(0.0f), glm::vec3(0, 0, 1), 5000, 0.3f, 7, 3);
  EXPECT_EQ(e1.mean, e3.mean);
}

TEST(ReferenceRender, InvalidSettingsThrowOneLineErrors) {
  Scene s = an::furnaceBox(0.5f, glm::vec3(1.0f));
  ReferenceTracer tracer(s);
  ReferenceSettings st;
  st.width = st.height = 4;
  st.spp = 0;
  EXPECT_THROW(tracer.render(st), Error);
  st.spp = 1;
  st.cameraIndex = 3;
  EXPECT_THROW(tracer.render(st), Error);
  try {
    parseMode("fancy");
    FAIL() << "parseMode accepted 'fancy'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("full, direct, one-bounce, two-bounce, indirect, indirect-K (K = 1..8"), std::string::npos) << e.what();
  }
  for (const char* bad : {"indirect-0", "indirect-9", "indirect-01", "indirect-", "indirect-+2", "indirect-2 "}) {
    try {
      parseMode(bad);
      FAIL() << "parseMode accepted '" << bad << "'";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("valid modes: "), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "one line: " << e.what();
    }
  }
  for (const auto& name : modeNames()) EXPECT_EQ(modeName(parseMode(name)), name);
}

// ---- Metrics and image files -------------------------------------------------------------------

namespace {
Image ramp(int w, int h) {
  Image img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* p = img.at(x, y);
      p[0] = float(x) / w;
      p[1] = float(y) / h;
      p[2] = 0.5f * float((x * 7 + y * 3) % 11) / 11.0f;
    }
  return img;
}
}  // namespace

TEST(ImageMetrics, IdenticalImages) {
  Image a = ramp(40, 30);
  ImageMetrics m = computeMetrics(a, a);
  EXPECT_EQ(m.rmse, 0.0);
  EXPECT_EQ(m.mae, 0.0);
  EXPECT_EQ(m.mre, 0.0);
  EXPECT_TRUE(std::isinf(m.psnr) && m.psnr > 0);
  EXPECT_NEAR(m.ssim, 1.0, 1e-12);  // exact up to double rounding of the window sums
  EXPECT_NE(metricsJson(m).find("\"psnr\": null"), std::string::npos);
  Image small = ramp(5, 4);  // smaller than the SSIM window: one global window
  EXPECT_NEAR(computeMetrics(small, small).ssim, 1.0, 1e-12);
}

TEST(ImageMetrics, ConstantOffsetHasKnownErrors) {
  Image b = ramp(40, 30);
  Image a = b;
  for (float& v : a.rgb) v += 0.1f;
  ImageMetrics m = computeMetrics(a, b);
  // Exact up to float rounding of the stored values (~1e-8).
  EXPECT_NEAR(m.rmse, 0.1, 1e-6);
  EXPECT_NEAR(m.mae, 0.1, 1e-6);
  EXPECT_NEAR(m.maxAbs, 0.1, 1e-6);
  double peak = 0;
  double mre = 0;
  for (float v : b.rgb) { peak = std::max(peak, double(v)); mre += 0.1 / (std::abs(v) + 0.01); }
  mre /= double(b.rgb.size());
  EXPECT_NEAR(m.peak, peak, 1e-9);
  EXPECT_NEAR(m.psnr, 20.0 * std::log10(peak / 0.1), 1e-4);
  EXPECT_NEAR(m.mre, mre, 1e-5 * mre);
  // A luminance offset keeps structure (sigma terms equal) but lowers the mean term: SSIM < 1.
  EXPECT_LT(m.ssim, 1.0);
  EXPECT_GT(m.ssim, 0.8);
  EXPECT_NEAR(m.dssim, (1.0 - m.ssim) / 2.0, 1e-15);
  EXPECT_DOUBLE_EQ(metricValue(m, "rmse"), m.rmse);
  EXPECT_THROW(metricValue(m, "l2"), Error);
}

TEST(ImageMetrics, SizeMismatchAndNonFinite) {
  Image a = ramp(4, 4), b = ramp(4, 5);
  try {
    computeMetrics(a, b);
    FAIL();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "image sizes differ: A is 4x4, B is 4x5");
  }
  Image c = ramp(4, 4);
  c.rgb[5] = NAN;
  ImageMetrics m = computeMetrics(c, a);
  EXPECT_EQ(m.nonFinite, 1u);
  EXPECT_TRUE(std::isnan(m.rmse));
}

TEST(ImageMetrics, ErrorColourRampIsMonotoneInLuminance) {
  float prev = -1.0f;
  for (int i = 0; i <= 100; ++i) {
    float rgb[3];
    errorColor(i / 100.0f, rgb);
    float y = luminance(rgb);
    EXPECT_GT(y, prev) << "at t = " << i / 100.0;
    prev = y;
  }
  Image a = ramp(8, 8), b = a;
  b.rgb[0] += 0.5f;
  float scale = 0;
  Image e = errorImage(a, b, 0.0f, &scale);
  EXPECT_NEAR(scale, 0.2126f * 0.5f, 1e-6);
}

TEST(ImageIO, ExrRoundTripKeepsValuesAndMetadata) {
  Image a = ramp(7, 5);
  a.rgb[3] = 123.25f;  // HDR values survive (32-bit float)
  std::string path = ::testing::TempDir() + "voxlab_ref_roundtrip.exr";
  writeExr(path, a, {{"voxlab:spp", "64", true}, {"voxlab:mode", "direct", false}});
  ImageAttributes attrs;
  Image b = readExr(path, &attrs);
  ASSERT_EQ(b.width, 7);
  ASSERT_EQ(b.height, 5);
  EXPECT_EQ(a.rgb, b.rgb);
  bool spp = false, mode = false;
  for (const auto& at : attrs) {
    spp = spp || (at.name == "voxlab:spp" && at.value == "64" && at.isInt);
    mode = mode || (at.name == "voxlab:mode" && at.value == "direct");
  }
  EXPECT_TRUE(spp && mode);
  EXPECT_EQ(stdErrPathFor("out/x.exr"), "out/x.stderr.exr");
  EXPECT_THROW(writeExr(::testing::TempDir() + "x.png", a), Error);
  std::remove(path.c_str());
}
