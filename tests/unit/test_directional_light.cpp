// A directional light through the whole pipeline, against the light model's own
// answer: a 2 x 2 m floor of albedo 0.5 under a sun of irradiance E = 2 W/m^2 travelling along
// (-0.3, -1, 0.2), with a small wall (0.5 m high) casting a shadow towards the camera's side.
// A lit floor point reflects L = albedo / pi * E * cos(theta) = 0.5 / pi * 2 / |(-0.3, -1, 0.2)|
// = 0.29944 (scene/light_model.h).
// Checked: vct-grid's composite/direct (G-buffer + fitted shadow map), its injected voxels, and
// the reference tracer's direct mode (next-event estimation to the sun) see L where lit and 0 in
// the wall's shadow.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtx/quaternion.hpp>

#include "reference/path_tracer.h"
#include "scene/scene.h"
#include "techniques/common/voxel_space.h"
#include "test_support.h"

namespace voxlab {
namespace {

const glm::vec3 kSunDirection = glm::normalize(glm::vec3(-0.3f, -1.0f, 0.2f));
constexpr float kIrradiance = 2.0f, kAlbedo = 0.5f;
const float kLit = kAlbedo / 3.14159265f * kIrradiance * -kSunDirection.y;  // 0.29944

// The wall: x 0.60..0.62, z -0.2..0.2, height 0.5; its shadow on the floor spans x from
// 0.60 - 0.5 * 0.3 = 0.45 to 0.62 and z shifted by up to +0.1. Points well inside it:
bool inShadowCore(glm::vec3 p) { return p.x > 0.49f && p.x < 0.57f && p.z > -0.1f && p.z < 0.15f; }
// Points lit and far from the wall and the floor's edges:
bool inLitCore(glm::vec3 p) { return std::abs(p.x) < 0.4f && std::abs(p.z) < 0.4f; }

// The sun's node rotation turns -z (a light's direction in its node) onto kSunDirection.
std::string writeScene() {
  const glm::quat q = glm::rotation(glm::vec3(0, 0, -1), kSunDirection);
  const std::string rotation = "[" + std::to_string(q.x) + "," + std::to_string(q.y) + "," + std::to_string(q.z) +
                               "," + std::to_string(q.w) + "]";
  return testing_support::writeFloorAndWallScene(
      "directional", "{\"type\":\"directional\",\"intensity\":" + std::to_string(kIrradiance) + "}",
      "\"rotation\":" + rotation);
}

const std::string& scenePath() {
  static const std::string p = writeScene();
  return p;
}

TEST(DirectionalLight, VctGridDirectAndInjectionFollowTheLightModel) {
  RunRequest r;
  r.technique = "vct-grid";
  r.scene = scenePath();
  r.sets = {"voxel.resolution=64", "voxel.format=rgba8"};  // the voxel check below counts in 8-bit steps
  r.width = r.height = 128;
  HeadlessSession& s = testing_support::session(r);
  ASSERT_EQ(s.cursor().scene().lights.size(), 1u);
  ASSERT_EQ(s.cursor().scene().lights[0].type, LightType::Directional);
  CapturedOutput position = testing_support::capture(s, "gbuffer", "position");
  CapturedOutput direct = testing_support::capture(s, "composite", "direct");
  const LevelData& P = position.levels.at(0);
  const LevelData& D = direct.levels.at(0);
  size_t lit = 0, shadowed = 0;
  double worstLit = 0.0, worstShadow = 0.0;
  for (int y = 0; y < P.size.y; ++y)
    for (int x = 0; x < P.size.x; ++x) {
      if (P.at(x, y, 0, 3) < 0.5f) continue;  // background
      glm::vec3 p(P.at(x, y, 0, 0), P.at(x, y, 0, 1), P.at(x, y, 0, 2));
      if (std::abs(p.y) > 1e-3f) continue;  // the wall
      float d = D.at(x, y, 0, 0);
      if (inLitCore(p)) {
        ++lit;
        worstLit = std::max(worstLit, double(std::abs(d - kLit)));
      } else if (inShadowCore(p)) {
        ++shadowed;
        worstShadow = std::max(worstShadow, double(d));
      }
    }
  EXPECT_GT(lit, 1500u);
  EXPECT_GT(shadowed, 20u);
  // The G-buffer stores albedo in RGBA8 (0.5 -> 128/255), composite/direct in rgba16f (a half
  // float step near 0.3 is 2.4e-4): expected 128/255 / pi * E * cos.
  const float litGBuffer = kLit * (128.0f / 255.0f) / kAlbedo;
  worstLit = 0.0;
  for (int y = 0; y < P.size.y; ++y)
    for (int x = 0; x < P.size.x; ++x) {
      glm::vec3 p(P.at(x, y, 0, 0), P.at(x, y, 0, 1), P.at(x, y, 0, 2));
      if (P.at(x, y, 0, 3) >= 0.5f && std::abs(p.y) <= 1e-3f && inLitCore(p))
        worstLit = std::max(worstLit, double(std::abs(D.at(x, y, 0, 0) - litGBuffer)));
    }
  EXPECT_LT(worstLit, 3e-4) << "lit floor vs " << litGBuffer;
  EXPECT_EQ(worstShadow, 0.0) << "inside the wall's shadow";

  // Injected voxels of the lit floor (one layer of voxels; all its fragments carry one value).
  CapturedOutput injected = testing_support::capture(s, "inject", "radiance-injected");
  const LevelData& V = injected.levels.at(0);
  const VoxelSpace space = VoxelSpace::fromScene(s.cursor().scene(), 64);
  const int layer = int(std::floor(space.toVoxel(glm::vec3(0.0f)).y));
  size_t voxels = 0, off = 0;
  // Fragments carry albedo in RGBA8 too: 128/255 / pi * E * cos = 0.30061, stored as 77/255.
  const float litVoxel = std::round(litGBuffer * 255.0f) / 255.0f;
  for (int z = 0; z < 64; ++z)
    for (int x = 0; x < 64; ++x) {
      glm::vec3 c = space.origin + (glm::vec3(x, layer, z) + 0.5f) * space.voxelSize;
      if (!inLitCore(c)) continue;
      ++voxels;
      if (std::abs(V.at(x, layer, z, 0) - litVoxel) > 1e-5f) {
        if (++off < 4) ADD_FAILURE() << "voxel " << x << "," << layer << "," << z << ": " << V.at(x, layer, z, 0);
      }
    }
  EXPECT_GT(voxels, 200u);
  EXPECT_EQ(off, 0u) << "injected floor voxels differ from " << litVoxel;
}

TEST(DirectionalLight, ReferenceTracerDirectFollowsTheLightModel) {
  Scene scene = loadScene(scenePath());
  reference::ReferenceTracer tracer(scene);
  const glm::vec3 eye(0.0f, 2.5f, 0.0f);
  // The sun is evaluated exactly (no random numbers involved): one sample per point.
  for (glm::vec3 p : {glm::vec3(0.1f, 0.0f, -0.2f), glm::vec3(-0.3f, 0.0f, 0.3f)}) {
    reference::Estimate e = tracer.estimateRadiance(eye, p - eye, reference::Mode::Direct, 1);
    EXPECT_NEAR(e.mean.x, kLit, 1e-5) << p.x << "," << p.z;
  }
  reference::Estimate shadow =
      tracer.estimateRadiance(eye, glm::vec3(0.53f, 0.0f, 0.02f) - eye, reference::Mode::Direct, 1);
  EXPECT_EQ(shadow.mean.x, 0.0);
}

}  // namespace
}  // namespace voxlab
