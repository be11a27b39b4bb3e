// The soft-shadow cone of every technique that traces one (an output named "soft-shadow"), against
// exact visibility from the reference tracer's ray queries (physics tier). Found through the
// technique registry, so a new technique with a shadow cone is checked without being named here.
//
// The known error it catches: a shadow cone marched all the way to a point light ends inside the
// fixture the light hangs from (the Cornell box's spot is 1 cm below the ceiling and its panel),
// and as the number of whole steps changes with the distance, its last samples take in more or
// less of it: concentric rings of visibility 0.3 to 0.9 over walls that nothing shadows
// (shaders/common/lights.glsl, shadowConeEnd).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <glm/gtc/constants.hpp>

#include "common/shared.h"
#include "graph/technique.h"
#include "reference/path_tracer.h"
#include "test_support.h"

using namespace voxlab;
using namespace voxlab::testing_support;

namespace {

struct ShadowStages {
  std::string shadow, gbuffer;  // stage ids of the outputs "soft-shadow" and "position"/"normal"
};

ShadowStages findStages(const std::string& techniqueId) {
  auto technique = createTechnique(techniqueId);
  const std::vector<std::string> ids = technique->stageIds();
  ShadowStages s;
  for (int i = 0; i < technique->stageCount(); ++i)
    for (const OutputDesc& o : technique->decl(i).outputs) {
      if (o.name == "soft-shadow") s.shadow = ids[size_t(i)];
      if (o.name == "position") s.gbuffer = ids[size_t(i)];
    }
  return s;
}

// How many of nine rays from p towards the light are blocked over their first 80 %: the axis and
// eight rays to points on a circle around the light of the cone's radius there, for a cone wider
// than any default shadow cone (12 degrees; the defaults are 8 and 10). 0: the whole cone is clear;
// 9: the pixel is in the umbra; anything between: a penumbra.
int blockedRays(const reference::ReferenceTracer& tracer, glm::vec3 p, glm::vec3 n, glm::vec3 light) {
  const glm::vec3 o = p + n * 1e-3f;
  const glm::vec3 axis = light - o;
  const float dist = glm::length(axis);
  const glm::vec3 d = axis / dist;
  const glm::vec3 t = glm::normalize(std::abs(d.y) < 0.9f ? glm::cross(d, glm::vec3(0, 1, 0)) : glm::cross(d, glm::vec3(1, 0, 0)));
  const glm::vec3 b = glm::cross(d, t);
  const float radius = dist * std::tan(0.5f * glm::radians(12.0f));
  int blocked = 0;
  for (int k = 0; k < 9; ++k) {
    glm::vec3 target = light;
    if (k > 0) {
      const float a = float(k - 1) * glm::two_pi<float>() / 8.0f;
      target += radius * (std::cos(a) * t + std::sin(a) * b);
    }
    const glm::vec3 ray = target - o;
    const float len = glm::length(ray);
    blocked += tracer.occluded(o, ray / len, 0.8f * len) ? 1 : 0;
  }
  return blocked;
}

}  // namespace

// On the Cornell box, every pixel that faces the spot (cosine >= 0.5: no grazing cone over its own
// surface) and whose whole cone towards it is clear must read the light as visible; those whose
// whole cone is blocked must read it as mostly hidden.
TEST(SoftShadowCone, AgreesWithExactVisibility) {
  int checked = 0;
  for (const TechniqueEntry& entry : techniqueRegistry()) {
    const ShadowStages stages = findStages(entry.id);
    if (stages.shadow.empty()) continue;
    ASSERT_FALSE(stages.gbuffer.empty()) << entry.id << ": a soft-shadow output without a G-buffer position";
    RunRequest request;
    request.technique = entry.id;
    request.width = request.height = 256;
    auto& s = session(request);
    const CapturedOutput position = capture(s, stages.gbuffer, "position");
    const CapturedOutput normal = capture(s, stages.gbuffer, "normal");
    const CapturedOutput shadow = capture(s, stages.shadow, "soft-shadow");
    voxlab::gpu::GpuLight light;
    auto bytes = s.cursor().board().buffer("light").download(sizeof light);
    std::memcpy(&light, bytes.data(), sizeof light);
    ASSERT_EQ(int(light.positionType.w), VOXLAB_LIGHT_SPOT) << entry.id;
    const glm::vec3 lightPos(light.positionType);
    const reference::ReferenceTracer tracer(s.cursor().scene());

    const LevelData& P = position.levels.at(0);
    const LevelData& N = normal.levels.at(0);
    const LevelData& V = shadow.levels.at(0);
    const int scale = P.size.x / V.size.x;  // the cone's traced resolution: full or half
    ASSERT_GE(scale, 1) << entry.id;
    size_t pixels = 0, dark = 0, umbra = 0, umbraLit = 0;
    double umbraSum = 0.0;
    double sum = 0.0, least = 1.0;
    for (int y = 0; y < V.size.y; ++y)
      for (int x = 0; x < V.size.x; ++x) {
        // A traced pixel shades the top-left G-buffer pixel of its block.
        const size_t g = size_t(std::min(y * scale, P.size.y - 1)) * P.size.x + size_t(std::min(x * scale, P.size.x - 1));
        if (P.values[g * P.channels + 3] == 0.0f) continue;
        const glm::vec3 p(P.values[g * P.channels], P.values[g * P.channels + 1], P.values[g * P.channels + 2]);
        const glm::vec3 n = glm::normalize(glm::vec3(N.values[g * N.channels], N.values[g * N.channels + 1], N.values[g * N.channels + 2]));
        if (glm::dot(n, glm::normalize(lightPos - p)) < 0.5f) continue;
        const int blocked = blockedRays(tracer, p, n, lightPos);
        if (blocked == 9) {
          const float v = V.values[(size_t(y) * V.size.x + x) * V.channels];
          ++umbra;
          umbraSum += v;
          umbraLit += v > 0.5f;
          continue;
        }
        if (blocked > 0) continue;
        const float v = V.values[(size_t(y) * V.size.x + x) * V.channels];
        ++pixels;
        sum += v;
        least = std::min(least, double(v));
        dark += v < 0.9f;
      }
    const double mean = pixels ? sum / double(pixels) : 0.0;
    std::printf("%s: %zu clear pixels facing the light, visibility mean %.4f, least %.4f, below 0.9: %zu (%.2f %%)\n",
                entry.id.c_str(), pixels, mean, least, dark, 100.0 * double(dark) / double(std::max<size_t>(pixels, 1)));
    std::printf("%s: %zu umbra pixels facing the light, visibility mean %.4f, above 0.5: %zu\n", entry.id.c_str(),
                umbra, umbraSum / double(std::max<size_t>(umbra, 1)), umbraLit);
    ASSERT_GT(pixels, 2000u) << entry.id;
    // Measured (256x256, defaults, 5979 pixels; 2026-12-02, one and two llvmpipe threads alike):
    // mean 0.998 (lrsm), 1.000 (svo), 0.997 (vct-grid), with 0.05, 0 and 0.18 % of the pixels below
    // 0.9 (cones starting near a box edge); while the cones ended at the light, inside its
    // fixture: mean 0.915, 0.936 and 0.610, with 27, 16 and 99.6 % below 0.9. The values are the
    // same at one and two threads; the bounds (mean above 0.99, under 1 % below 0.9) sit between
    // the two.
    EXPECT_GT(mean, 0.99) << entry.id;
    EXPECT_LT(double(dark), 0.01 * double(pixels)) << entry.id;
    // And where every ray of the cone is blocked (the boxes' shadows on the floor and the red wall),
    // the light must read as mostly hidden. Measured: 441 pixels; mean visibility 0.018 (vct-grid),
    // 0.040 (svo; 0.146 while its shadow cone read the voxel halo), 0.137 (lrsm; 0.336 with its shadow cone at the diffuse cones' lod bias 0, which
    // reads the boxes' one-voxel shells at coarse mips and sees through them: 140 of the 441 umbra
    // pixels above 0.5; docs/fidelity.md, lrsm). The bound, 0.25, sits between the two; a cone that
    // ignored the occluders reads 1.
    ASSERT_GT(umbra, 200u) << entry.id;
    EXPECT_LT(umbraSum / double(umbra), 0.25) << entry.id;
    ++checked;
  }
  EXPECT_GE(checked, 3);  // vct-grid, svo and lrsm trace a shadow cone today
}
