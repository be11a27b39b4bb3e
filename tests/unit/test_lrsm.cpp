// lrsm checks against answers that do not come from the code under test (testing.md):
//  - decisions (CPU): the overlap weights sum to 1 for both falloffs; Eq. 12 by the erf
//    approximation against std::erf, V in [0,1] and V -> the indicator as sigma -> 0; a flat
//    plane's quantised moments give no NaN and a sharp V; the cone weights are pi * the caps'
//    cosine integrals normalised (white furnace); the paper's memory arithmetic; the atlas limit;
//  - exact (GPU vs CPU): occlusion base = the fragment list's voxel set = the shared binary grid
//    unpacked; every occlusion mip = mean of its 8 children; every layer id = the CPU
//    classification of the texel's (z, <n.l>); base alpha a multiple of 0.25;
//  - structural: sum over layers of alpha = the valid fraction, and of A*R = the plain RSM's box
//    mip at level m + 1 (the sum identity), at every level; the base = the CPU layer build;
//    moments in range; the probe's per-layer records pass their visualiser's check and their V
//    equals the erf form of their own mu, sigma^2, z', r';
//  - Algorithm 1 against a brute-force sum over the RSM texels of the footprint (Eq. 3 / 7);
//  - physics: one-bounce indirect against the reference path tracer's indirect-1 (Cornell box,
//    Sponza), a roof over a sunlit floor against the analytic irradiance (energy and smoothness),
//    the Cornell box's flat faces against the reference's at 4-16 pixel scale (rings, stripes).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <set>

#include "run/reference_error.h"
#include "graph/resource_budget.h"
#include "graph/technique.h"
#include "reference/image_io.h"
#include "reference/path_tracer.h"
#include "core/paths.h"
#include "inspect/visualiser.h"
#include "lrsm/lrsm_shared.h"
#include "techniques/common/binary_voxels_stage.h"
#include "techniques/lrsm/lrsm.h"
#include "techniques/lrsm/stages.h"
#include "test_support.h"

namespace voxlab {
namespace {

using namespace lrsm;
using testing_support::capture;
using testing_support::session;

// The snapshot suite's settings (tests/golden/lrsm/settings.json), so the runs are shared.
RunRequest snapshotRequest() {
  RunRequest r;
  r.technique = "lrsm";
  r.scene = "cornell-box";
  r.width = r.height = 128;
  r.sets = {"voxel.resolution=64", "rsm.resolution=128", "shadow.resolution=256"};
  return r;
}

// --- Decisions (CPU) ------------------------------------------------------------------------------

TEST(LrsmDecisions, OverlapFalloffWeightsSumToOneEverywhere) {
  for (bool smooth : {true, false}) {
    LayerLayout L;
    L.depthSplits = 3;
    L.zNear = 2.0f;
    L.zFar = 10.0f;
    L.overlap = 0.4f;
    double worst = 0;
    for (int i = 0; i <= 4000; ++i) {
      const float z = L.zNear + (L.zFar - L.zNear) * float(i) / 4000.0f;
      float sum = 0;
      for (int d = 0; d < L.depthIntervals(); ++d) sum += L.falloff(d, z, smooth);
      worst = std::max(worst, std::fabs(double(sum) - 1.0));
    }
    // float smoothstep: k(t) + k(1-t) = 1 up to rounding (measured 1.2e-7).
    EXPECT_LT(worst, 1e-5) << (smooth ? "smoothstep" : "linear");
    for (float t = 0; t <= 1.0f; t += 0.01f) EXPECT_NEAR(falloffK(t, smooth) + falloffK(1 - t, smooth), 1.0f, 1e-6f);
  }
  // A k without the symmetry (t^2) would not sum to 1: the property is not automatic.
  EXPECT_GT(std::fabs(0.3f * 0.3f + 0.7f * 0.7f - 1.0f), 0.1f);
}

TEST(LrsmDecisions, WarpPutsEveryIntervalInsideZeroOneAndRangesOverlapByDelta) {
  LayerLayout L;
  L.depthSplits = 2;
  L.zNear = 1.0f;
  L.zFar = 4.0f;
  L.overlap = 0.5f;
  for (int d = 0; d < L.depthIntervals(); ++d) {
    const float lo = L.zNear + L.intervalWidth() * d, hi = lo + L.intervalWidth();
    EXPECT_GE(L.warp(d, lo), 0.0f);
    EXPECT_LE(L.warp(d, hi), 1.0f);
    EXPECT_EQ(L.depthIntervalOf(0.5f * (lo + hi)), d);
    if (d + 1 < L.depthIntervals()) {
      float a0, a1, b0, b1;
      L.rangeOf(d, a0, a1);
      L.rangeOf(d + 1, b0, b1);
      EXPECT_NEAR(a1 - b0, L.delta(), 1e-6f);
    }
  }
  EXPECT_EQ(L.normalIntervalOf(0.0f), 0);
  EXPECT_EQ(L.normalIntervalOf(0.49f), 0);
  EXPECT_EQ(L.normalIntervalOf(0.5f), 1);
  EXPECT_EQ(L.normalIntervalOf(1.0f), 1);  // <n.l> = 1 belongs to the last interval
  EXPECT_EQ(L.classify(3.9f, 0.9f), 5);    // interval 2 of 3, normal interval 1 of 2
}

TEST(LrsmDecisions, Eq12ByErfApproximationMatchesStdErfAndTendsToTheIndicator) {
  double worst = 0;
  for (float mu = 0.0f; mu <= 1.0f; mu += 0.05f)
    for (float s2 : {1e-6f, 4e-5f, 1e-3f, 0.02f})
      for (float zc = 0.0f; zc <= 1.0f; zc += 0.02f) {
        const float v = gaussianVisibility(zc, 0.05f, mu, s2);
        EXPECT_GE(v, 0.0f);
        EXPECT_LE(v, 1.0f);
        worst = std::max(worst, std::fabs(double(v) - gaussianVisibilityExact(zc, 0.05, mu, s2)));
      }
  // A-S 7.1.26 errs by < 1.5e-7 per erf; the float evaluation (exp, the polynomial) adds more:
  // measured 4.9e-6 over this grid.
  EXPECT_LT(worst, 1e-5);
  // sigma -> 0: V -> 1 inside [zc - rc, zc + rc], 0 outside (away from the edges).
  for (float zc = 0.0f; zc <= 1.0f; zc += 0.01f) {
    const float d = std::fabs(zc - 0.5f);
    if (std::fabs(d - 0.1f) < 0.005f) continue;
    EXPECT_NEAR(gaussianVisibility(zc, 0.1f, 0.5f, 1e-8f), d < 0.1f ? 1.0f : 0.0f, 1e-6f) << zc;
  }
}

// Raw moments E[z^k], k = 1..4, of depths drawn from 'sample' (n equal-weight points).
template <class F>
glm::vec4 rawMoments(int n, F sample) {
  glm::dvec4 m(0.0);
  for (int i = 0; i < n; ++i) {
    const double z = sample((i + 0.5) / n);
    m += glm::dvec4(z, z * z, z * z * z, z * z * z * z) / double(n);
  }
  return glm::vec4(m);
}

TEST(LrsmDecisions, DepthLobesLeaveTheGapBetweenTwoSurfacesEmpty) {
  // Two planes at z' = 0.2 (30 %) and 0.8 (70 %): one Gaussian (sigma^2 0.076) reads 0.13 in a
  // window [0.45, 0.55] in the empty air between them; the two lobes sit on the planes (lambda 0:
  // their own variance is the floor), read nothing there and each plane's share on it.
  const glm::vec4 two = rawMoments(1000, [](double u) { return u < 0.3 ? 0.2 : 0.8; });
  const DepthLobes a = depthLobes(two, kDefaultMinVariance);
  ASSERT_EQ(a.count, 3);
  EXPECT_NEAR(a.weight[0], 0.0f, 1e-6f);  // sigma^2 0.076 > 3 x 0.01: the lobes alone
  EXPECT_NEAR(a.mean[1], 0.8f, 1e-3f);
  EXPECT_NEAR(a.weight[1], 0.7f, 1e-3f);
  EXPECT_NEAR(a.mean[2], 0.2f, 1e-3f);
  EXPECT_LT(a.lambda, 1e-3f);
  const float single = gaussianVisibility(0.5f, 0.05f, two.x, two.y - two.x * two.x);
  EXPECT_GT(single, 0.12f);
  EXPECT_LT(lobeVisibility(a, 0.5f, 0.05f), 1e-6f);
  EXPECT_NEAR(lobeVisibility(a, 0.2f, 0.05f), 0.3f, 1e-3f);
  EXPECT_NEAR(lobeVisibility(a, 0.8f, 0.05f), 0.7f, 1e-3f);
  // A tilted plane's even spread over [0.2, 0.8] (sigma^2 0.03, kurtosis 1.8): lambda 0.225 from
  // 1 + 4 lambda - 2 lambda^2 = 1.8, lobes at mu -+ 0.88 sigma; a window over the middle third
  // reads 0.26 of the surface against the exact 1/3 (one Gaussian: 0.44).
  const glm::vec4 even = rawMoments(1000, [](double u) { return 0.2 + 0.6 * u; });
  const DepthLobes b = depthLobes(even, kDefaultMinVariance);
  EXPECT_NEAR(b.lambda, 0.2254f, 2e-3f);
  EXPECT_NEAR(b.weight[1], 0.5f * (1.0f - b.weight[0]), 1e-3f);
  const float middle = lobeVisibility(b, 0.5f, 0.1f);
  EXPECT_GT(middle, 0.2f);
  EXPECT_LT(middle, 0.34f);
  // A Gaussian's moments (kurtosis 3, no skew) keep the single lobe.
  const float mu = 0.5f, v = 0.0225f;  // N(0.5, 0.15^2)'s raw moments
  const glm::vec4 gauss(mu, mu * mu + v, mu * mu * mu + 3 * mu * v, mu * mu * mu * mu + 6 * mu * mu * v + 3 * v * v);
  EXPECT_EQ(depthLobes(gauss, kDefaultMinVariance).count, 1);
  // Below sigma^2 = 0.01 the moments' rounding decides nothing: one lobe.
  EXPECT_EQ(depthLobes(rawMoments(1000, [](double u) { return u < 0.5 ? 0.45 : 0.55; }), kDefaultMinVariance).count, 1);
}

// UNORM16 storage, as the layer-depth texture rounds.
float unorm16(float v) { return std::round(std::clamp(v, 0.0f, 1.0f) * 65535.0f) / 65535.0f; }

TEST(LrsmDecisions, FlatPlaneQuantisedMomentsGiveNoNanAndASharpVisibility) {
  int negativeRaw = 0;
  float worstRaw = 0.0f;
  for (float z = 0.0f; z <= 1.0f; z += 0.001f) {
    for (float alpha : {0.25f, 0.5f, 1.0f}) {
      const float m1 = unorm16(alpha * z), m2 = unorm16(alpha * z * z), a = unorm16(alpha);
      const float mu = m1 / a, raw = m2 / a - mu * mu;
      negativeRaw += raw < 0.0f;
      // Rounding alpha z and alpha z^2 by <= 0.5/65535 each moves E[z^2] - mu^2 by at most
      // (1 + 2 mu) (0.5/65535) / alpha <= 9.2e-5 at alpha = 1/4, plus alpha's own rounding and float
      // arithmetic (measured 9.23e-5): below the floor 1e-4.
      EXPECT_LT(std::fabs(raw), kDefaultMinVariance) << z << " " << alpha;
      worstRaw = std::max(worstRaw, std::fabs(raw));
      const float s2 = std::max(raw, kDefaultMinVariance);
      const float inside = gaussianVisibility(mu, 0.05f, mu, s2), outside = gaussianVisibility(mu + 0.1f, 0.05f, mu, s2);
      EXPECT_FALSE(std::isnan(inside));
      EXPECT_GT(inside, 0.999f);
      EXPECT_LT(outside, 1e-3f);
    }
  }
  // Quantisation does make E[z^2] - mu^2 negative somewhere: the floor is needed, and it must
  // exceed what rounding produces.
  EXPECT_GT(negativeRaw, 0);
  EXPECT_LT(worstRaw, kDefaultMinVariance);
}

TEST(LrsmDecisions, ConeWeightsAreNormalisedCapCosineIntegralsSummingToPi) {
  const auto cones = diffuseCones();
  ASSERT_EQ(int(cones.size()), 6);
  double sum = 0, capSum = 0;
  std::vector<double> caps;
  for (const auto& c : cones) {
    EXPECT_NEAR(glm::length(c.direction), 1.0f, 1e-6f);
    EXPECT_GT(c.direction.z, 0.0f);
    const double tilt = std::acos(std::clamp(double(c.direction.z), -1.0, 1.0));
    caps.push_back(capCosineIntegral(0.5 * kDiffuseAperture, tilt));
    capSum += caps.back();
    sum += c.weight;
  }
  // White furnace: E = sum w_k L = pi L, so L_o = albedo/pi * E = albedo * L.
  EXPECT_NEAR(sum, 3.14159265, 1e-5);
  for (size_t k = 0; k < cones.size(); ++k) EXPECT_NEAR(cones[k].weight, 3.14159265 * caps[k] / capSum, 1e-5) << k;
  // The six caps cover less than the hemisphere's cosine integral (pi): the weights rescale it.
  EXPECT_LT(capSum, 3.14159265);
}

TEST(LrsmDecisions, PaperMemoryArithmeticAndTheTenPercentTarget) {
  // Table 2 (SRS14): Sibenik 256^3 19.2 MB; RSM 1024^2 22.4 MB; LRSM 512^2 x 4 layers 33.6 MB.
  EXPECT_NEAR(paperMemory(256, 1024, 4).occlusion / 1e6, 19.17, 0.01);
  EXPECT_NEAR(paperMemory(512, 1024, 4).occlusion / 1e6, 153.39, 0.01);  // tabulated 156.4: see fidelity.md
  EXPECT_NEAR(paperMemory(512, 1024, 4).rsm / 1e6, 22.37, 0.01);
  EXPECT_NEAR(paperMemory(512, 1024, 4).lrsm / 1e6, 33.55, 0.01);
  EXPECT_NEAR(paperMemory(512, 1024, 6).lrsm / 1e6, 50.33, 0.01);
  const double sponza = paperMemory(512, 1024, 4).total() / 1e6;
  EXPECT_LT(std::fabs(sponza - 212.4) / 212.4, 0.10) << sponza;
}

// The paper's layout as voxlab allocates it: at 512^3 voxels and RSM 1024^2 (LRSM 512^2 x 4
// layers) the occlusion volume with its mips and the three LRSM atlases with theirs, from the
// same declarations the run allocates from (ResourceBudget.DeclarationsMatchAllocations ties the
// two; `voxlab bench --technique lrsm --scene sponza --set voxel.resolution=512 --set
// rsm.resolution=1024` listed the same 146.29 + 3 x 10.67 MiB). Against the arithmetic for the
// same layout: 186.9 MB both (docs/performance.md, lrsm memory).
TEST(LrsmDecisions, AllocatedOcclusionAndLrsmAt512MatchThePapersArithmetic) {
  auto t = createTechnique("lrsm");
  ParamSet p = t->defaultParams();
  p.set("voxel.resolution", 512);
  p.set("rsm.resolution", 1024);
  ViewState view;
  view.width = 1280;
  view.height = 720;
  const ResourceEstimate e = estimateResources(*t, p, view);
  double occlusion = 0, lrsm = 0;
  for (const auto& item : e.items) {
    if (item.resource == "occlusion") occlusion += double(item.bytes);
    if (item.resource == "lrsm-radiance" || item.resource == "lrsm-normal" || item.resource == "lrsm-depth")
      lrsm += double(item.bytes);
  }
  const PaperMemory paper = paperMemory(512, 1024, 4);
  std::printf("allocated at 512^3 / RSM 1024: occlusion %.2f MB (paper layout %.2f), LRSM %.2f MB (%.2f); all "
              "resources %.1f MB\n", occlusion / 1e6, paper.occlusion / 1e6, lrsm / 1e6, paper.lrsm / 1e6, e.totalBytes / 1e6);
  // Full mip chains down to 1 texel: the allocation's x (1 + 1/8 + ...) and x (1 + 1/4 + ...)
  // against the arithmetic's limits 8/7 and 4/3 (measured: within 0.01 %). 1 % would catch a
  // missing level or a wrong texel size; the target is 10 % of the paper's 212.4 MB in all.
  EXPECT_NEAR(occlusion / paper.occlusion, 1.0, 0.01);
  EXPECT_NEAR(lrsm / paper.lrsm, 1.0, 0.01);
  EXPECT_LT(std::fabs((occlusion + lrsm + paper.rsm) / 1e6 - 212.4) / 212.4, 0.10);
}

TEST(LrsmDecisions, OversizedAtlasIsRefusedWithOneLine) {
  EXPECT_EQ(atlasSizeError(1024, 4, 16384), "");
  const std::string e = atlasSizeError(4096, 16, 16384);
  EXPECT_NE(e.find("32768"), std::string::npos) << e;
  EXPECT_NE(e.find("rsm.resolution"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos);
}

// --- GPU against CPU ------------------------------------------------------------------------------

std::vector<uint32_t> fragmentKeys(HeadlessSession& s) {
  CapturedOutput f = capture(s, "voxelize", "fragments");
  std::vector<uint32_t> keys;
  for (uint32_t i = 0; i < f.recordCount; ++i) {
    uint32_t k;
    std::memcpy(&k, &f.records[size_t(i) * f.desc.layout.stride], 4);
    keys.push_back(k);
  }
  return keys;
}

TEST(LrsmOcclusion, BaseEqualsFragmentVoxelsAndTheSharedBinaryGridUnpacked) {
  auto& s = session(snapshotRequest());
  const int res = 64;
  CapturedOutput occ = capture(s, "occlusion-voxels", "occlusion-voxels");
  ASSERT_EQ(occ.levels.size(), 1u);
  std::set<uint32_t> keys;
  for (uint32_t k : fragmentKeys(s)) keys.insert(k);
  const auto grid = binaryGridFromVoxelKeys(std::vector<uint32_t>(keys.begin(), keys.end()), res);
  size_t set = 0, wrong = 0, gridWrong = 0;
  for (int z = 0; z < res; ++z)
    for (int y = 0; y < res; ++y)
      for (int x = 0; x < res; ++x) {
        const float v = occ.levels[0].at(x, y, z, 0);
        const bool full = keys.count(uint32_t(x) | uint32_t(y) << 10 | uint32_t(z) << 20) > 0;
        set += v != 0.0f;
        wrong += (v == 1.0f) != full || (v != 0.0f && v != 1.0f);
        int first, last;
        slicesOfVoxel(z, res, first, last);
        gridWrong += hasSlice(grid[size_t(y) * res + x], first) != full;
      }
  EXPECT_GT(set, 5000u);
  EXPECT_EQ(wrong, 0u);
  EXPECT_EQ(gridWrong, 0u);
}

TEST(LrsmOcclusion, EveryMipIsTheMeanOfItsEightChildren) {
  auto& s = session(snapshotRequest());
  CapturedOutput occ = capture(s, "occlusion-mips", "occlusion");
  ASSERT_EQ(occ.levels.size(), 7u);  // 64 -> 1
  for (size_t l = 1; l < occ.levels.size(); ++l) {
    const LevelData& c = occ.levels[l - 1];
    const LevelData& p = occ.levels[l];
    double worst = 0;
    for (int z = 0; z < p.size.z; ++z)
      for (int y = 0; y < p.size.y; ++y)
        for (int x = 0; x < p.size.x; ++x) {
          double mean = 0;
          for (int i = 0; i < 8; ++i) mean += c.at(2 * x + (i & 1), 2 * y + ((i >> 1) & 1), 2 * z + (i >> 2), 0) / 8.0;
          const double v = p.at(x, y, z, 0);
          worst = std::max(worst, std::fabs(v - mean));
          if (mean == 0.0) { ASSERT_EQ(v, 0.0); }
          if (mean == 1.0) { ASSERT_EQ(v, 1.0); }
        }
    // UNORM8 rounding of the exact mean of the stored children: at most half a step (+ float).
    EXPECT_LE(worst, 0.5 / 255.0 + 1e-6) << "level " << l;
  }
}

struct Layered {
  LayerLayout layout;
  int rsm = 0;
  std::vector<float> depth, ndotl;
  std::vector<glm::vec3> normal, radiance;
  std::vector<uint8_t> valid;
};

Layered readRsm(HeadlessSession& s) {
  Layered r;
  r.layout = layoutFor(s.cursor().scene(), s.cursor().board(), s.cursor().params());
  CapturedOutput d = capture(s, "layers", "rsm-depth");
  CapturedOutput n = capture(s, "rsm", "rsm-normal");
  CapturedOutput rad = capture(s, "rsm", "rsm-radiance");
  r.rsm = d.levels[0].size.x;
  const size_t count = size_t(r.rsm) * r.rsm;
  for (size_t i = 0; i < count; ++i) {
    const int x = int(i % r.rsm), y = int(i / r.rsm);
    r.depth.push_back(d.levels[0].at(x, y, 0, 0));
    r.ndotl.push_back(d.levels[0].at(x, y, 0, 1));
    r.valid.push_back(n.levels[0].at(x, y, 0, 3) > 0.5f);
    r.normal.emplace_back(n.levels[0].at(x, y, 0, 0), n.levels[0].at(x, y, 0, 1), n.levels[0].at(x, y, 0, 2));
    r.radiance.emplace_back(rad.levels[0].at(x, y, 0, 0), rad.levels[0].at(x, y, 0, 1), rad.levels[0].at(x, y, 0, 2));
  }
  return r;
}

TEST(LrsmLayers, LayerIdsEqualTheCpuClassificationAndBaseAlphaIsQuarters) {
  auto& s = session(snapshotRequest());
  const Layered r = readRsm(s);
  CapturedOutput ids = capture(s, "layers", "layer-id");
  std::set<int> used;
  size_t wrong = 0, covered = 0;
  for (int y = 0; y < r.rsm; ++y)
    for (int x = 0; x < r.rsm; ++x) {
      const size_t i = size_t(y) * r.rsm + x;
      const int expect = r.valid[i] ? r.layout.classify(r.depth[i], r.ndotl[i]) : 255;
      const int got = int(ids.levels[0].at(x, y, 0, 0));
      wrong += got != expect;
      covered += r.valid[i];
      used.insert(got);
    }
  EXPECT_GT(covered, size_t(r.rsm) * r.rsm / 4);
  EXPECT_EQ(wrong, 0u);
  EXPECT_GE(used.size(), 3u) << "the Cornell box spans at least two layers and the empty id";
  CapturedOutput rad = capture(s, "layers", "layer-radiance");
  const LevelData& b = rad.levels[0];
  for (int y = 0; y < b.size.y; ++y)
    for (int x = 0; x < b.size.x; ++x) {
      const float a = b.at(x, y, 0, 3);
      ASSERT_EQ(a * 4.0f, std::round(a * 4.0f)) << "alpha " << a << " at " << x << ", " << y;
    }
}

TEST(LrsmLayers, BaseEqualsTheCpuLayerBuild) {
  auto& s = session(snapshotRequest());
  const Layered r = readRsm(s);
  const LayerBase cpu = buildLayersCpu(r.layout, r.rsm, r.depth, r.ndotl, r.normal, r.radiance, r.valid);
  CapturedOutput rad = capture(s, "layers", "layer-radiance");
  CapturedOutput nor = capture(s, "layers", "layer-normal");
  CapturedOutput dep = capture(s, "layers", "layer-depth");
  const LevelData &R = rad.levels[0], &N = nor.levels[0], &D = dep.levels[0];
  ASSERT_EQ(R.size.x, cpu.width * cpu.layers);
  double worstR = 0, worstN = 0, worstD = 0;
  for (int y = 0; y < R.size.y; ++y)
    for (int x = 0; x < R.size.x; ++x) {
      const size_t a = size_t(y) * R.size.x + x;
      for (int c = 0; c < 4; ++c) {
        const double rel = std::max(1.0, double(std::fabs(cpu.radiance[a][c])));
        worstR = std::max(worstR, std::fabs(R.at(x, y, 0, c) - cpu.radiance[a][c]) / rel);
        worstN = std::max(worstN, double(std::fabs(N.at(x, y, 0, c) - cpu.normal[a][c])));
        worstD = std::max(worstD, double(std::fabs(D.at(x, y, 0, c) - cpu.depth[a][c])));
      }
    }
  // fp16: relative 2^-11 of the value (1e-3 with margin); UNORM16: half a step of 1/65535 (+ the
  // GPU's float warp, measured 1e-6).
  EXPECT_LT(worstR, 1e-3);
  EXPECT_LT(worstN, 1e-3);
  EXPECT_LT(worstD, 1.0 / 65535.0);
}

// Box mip of an RSM-resolution image (invalid texels count 0) down to 'level'.
std::vector<glm::vec4> boxMip(std::vector<glm::vec4> img, int size, int level) {
  for (int l = 0; l < level; ++l) {
    const int h = size / 2;
    std::vector<glm::vec4> next(size_t(h) * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < h; ++x)
        next[size_t(y) * h + x] = 0.25f * (img[size_t(2 * y) * size + 2 * x] + img[size_t(2 * y) * size + 2 * x + 1] +
                                           img[size_t(2 * y + 1) * size + 2 * x] + img[size_t(2 * y + 1) * size + 2 * x + 1]);
    img.swap(next);
    size = h;
  }
  return img;
}

TEST(LrsmLayers, SumIdentityAndCoverageSumHoldAtEveryLevel) {
  auto& s = session(snapshotRequest());
  const Layered r = readRsm(s);
  std::vector<glm::vec4> plain(size_t(r.rsm) * r.rsm);
  for (size_t i = 0; i < plain.size(); ++i) plain[i] = r.valid[i] ? glm::vec4(r.radiance[i], 1.0f) : glm::vec4(0.0f);
  CapturedOutput rad = capture(s, "lrsm-mips", "lrsm-radiance");
  CapturedOutput sum = capture(s, "lrsm-mips", "coverage-sum");
  ASSERT_EQ(rad.levels.size(), size_t(lrsmLevels(r.rsm / 2)));
  for (size_t m = 0; m < rad.levels.size(); ++m) {
    const auto ref = boxMip(plain, r.rsm, int(m) + 1);
    const LevelData& L = rad.levels[m];
    const int w = L.size.y, n = L.size.x / w;
    double worst = 0, worstAlpha = 0;
    for (int y = 0; y < w; ++y)
      for (int x = 0; x < w; ++x) {
        glm::vec4 total(0.0f);
        for (int l = 0; l < n; ++l)
          total += glm::vec4(L.at(l * w + x, y, 0, 0), L.at(l * w + x, y, 0, 1), L.at(l * w + x, y, 0, 2), L.at(l * w + x, y, 0, 3));
        const glm::vec4 e = ref[size_t(y) * w + x];
        for (int c = 0; c < 3; ++c) worst = std::max(worst, double(std::fabs(total[c] - e[c])) / std::max(1.0, double(e[c])));
        worstAlpha = std::max(worstAlpha, double(std::fabs(total.w - e.w)));
        worstAlpha = std::max(worstAlpha, double(std::fabs(sum.levels[m].at(x, y, 0, 0) - e.w)));
      }
    // fp16 per layer and level (2^-11 relative), rounded once per level and summed over the
    // layers: measured below 2e-3 of max(1, value) at 7 levels.
    EXPECT_LT(worst, 4e-3) << "level " << m;
    EXPECT_LT(worstAlpha, 2e-3) << "level " << m;
  }
}

TEST(LrsmLayers, WarpedMomentsStayInRangeAfterQuantisation) {
  auto& s = session(snapshotRequest());
  CapturedOutput dep = capture(s, "lrsm-mips", "lrsm-depth");
  CapturedOutput nor = capture(s, "lrsm-mips", "lrsm-normal");  // alpha: the normal's .w
  size_t checked = 0, negative = 0;
  double worstNegative = 0;
  for (size_t m = 0; m < dep.levels.size(); ++m) {
    const LevelData& L = dep.levels[m];
    for (int y = 0; y < L.size.y; ++y)
      for (int x = 0; x < L.size.x; ++x) {
        const float a = nor.levels[m].at(x, y, 0, 3);
        if (a < 0.01f) continue;
        const float mu = L.at(x, y, 0, 0) / a, e2 = L.at(x, y, 0, 1) / a;
        ++checked;
        EXPECT_GE(mu, -1e-4f);
        EXPECT_LE(mu, 1.0f + 1e-3f);  // alpha and alpha*z' rounded separately
        if (e2 < mu * mu) {
          ++negative;
          // Relative to what rounding alpha z and alpha z^2 (half a UNORM16 step each, and once
          // more per level they were averaged into) can do at this alpha and mu.
          const double bound = (1.0 + 2.0 * mu) * (0.5 / 65535.0) / a;
          worstNegative = std::max(worstNegative, double(mu * mu - e2) / bound);
        }
      }
  }
  EXPECT_GT(checked, 1000u);
  // Where quantisation makes E[z^2] < mu^2 it is by no more than rounding explains (x 7 levels of
  // re-rounding at most; measured 1.3 x one rounding), and at alpha >= 1/4 that is below the floor.
  EXPECT_LT(worstNegative, 7.0) << negative << " texels with E[z^2] < mu^2";
}

TEST(LrsmGather, ProbeRecordsPassTheirCheckAndVisibilityIsTheErfForm) {
  RunRequest req = snapshotRequest();
  req.sets.push_back("probe.x=0.5");
  req.sets.push_back("probe.y=0.85");  // the floor, in front of the boxes
  auto& s = session(req);
  CapturedOutput g = capture(s, "cone-gather", "gather-records");
  ASSERT_GT(g.recordCount, 20u);
  const RecordCheck check = visualiserFor(g.desc).checkRecords(g);
  EXPECT_EQ(check.error, "") << check.summary;
  size_t contributing = 0;
  double worst = 0;
  for (uint32_t i = 0; i < g.recordCount; ++i) {
    gpu::LrsmGatherRecord r;
    std::memcpy(&r, &g.records[size_t(i) * sizeof r], sizeof r);
    if (r.layer.y < 0.5f || r.layer.w <= 0.0f || r.coverage.w <= 0.0f) continue;
    EXPECT_GE(r.moments.y, kDefaultMinVariance * 0.999f);
    if (r.moments.y >= kTwoLobeVariance) continue;  // two depth lobes (LrsmDecisions.DepthLobes...)
    worst = std::max(worst, std::fabs(r.moments.z - gaussianVisibilityExact(r.moments.w, r.contribution.w, r.moments.x, r.moments.y)));
    contributing += r.contribution.x > 0.0f;
  }
  EXPECT_GT(contributing, 0u);
  // GPU exp/erf approximation in fp32: measured 4e-7.
  EXPECT_LT(worst, 1e-5);
  CapturedOutput samples = capture(s, "cone-gather", "cone-samples");
  const RecordCheck sc = visualiserFor(samples.desc).checkRecords(samples);
  EXPECT_EQ(sc.error, "") << sc.summary;
  EXPECT_GT(sc.elements, 20u);
}


TEST(LrsmGather, Algorithm1AgainstABruteForceSumOverTheFootprint) {
  // Algorithm 1 as printed (the numerator sum_l f A*R V N) for every sample of the probed pixel,
  // against Eq. 3 / 7 summed directly over the RSM texels the sample's circle covers: the mean over
  // the footprint (a square of side d_circle LRSM texels around the sample's uv) of
  // R * H(r_c - |x - x_c|) * [<n . v_c> > 0] * <n . v_c>, invalid texels counting 0.
  RunRequest req = snapshotRequest();
  req.sets = {"voxel.resolution=64", "rsm.resolution=128", "shadow.resolution=256", "lrsm.estimator=paper",
              "lrsm.layer-select=overlap", "lrsm.footprint-bias=0", "cone.horizon=false", "probe.x=0.3", "probe.y=0.9"};
  auto& s = session(req);
  CapturedOutput g = capture(s, "cone-gather", "gather-records");
  CapturedOutput pos = capture(s, "rsm", "rsm-position");
  CapturedOutput nor = capture(s, "rsm", "rsm-normal");
  CapturedOutput rad = capture(s, "rsm", "rsm-radiance");
  CapturedOutput gp = capture(s, "gbuffer", "position");
  const int rsm = pos.levels[0].size.x;
  std::map<std::pair<int, int>, std::pair<gpu::LrsmGatherRecord, double>> samples;  // (cone, step) -> record, sum
  for (uint32_t i = 0; i < g.recordCount; ++i) {
    gpu::LrsmGatherRecord r;
    std::memcpy(&r, &g.records[size_t(i) * sizeof r], sizeof r);
    auto& e = samples[{int(r.cone.x), int(r.cone.y)}];
    e.first = r;
    e.second += r.contribution.x + r.contribution.y + r.contribution.z;
  }
  // The receiver: the probed traced pixel's G-buffer position (half resolution: pixel 2x, 2y).
  const int tw = 64, th = 64;
  const int px = std::min(int(0.3f * tw), tw - 1), py = std::min(int((1.0f - 0.9f) * th), th - 1);
  const glm::vec3 p(gp.levels[0].at(2 * px, 2 * py, 0, 0), gp.levels[0].at(2 * px, 2 * py, 0, 1), gp.levels[0].at(2 * px, 2 * py, 0, 2));
  std::vector<double> ratios;
  double sumGather = 0, sumBrute = 0;
  for (const auto& [key, e] : samples) {
    const auto& r = e.first;
    const glm::vec3 xc(r.centre), vc = glm::normalize(p - xc);
    const float rc = r.centre.w;
    const int half = std::max(1, int(std::ceil(r.footprint.x)));
    const int cx = int(r.march.y * rsm), cy = int(r.march.z * rsm);
    double brute = 0;
    int texels = 0;
    for (int y = cy - half; y < cy + half; ++y)
      for (int x = cx - half; x < cx + half; ++x) {
        ++texels;
        if (x < 0 || y < 0 || x >= rsm || y >= rsm || nor.levels[0].at(x, y, 0, 3) < 0.5f) continue;
        const glm::vec3 xs(pos.levels[0].at(x, y, 0, 0), pos.levels[0].at(x, y, 0, 1), pos.levels[0].at(x, y, 0, 2));
        const glm::vec3 ns(nor.levels[0].at(x, y, 0, 0), nor.levels[0].at(x, y, 0, 1), nor.levels[0].at(x, y, 0, 2));
        const float nv = glm::dot(ns, vc);
        if (glm::length(xs - xc) > rc || nv <= 0.0f) continue;
        brute += (rad.levels[0].at(x, y, 0, 0) + rad.levels[0].at(x, y, 0, 1) + rad.levels[0].at(x, y, 0, 2)) * nv;
      }
    brute /= std::max(texels, 1);
    sumGather += e.second;
    sumBrute += brute;
    if (brute > 1e-3 && e.second > 1e-3) ratios.push_back(e.second / brute);
  }
  ASSERT_GT(samples.size(), 5u);
  std::sort(ratios.begin(), ratios.end());
  const double median = ratios.empty() ? 0.0 : ratios[ratios.size() / 2];
  std::printf("Algorithm 1 vs brute force: %zu samples, %zu with both non-zero, median ratio %.3f, sums %.4f vs %.4f\n",
              samples.size(), ratios.size(), median, sumGather, sumBrute);
  ::testing::Test::RecordProperty("median_ratio", std::to_string(median));
  // Measured over the 33 samples of this pixel: sums 0.545 (Algorithm 1) vs 0.533 (brute force),
  // ratio 1.02; per sample the median ratio is 1.25 (the Gaussian V smooths the sphere's hard
  // edge and the bilinear mip lookup widens the footprint, so single samples diverge at depth
  // steps while the totals agree). The band 0.6..1.6 on the totals fails without V (x 2.4) or N.
  EXPECT_GT(sumBrute, 0.0);
  EXPECT_GT(sumGather / sumBrute, 0.6);
  EXPECT_LT(sumGather / sumBrute, 1.6);
}

// lrsm's one-bounce indirect light as the composite adds it: the gathered light after the filter
// stage (which averages cone.interleave's 4 x 4 tile of step phases).
CapturedOutput lrsmIndirect(HeadlessSession& s) { return capture(s, "filter", "indirect-filtered"); }

// The gather as it was before its steps were interleaved: every pixel's samples start at
// cone.start, and no filter. The detail tests run their variants with it: the filter's kernel
// would smooth the very rings and stripes they must show to prove that the measure sees them.
const std::vector<std::string> kUnfiltered = {"cone.interleave=false", "filter.passes=0"};
std::vector<std::string> unfiltered(std::vector<std::string> sets) {
  sets.insert(sets.end(), kUnfiltered.begin(), kUnfiltered.end());
  return sets;
}

double indirectMeanRatio(const RunRequest& req) {
  auto& s = session(req);
  CapturedOutput out = lrsmIndirect(s);
  const nlohmann::json e = compareWithReference(out, req.scene, 0, testing::TempDir(), "lrsm-indirect");
  EXPECT_FALSE(e.is_null());
  EXPECT_FALSE(e.contains("skipped")) << e.dump();
  if (e.is_null() || e.contains("skipped")) return -1.0;
  std::printf("lrsm indirect-1 mean ratio %.3f, rmse %.4f, ssim %.3f\n", e["mean_ratio"].get<double>(),
              e["rmse"].get<double>(), e["ssim"].get<double>());
  return e["mean_ratio"].get<double>();
}

// Algorithm 1 as the paper prints it: L_i = sum_l f A*R V N times alpha_i in Eq. 1, the layers of
// Eq. 15's overlap, the LRSM level log2(d_circle), no horizon.
std::vector<std::string> paperSettings() {
  return {"lrsm.estimator=paper", "lrsm.layer-select=overlap", "lrsm.footprint-bias=0", "cone.horizon=false"};
}

// Sponza at the size of its references (512x512, camera 0, defaults).
TEST(LrsmPhysics, SponzaOneBounceIndirectAgainstTheReferencePathTracer) {
  RunRequest r;
  r.technique = "lrsm";
  r.scene = "sponza";
  const double coverage = indirectMeanRatio(r);
  for (const auto& set : paperSettings()) r.sets.push_back(set);
  const double printed = indirectMeanRatio(r);
  // Coverage estimator: measured 0.806 (0.814 with one step phase for every pixel,
  // cone.interleave=false; 0.819 with that and one Gaussian per layer, lrsm.two-lobes=false; the
  // fidelity target is 0.8 .. 1.25; docs/lrsm.md says where the rest goes). Algorithm 1 as
  // printed: 0.101 (alpha_i, A and V compound). Deterministic runs; each band is x0.8 .. x1.25 of
  // its measurement and fails on a lost or extra pi, a lost layer or cone, or the estimators swapped.
  EXPECT_GT(coverage, 0.645);
  EXPECT_LT(coverage, 1.01);
  EXPECT_GT(printed, 0.082);
  EXPECT_LT(printed, 0.128);
}

TEST(LrsmPhysics, OneBounceIndirectAgainstTheReferencePathTracer) {
  // Coverage estimator (the default): measured 1.068 at these settings (64^3, RSM 128, 128x128;
  // 1.007 with one step phase for every pixel, cone.interleave=false; 1.005 with that and one
  // Gaussian per layer; 1.062 before the solid-angle bound of samples that reach near the spot).
  // The band is x0.8 .. x1.25 of it and fails on a missing or extra pi, a lost layer or a lost
  // cone (6 cones, the central one carries 1/3.2 of the weight).
  const double coverage = indirectMeanRatio(snapshotRequest());
  EXPECT_GT(coverage, 0.85);
  EXPECT_LT(coverage, 1.34);
  // Algorithm 1 as printed: measured 0.037 (0.038 with one step phase); alpha_i, A, V and N
  // compound (the band x0.8 .. x1.25).
  RunRequest paper = snapshotRequest();
  for (const auto& set : paperSettings()) paper.sets.push_back(set);
  const double printed = indirectMeanRatio(paper);
  EXPECT_GT(printed, 0.030);
  EXPECT_LT(printed, 0.048);
  EXPECT_GT(coverage, 5.0 * printed);
}

}  // namespace
}  // namespace voxlab

namespace voxlab {
namespace {

TEST(LrsmVisualisers, LayeredDataAndGatherRecordsHaveTheirOwnVisualisers) {
  using namespace lrsm;
  EXPECT_STREQ(visualiserFor(OutputKind::Image2D, kLayerRadiance).name(), "lrsm-layers");
  EXPECT_STREQ(visualiserFor(OutputKind::Image2D, kLayerNormal).name(), "lrsm-layers");
  EXPECT_STREQ(visualiserFor(OutputKind::Image2D, kLayerDepth).name(), "lrsm-layers");
  EXPECT_STREQ(visualiserFor(OutputKind::Buffer, kGatherRecords).name(), "lrsm-gather");
  EXPECT_TRUE(texelMapping(kLayerId).exact);
  // The layer statistics: per level, each layer's mean coverage; summed they are the RSM's covered
  // fraction at that level (the sum identity seen through the visualiser).
  auto& s = testing_support::session(snapshotRequest());
  CapturedOutput rad = testing_support::capture(s, "lrsm-mips", "lrsm-radiance");
  CapturedOutput sum = testing_support::capture(s, "lrsm-mips", "coverage-sum");
  const nlohmann::json st = visualiserFor(rad.desc).statistics(rad);
  ASSERT_EQ(st["layers"].get<int>(), 4);
  ASSERT_EQ(st["layer_coverage_per_level"].size(), rad.levels.size());
  for (size_t m = 0; m < rad.levels.size(); ++m) {
    double total = 0, expect = 0;
    for (const auto& v : st["layer_coverage_per_level"][m]) total += v.get<double>();
    const LevelData& L = sum.levels[m];
    for (float v : L.values) expect += v;
    expect /= double(L.values.size());
    // fp16 alphas summed per texel and averaged: measured 1e-4.
    EXPECT_NEAR(total, expect, 2e-3) << "level " << m;
  }
}

}  // namespace
}  // namespace voxlab

namespace voxlab {
namespace {

// --- Thin wall: the leak of isotropic occlusion, measured ------------------------------------------

// Mean luminance of an image output over the G-buffer pixels on each side of the wall at x = 0
// (|x| > 2 cm: the wall is 1 cm thick). An image traced at half resolution maps its texel (i, j)
// to G-buffer pixel (2i, 2j).
struct SideMeans {
  double lit = 0, sealed = 0;  // the spot's half (x < 0), the sealed half (x > 0)
  size_t litPixels = 0, sealedPixels = 0;
};

SideMeans sideMeans(const CapturedOutput& image, const CapturedOutput& position) {
  const LevelData& I = image.levels.at(0);
  const LevelData& P = position.levels.at(0);
  const int scale = P.size.x / I.size.x;
  SideMeans m;
  for (int y = 0; y < I.size.y; ++y)
    for (int x = 0; x < I.size.x; ++x) {
      const int gx = x * scale, gy = y * scale;
      if (P.at(gx, gy, 0, 3) == 0.0f) continue;  // no surface
      const float wx = P.at(gx, gy, 0, 0);
      const double lum = 0.2126 * I.at(x, y, 0, 0) + 0.7152 * I.at(x, y, 0, 1) + 0.0722 * I.at(x, y, 0, 2);
      if (wx < -0.02f) m.lit += lum, ++m.litPixels;
      if (wx > 0.02f) m.sealed += lum, ++m.sealedPixels;
    }
  if (m.litPixels) m.lit /= double(m.litPixels);
  if (m.sealedPixels) m.sealed /= double(m.sealedPixels);
  return m;
}

RunRequest thinWallRequest(const char* technique) {
  RunRequest r;
  r.technique = technique;
  r.scene = "tests/data/scenes/thin-wall-spot.gltf";
  r.width = r.height = 128;
  r.sets = {"voxel.resolution=64"};  // voxels of 3.1 cm in the 2 m room: the 1 cm wall fills one voxel layer
  return r;
}

// A 1 cm wall seals the spot's half of the room from the other (scripts/make_scenes.py
// thin_wall): no light path reaches the sealed half, so its true radiance is exactly 0 and
// everything there is leak. The paper reports this leak for isotropic occlusion (SRS14 section 6,
// Sibenik): a wall one voxel thick is opaque at voxel level 0 but only half covered at mip 1 and
// an eighth at mip 3, and a 60-degree cone reads coarse mips after a few samples.
TEST(LrsmPhysics, ThinWallLeaksThroughIsotropicOcclusionAndTheShadowMapDoesNot) {
  RunRequest cone = thinWallRequest("lrsm");
  cone.sets.push_back("rsm.resolution=128");
  cone.sets.push_back("composite.shadow=cone");
  auto& s = session(cone);
  const CapturedOutput position = capture(s, "gbuffer", "position");
  const SideMeans indirect = sideMeans(lrsmIndirect(s), position);
  const SideMeans direct = sideMeans(capture(s, "composite", "direct"), position);
  // The reference path tracer's one-bounce light on the same pixels (its rows run top first).
  reference::ReferenceTracer tracer(s.cursor().scene());
  reference::ReferenceSettings rs;
  rs.mode = reference::Mode::IndirectOne;
  rs.width = rs.height = 128;
  rs.spp = 32;
  rs.computeStdErr = false;
  const reference::Image refImage = tracer.render(rs);
  CapturedOutput refOut = position;
  LevelData& R = refOut.levels[0];
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 128; ++x)
      for (int c = 0; c < 3; ++c) R.values[(size_t(y) * 128 + x) * R.channels + c] = refImage.at(x, 127 - y)[c];
  const SideMeans truth = sideMeans(refOut, position);
  // (session() drops the other sessions: s is not used after the next call.)
  RunRequest mapped = cone;
  mapped.sets.back() = "composite.shadow=shadow-map";
  auto& sm = session(mapped);
  const SideMeans directMapped = sideMeans(capture(sm, "composite", "direct"), capture(sm, "gbuffer", "position"));
  auto& v = session(thinWallRequest("vct-grid"));
  const SideMeans vct = sideMeans(capture(v, "cone-trace", "indirect-diffuse"), capture(v, "gbuffer", "position"));
  std::printf("thin wall, lrsm: indirect lit %.5f sealed %.5f (leak %.3f); direct (shadow cone) lit %.5f sealed %.5f "
              "(leak %.3f); direct (shadow map) sealed %.6f; vct-grid indirect lit %.5f sealed %.5f (leak %.3f); "
              "pixels %zu / %zu; reference indirect-1 lit %.5f sealed %.6f\n",
              indirect.lit, indirect.sealed, indirect.sealed / indirect.lit, direct.lit, direct.sealed,
              direct.sealed / direct.lit, directMapped.sealed, vct.lit, vct.sealed, vct.sealed / vct.lit,
              indirect.litPixels, indirect.sealedPixels, truth.lit, truth.sealed);
  ASSERT_GT(indirect.litPixels, 500u);
  ASSERT_GT(indirect.sealedPixels, 500u);
  ASSERT_GT(indirect.lit, 0.0);
  // The wall seals the half: the path tracer finds no light there at all.
  EXPECT_EQ(truth.sealed, 0.0);
  EXPECT_GT(truth.lit, 0.0);
  // The shadow map sees the wall: not one sealed pixel gets direct light.
  EXPECT_EQ(directMapped.sealed, 0.0);
  // The leak, pinned at what was measured (docs/lrsm.md; 64^3, RSM 128, 128x128): the sealed
  // half's indirect light is 0.100 of the lit half's (vct-grid's isotropic mips: 0.056), 7.9 % of
  // the true lit-side one-bounce light (reference 0.0642; lrsm's lit half 0.0507: the coverage
  // estimator gives senders their full radiance, and the wall's lit face, a back face from the
  // sealed side, blocks as much as it covers, not the isotropic mips' eighth); the shadow cone lets 0.012 of
  // the lit half's direct light through (at cone.shadow-lod-bias -1; 0.047 at the diffuse cones'
  // bias 0). The bands (x 0.5 .. x 2) fail if the leak goes away (occlusion became directional, or
  // the cones stopped reading coarse mips) or doubles.
  EXPECT_GT(indirect.sealed / indirect.lit, 0.05);
  EXPECT_LT(indirect.sealed / indirect.lit, 0.20);
  EXPECT_GT(direct.sealed / direct.lit, 0.006);
  EXPECT_LT(direct.sealed / direct.lit, 0.024);
}

}  // namespace
}  // namespace voxlab

namespace voxlab {
namespace {

// --- Direct light: every occluder the shadow map sees -----------------------------------------------

// Mean ratio of lrsm's direct output to the reference's direct image (tests/golden/reference/
// <scene>/direct.exr, box-filtered down to the output's size), camera 0.
double directMeanRatio(const std::string& scene, const std::vector<std::string>& sets) {
  RunRequest r;
  r.technique = "lrsm";
  r.scene = scene;
  r.width = r.height = 64;
  r.sets = sets;
  auto& s = session(r);
  const nlohmann::json e = compareWithReference(capture(s, "composite", "direct"), scene, 0, testing::TempDir(),
                                                "lrsm-direct");
  EXPECT_FALSE(e.is_null());
  EXPECT_FALSE(e.contains("skipped")) << e.dump();
  if (e.is_null() || e.contains("skipped")) return -1.0;
  std::printf("lrsm direct on %s (%s): mean ratio %.3f, ssim %.3f\n", scene.c_str(),
              sets.empty() ? "defaults" : sets[0].c_str(), e["mean_ratio"].get<double>(), e["ssim"].get<double>());
  return e["mean_ratio"].get<double>();
}

// skylight-room: a closed room whose only light is a sun through a 1.2 m opening in a 20 cm
// ceiling slab. The voxelized slab is two one-voxel faces with empty voxels between them, and the
// isotropic mips average them away: the shadow cone (composite.shadow=cone) crossed the ceiling
// at about half transmittance and lit every wall and the floor, 16.8x the reference's direct light
// at 256x256 (16.85x here, 64x64), in horizontal bands where a step's samples landed on or beside
// the slab. The default direct light is shadowed by the shadow map, which sees the slab: measured
// 1.002 at 256x256 and 0.991 here, deterministic (one shadow-map lookup per pixel). The band is the
// fidelity target (5 %): the sunlit patch is under a tenth of the floor, so the rest of the floor
// lit through the ceiling at 1 % of the sun would already add about 10 %.
TEST(LrsmPhysics, DefaultDirectLightSeesTheClosedCeilingOfTheSkylightRoom) {
  const double ratio = directMeanRatio("skylight-room", {});
  EXPECT_GT(ratio, 0.95);
  EXPECT_LT(ratio, 1.05);
}

}  // namespace
}  // namespace voxlab

namespace voxlab {
namespace {

// --- Analytic: a sunlit floor facing a roof ---------------------------------------------------------

// Luminance of a capture (level 0, bottom row first as GL stores it) at (x, y) counted from the top.
double lumTop(const LevelData& L, int x, int y) {
  const int row = L.size.y - 1 - y;
  return 0.2126 * L.at(x, row, 0, 0) + 0.7152 * L.at(x, row, 0, 1) + 0.0722 * L.at(x, row, 0, 2);
}

// Integral over the floor's lit half (x in [0, 1], z in [-1, 1], y = 0) of cos * cos / d^2 seen
// from (x0, 1, z0) facing down: both cosines are 1 / d at height 1, so the integrand is 1 / d^4.
// Midpoint rule on 400 x 800 cells (halving them changes it by under 1e-5).
double litHalfFormFactor(double x0, double z0) {
  const int nx = 400, nz = 800;
  const double dx = 1.0 / nx, dz = 2.0 / nz;
  double sum = 0.0;
  for (int i = 0; i < nx; ++i)
    for (int k = 0; k < nz; ++k) {
      const double x = (i + 0.5) * dx - x0, z = -1.0 + (k + 0.5) * dz - z0;
      const double d2 = x * x + 1.0 + z * z;
      sum += 1.0 / (d2 * d2);
    }
  return sum * dx * dz;
}

// half-roof.gltf (scripts/make_scenes.py sunlit_floor): a 2 x 2 m floor of albedo 0.5 under a sun
// straight down, a roof of albedo 0.5 over its -x half at y = 1, facing down. The floor's lit half
// has one radiance L (the RSM's), the half under the roof none, and nothing else is in the scene,
// so the roof's underside at (x0, 1, z0) reflects exactly 0.5 / pi * L * litHalfFormFactor(x0, z0)
// of one-bounce light. The camera under the roof looks up at it.
struct RoofRatios {
  double mean = 0.0;    // mean over the roof's pixels of lrsm / analytic
  double detail = 0.0;  // RMS of the ratio minus its 9 x 9 box mean, over the mean: rings, stripes
  size_t pixels = 0;
};

RoofRatios roofAgainstAnalytic(const std::vector<std::string>& extra) {
  RunRequest r;
  r.technique = "lrsm";
  r.scene = "tests/data/scenes/half-roof.gltf";
  r.width = r.height = 128;
  r.sets = {"voxel.resolution=64", "rsm.resolution=256"};
  for (const auto& s : extra) r.sets.push_back(s);
  r.lookFrom = glm::vec3(-0.5f, 0.2f, -0.3f);
  r.lookAt = glm::vec3(-0.5f, 1.0f, 0.2f);
  auto& s = session(r);
  const CapturedOutput out = lrsmIndirect(s);
  const CapturedOutput pos = capture(s, "gbuffer", "position");
  const CapturedOutput nor = capture(s, "gbuffer", "normal");
  const CapturedOutput rsm = capture(s, "rsm", "rsm-radiance");
  // L: the RSM's radiance of the lit floor (its brightest texels; the roof's top sends nothing).
  double L = 0.0;
  for (size_t i = 0; i < rsm.levels[0].values.size(); i += rsm.levels[0].channels)
    L = std::max(L, double(rsm.levels[0].values[i]));
  const LevelData& I = out.levels[0];
  const LevelData& P = pos.levels[0];
  const int w = I.size.x, h = I.size.y, scale = P.size.x / w;
  std::vector<double> ratio(size_t(w) * h, -1.0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int gx = x * scale, gy = (h - 1 - y) * scale;
      // The roof's underside, away from its edges by 5 cm (the voxels there hold the edge).
      if (P.at(gx, gy, 0, 3) == 0.0f || nor.levels[0].at(gx, gy, 0, 1) > -0.9f) continue;
      const double x0 = P.at(gx, gy, 0, 0), z0 = P.at(gx, gy, 0, 2);
      if (x0 > -0.05 || x0 < -0.95 || std::fabs(z0) > 0.95) continue;
      const double expect = 0.5 / 3.14159265358979 * L * litHalfFormFactor(x0, z0);
      ratio[size_t(y) * w + x] = lumTop(I, x, y) / expect;
    }
  RoofRatios rr;
  double sum = 0, detail = 0;
  size_t detailed = 0;
  const int R = 4;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double v = ratio[size_t(y) * w + x];
      if (v < 0.0) continue;
      sum += v;
      ++rr.pixels;
      double box = 0;
      int n = 0;
      bool full = x >= R && y >= R && x + R < w && y + R < h;
      for (int j = -R; full && j <= R; ++j)
        for (int i = -R; full && i <= R; ++i) {
          const double u = ratio[size_t(y + j) * w + x + i];
          if (u < 0.0) full = false;
          box += u, ++n;
        }
      if (!full) continue;
      detail += (v - box / n) * (v - box / n);
      ++detailed;
    }
  rr.mean = rr.pixels ? sum / rr.pixels : 0.0;
  rr.detail = detailed ? std::sqrt(detail / detailed) / std::max(rr.mean, 1e-9) : 0.0;
  std::printf("roof (%s): %zu pixels, lrsm / analytic mean %.3f, detail %.4f (%zu pixels), L %.4f\n",
              extra.empty() ? "defaults" : extra[0].c_str(), rr.pixels, rr.mean, rr.detail, detailed, L);
  return rr;
}

// RMS of a luminance image minus its 9 x 9 box mean over the pixels of a rectangle (top-first
// pixel coordinates, the box inside the rectangle), over the rectangle's mean: the structure at
// 4-16 pixel scale that a flat, evenly lit face should not have.
double faceDetail(const std::vector<double>& lum, int w, int x0, int y0, int x1, int y1) {
  const int R = 4;
  double mean = 0, detail = 0;
  int n = 0, m = 0;
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) mean += lum[size_t(y) * w + x], ++n;
  mean /= n;
  for (int y = y0 + R; y <= y1 - R; ++y)
    for (int x = x0 + R; x <= x1 - R; ++x) {
      double box = 0;
      for (int j = -R; j <= R; ++j)
        for (int i = -R; i <= R; ++i) box += lum[size_t(y + j) * w + x + i];
      const double d = lum[size_t(y) * w + x] - box / ((2 * R + 1) * (2 * R + 1));
      detail += d * d, ++m;
    }
  return std::sqrt(detail / m) / mean;
}

// lrsm's one-bounce indirect light on the Cornell box at the fidelity size (256x256, cones at
// 128x128), with 'sets' on top of the defaults.
CapturedOutput cornellIndirect256(const std::vector<std::string>& sets) {
  RunRequest r;
  r.technique = "lrsm";
  r.scene = "cornell-box";
  r.width = r.height = 256;
  r.sets = sets;
  return lrsmIndirect(session(r));
}

struct CornellFaces {
  double ceiling, backWall, tallBox;
};

// The Cornell box at the fidelity size (256x256, cones at 128x128): the detail of three flat faces
// (the ceiling, the back wall beside the tall box, the tall box's front face) in lrsm's indirect
// light and in the reference's indirect-1 box-filtered to the same 128x128.
CornellFaces cornellFaceDetail(const std::vector<std::string>& sets, bool reference) {
  const int w = 128;
  std::vector<double> lum(size_t(w) * w);
  if (reference) {
    const reference::Image ref = reference::readExr(referenceImagePath("cornell-box", "indirect-1"));
    const int f = ref.width / w;
    for (int y = 0; y < w; ++y)
      for (int x = 0; x < w; ++x) {
        double sum = 0;
        for (int j = 0; j < f; ++j)
          for (int i = 0; i < f; ++i) {
            const float* p = ref.at(x * f + i, y * f + j);
            sum += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
          }
        lum[size_t(y) * w + x] = sum / (f * f);
      }
  } else {
    const CapturedOutput out = cornellIndirect256(sets);
    const LevelData& I = out.levels[0];
    for (int y = 0; y < w; ++y)
      for (int x = 0; x < w; ++x) lum[size_t(y) * w + x] = lumTop(I, x, y);
  }
  const CornellFaces f{faceDetail(lum, w, 40, 3, 90, 17), faceDetail(lum, w, 70, 30, 100, 50),
                       faceDetail(lum, w, 43, 62, 60, 98)};
  std::printf("cornell faces (%s): ceiling %.4f, back wall %.4f, tall box %.4f\n",
              reference ? "reference" : sets.empty() ? "defaults" : sets[0].c_str(), f.ceiling, f.backWall, f.tallBox);
  return f;
}

// The tall box's front face in the Cornell box at the fidelity size (256x256, cones at 128x128):
// lrsm's indirect light over the reference's indirect-1 (box-filtered to 128x128) in 4x4-pixel
// cells of the face (x 44-59, y 62-97, top-first), the darkest cell's ratio over the median cell's.
// A dark patch where the reference is even sets it low, whatever the face's overall ratio. 'stage'
// and 'output' choose the image: the filtered one the composite adds, or the gathered one before
// the filter, whose cells then average one 4 x 4 tile of cone.interleave's step phases each.
double tallBoxDarkestCell(const std::vector<std::string>& sets, const char* stage, const char* output) {
  RunRequest r;
  r.technique = "lrsm";
  r.scene = "cornell-box";
  r.width = r.height = 256;
  r.sets = sets;
  const CapturedOutput out = capture(session(r), stage, output);
  const LevelData& I = out.levels[0];
  const reference::Image ref = reference::readExr(referenceImagePath("cornell-box", "indirect-1"));
  const int f = ref.width / I.size.x;
  std::vector<double> ratios;
  for (int cy = 62; cy + 4 <= 98; cy += 4)
    for (int cx = 44; cx + 4 <= 60; cx += 4) {
      double got = 0, expect = 0;
      for (int y = cy; y < cy + 4; ++y)
        for (int x = cx; x < cx + 4; ++x) {
          got += lumTop(I, x, y);
          for (int j = 0; j < f; ++j)
            for (int i = 0; i < f; ++i) {
              const float* p = ref.at(x * f + i, y * f + j);
              expect += (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / (f * f);
            }
        }
      ratios.push_back(got / expect);
    }
  std::vector<double> sorted = ratios;
  std::sort(sorted.begin(), sorted.end());
  const double darkest = sorted.front() / sorted[sorted.size() / 2];
  std::printf("tall box face (%s, %s): darkest 4x4 cell / median %.3f over %zu cells\n",
              sets.empty() ? "defaults" : sets[0].c_str(), stage, darkest, ratios.size());
  return darkest;
}

TEST(LrsmPhysics, CornellBoxFlatFacesHaveNoRingsOrStripes) {
  const CornellFaces ref = cornellFaceDetail({}, true);
  const CornellFaces lrsm = cornellFaceDetail({}, false);
  const CornellFaces oneStart = cornellFaceDetail(kUnfiltered, false);
  const CornellFaces overlap = cornellFaceDetail(unfiltered({"lrsm.layer-select=overlap"}), false);
  const CornellFaces noHorizon = cornellFaceDetail(unfiltered({"cone.horizon=false"}), false);
  // Measured (deterministic runs; the reference's noise and its real gradients give it 0.033,
  // 0.043, 0.026): lrsm 0.036, 0.024, 0.015. With one step phase for every pixel and no filter
  // (kUnfiltered) the ceiling read 0.072: swirls round the lamp, where a sample's depth window
  // meets the floor or a wall at the same height for every receiver. Eq. 15's layers
  // (lrsm.layer-select=overlap, unfiltered) halve the light on a band around every depth
  // boundary, which the spot's radial depth draws as rings: ceiling 0.210, back wall 0.100.
  // Without the horizon (unfiltered) the box's own voxels shade its face in vertical stripes:
  // 0.063. The ceiling's bound is 1.5 times the reference's, the others sit between the
  // reference and the artefact they catch.
  EXPECT_LT(ref.ceiling, 0.05);
  EXPECT_LT(ref.backWall, 0.06);
  EXPECT_LT(ref.tallBox, 0.045);
  EXPECT_LT(lrsm.ceiling, 0.05);
  EXPECT_LT(lrsm.backWall, 0.06);
  EXPECT_LT(lrsm.tallBox, 0.045);
  EXPECT_GT(oneStart.ceiling, 0.05);
  EXPECT_GT(overlap.ceiling, 0.05);
  EXPECT_GT(overlap.backWall, 0.06);
  EXPECT_GT(noHorizon.tallBox, 0.045);
}

TEST(LrsmPhysics, CornellTallBoxFaceHasNoDarkPatch) {
  // Measured (deterministic): the darkest cell 0.850 of the median at the defaults, after the
  // filter and before it alike (a 4x4 cell of the gathered image averages one tile of the 16 step
  // phases: the interleaving, not the filter, lifts the patch); 0.792 with one step phase for
  // every pixel (kUnfiltered: a dark patch low in the face's middle, which the one phase puts
  // there: with sixteen phases it is gone before any filtering), 0.828 with one phase and the
  // filter. The bound sits between the interleaved and the single phase.
  EXPECT_GT(tallBoxDarkestCell({}, "filter", "indirect-filtered"), 0.82);
  EXPECT_GT(tallBoxDarkestCell({}, "cone-gather", "indirect-diffuse"), 0.82);
  EXPECT_LT(tallBoxDarkestCell(kUnfiltered, "filter", "indirect-filtered"), 0.82);
}

// The short box's front face in the Cornell box at the fidelity size (256x256, cones at 128x128):
// the spread (standard deviation) of log(lrsm / reference) over 4x4-pixel cells of the face, the
// reference's indirect-1 box-filtered to 128x128. A face lit evenly in the reference should be lit
// evenly in lrsm, whatever the overall ratio.
double shortBoxFaceSpread(const std::vector<std::string>& sets) {
  const CapturedOutput out = cornellIndirect256(sets);
  const LevelData& I = out.levels[0];
  const reference::Image ref = reference::readExr(referenceImagePath("cornell-box", "indirect-1"));
  const int f = ref.width / I.size.x;
  const int cell = 4, x0 = 64, y0 = 89, x1 = 92, y1 = 117;  // the face, top-first pixels
  double sum = 0, sum2 = 0;
  int n = 0;
  for (int cy = y0; cy + cell <= y1; cy += cell)
    for (int cx = x0; cx + cell <= x1; cx += cell) {
      double got = 0, expect = 0;
      for (int y = cy; y < cy + cell; ++y)
        for (int x = cx; x < cx + cell; ++x) {
          got += lumTop(I, x, y);
          for (int j = 0; j < f; ++j)
            for (int i = 0; i < f; ++i) {
              const float* p = ref.at(x * f + i, y * f + j);
              expect += (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / (f * f);
            }
        }
      const double l = std::log(got / expect);
      sum += l, sum2 += l * l, ++n;
    }
  const double mean = sum / n, spread = std::sqrt(std::max(sum2 / n - mean * mean, 0.0));
  std::printf("short box face (%s): log-ratio spread %.3f over %d cells, mean ratio %.3f\n",
              sets.empty() ? "defaults" : sets[0].c_str(), spread, n, std::exp(mean));
  return spread;
}

TEST(LrsmPhysics, CornellShortBoxFaceFollowsTheReference) {
  // The reference lights the face evenly. A sample in front of the face, near the boundary of the
  // box's shadow volume, reads one layer that holds both the box's top and the lit floor beyond
  // its shadow (both face up; 2 depth intervals put them in one). One Gaussian fitted to both
  // (lrsm.two-lobes=false) puts surface between the two depths, where the sample sits in empty
  // air, and its mean point there, behind the face's plane for the samples low on the face: a
  // diagonal band, light above it (upper left 2.5x the reference) and none below (lower right
  // 0.2x). Measured (deterministic): 0.647 with one Gaussian (unfiltered, one step phase; 0.477
  // after the filter, which blurs the band's edge); 0.189 with the two depth lobes (defaults; 0.201
  // before the steps were interleaved and filtered), 0.150 and 0.147 with the lobes blended in
  // from sigma^2 = 0.002 and 0.0003; 0.182 with one Gaussian and 3 depth intervals
  // (lrsm.depth-splits=2). The bound 0.30 sits between the band and the fix; the single Gaussian
  // must still show the band (above 0.5), or the test no longer measures it.
  EXPECT_LT(shortBoxFaceSpread({}), 0.30);
  EXPECT_GT(shortBoxFaceSpread(unfiltered({"lrsm.two-lobes=false"})), 0.5);
}

// The corridor suite scene: 12 m long, its point light 0.6 m from the far end wall, the camera at
// the other end. lrsm's indirect light (128x128, cones at 64x64) over the reference's indirect-1
// box-filtered to the same size: the whole image's mean, and the lower quarter's (the floor and the
// walls near the camera, 11 m from the lamp).
struct CorridorRatios {
  double whole, nearCamera;
};

CorridorRatios corridorRatios() {
  RunRequest r;
  r.technique = "lrsm";
  r.scene = "corridor";
  r.width = r.height = 128;
  auto& s = session(r);
  const CapturedOutput out = lrsmIndirect(s);
  const LevelData& I = out.levels[0];
  const int w = I.size.x;
  const reference::Image ref = reference::readExr(referenceImagePath("corridor", "indirect-1"));
  const int f = ref.width / w;
  double sumLrsm[2] = {0, 0}, sumRef[2] = {0, 0};
  for (int y = 0; y < w; ++y)
    for (int x = 0; x < w; ++x) {
      double expect = 0;
      for (int j = 0; j < f; ++j)
        for (int i = 0; i < f; ++i) {
          const float* p = ref.at(x * f + i, y * f + j);
          expect += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        }
      expect /= f * f;
      const double got = lumTop(I, x, y);
      sumLrsm[0] += got, sumRef[0] += expect;
      if (y >= 3 * w / 4) sumLrsm[1] += got, sumRef[1] += expect;
    }
  const CorridorRatios c{sumLrsm[0] / sumRef[0], sumLrsm[1] / sumRef[1]};
  std::printf("corridor: lrsm / reference indirect-1 %.3f, lower quarter %.3f\n", c.whole, c.nearCamera);
  return c;
}

TEST(LrsmPhysics, CorridorLitFromItsFarEndAgainstTheReferencePathTracer) {
  const CorridorRatios c = corridorRatios();
  // Measured (deterministic): 0.808 over the image, 0.962 over the lower quarter; 0.910 and
  // 1.166 with one step phase for every pixel (cone.interleave=false, before the filter), 0.906
  // and 1.306 with that and one Gaussian per layer. Before the cone samples that reach near the
  // lamp were bounded by the solid angle their surface can fill, they read 1.990 and 11.59: the
  // lamp's bright surroundings spread over the whole cross-section of the far samples. Bands
  // x0.8 .. x1.25 of the defaults' measurements.
  EXPECT_GT(c.whole, 0.65);
  EXPECT_LT(c.whole, 1.01);
  EXPECT_GT(c.nearCamera, 0.77);
  EXPECT_LT(c.nearCamera, 1.20);
}

TEST(LrsmPhysics, RoofOverASunlitFloorAgainstTheAnalyticIrradiance) {
  const RoofRatios coverage = roofAgainstAnalytic({});
  const RoofRatios paper = roofAgainstAnalytic(unfiltered(paperSettings()));
  const RoofRatios noLayers =
      roofAgainstAnalytic(unfiltered({"lrsm.depth-splits=0", "lrsm.normal-splits=0", "lrsm.two-lobes=false"}));
  ASSERT_GT(coverage.pixels, 2000u);
  // Measured (deterministic): the coverage estimator 1.092 of the exact answer; 1.453 with one
  // step phase for every pixel (cone.interleave=false). The bias is the estimator's: a sphere
  // whose depth window reaches a plane counts the plane's whole footprint, so the tilted cones,
  // whose lower half meets the lit floor and upper half the open side, count the floor over more
  // of their cross-section than it covers, and with one phase every receiver of the flat roof puts
  // its samples at the same heights, so that the overcount is the same everywhere instead of
  // averaging over where the windows fall (docs/lrsm.md; with cone.horizon off the roof's own
  // voxels shade the cones by about as much). Algorithm 1 as printed (unfiltered, one phase):
  // 0.075. Bands x0.8 .. x1.25.
  EXPECT_GT(coverage.mean, 0.87);
  EXPECT_LT(coverage.mean, 1.37);
  EXPECT_GT(paper.mean, 0.059);
  EXPECT_LT(paper.mean, 0.093);
  // The exact answer is smooth; what lrsm adds at 9-pixel scale (18 camera pixels) is its own:
  // measured 0.009 at the defaults (0.030 with one phase and no filter), and, with one phase and
  // no filter (which would smooth what this measures), 0.052 as printed (alpha_i times the sum,
  // Eq. 15's layers) and 0.047 with one layer and one Gaussian (floor and roof in one set of
  // moments; with one layer the two depth lobes tell them apart: 0.030). 0.040 fails both.
  EXPECT_LT(coverage.detail, 0.040);
  EXPECT_GT(paper.detail, 0.040);
  EXPECT_GT(noLayers.detail, 0.040);
}

}  // namespace
}  // namespace voxlab

