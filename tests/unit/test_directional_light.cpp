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
#include <filesystem>
#include <fstream>
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

namespace fs = std::filesystem;

const glm::vec3 kSunDirection = glm::normalize(glm::vec3(-0.3f, -1.0f, 0.2f));
constexpr float kIrradiance = 2.0f, kAlbedo = 0.5f;
const float kLit = kAlbedo / 3.14159265f * kIrradiance * -kSunDirection.y;  // 0.29944

// The wall: x 0.60..0.62, z -0.2..0.2, height 0.5; its shadow on the floor spans x from
// 0.60 - 0.5 * 0.3 = 0.45 to 0.62 and z shifted by up to +0.1. Points well inside it:
bool inShadowCore(glm::vec3 p) { return p.x > 0.49f && p.x < 0.57f && p.z > -0.1f && p.z < 0.15f; }
// Points lit and far from the wall and the floor's edges:
bool inLitCore(glm::vec3 p) { return std::abs(p.x) < 0.4f && std::abs(p.z) < 0.4f; }

std::string writeScene() {
  const fs::path dir = fs::path(::testing::TempDir()) / "voxlab-directional";
  fs::create_directories(dir);
  // Floor (2 triangles, +y) and the wall as a closed box (12 triangles).
  std::vector<float> pos = {-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1};
  std::vector<uint32_t> idx = {0, 2, 1, 0, 3, 2};
  const glm::vec3 lo(0.6f, 0.0f, -0.2f), hi(0.62f, 0.5f, 0.2f);
  uint32_t base = 4;
  for (int k = 0; k < 8; ++k) {
    pos.push_back((k & 1) ? hi.x : lo.x);
    pos.push_back((k & 2) ? hi.y : lo.y);
    pos.push_back((k & 4) ? hi.z : lo.z);
  }
  const uint32_t box[36] = {0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2,
                            1, 3, 7, 1, 7, 5, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6};
  for (uint32_t i : box) idx.push_back(base + i);
  std::ofstream bin(dir / "directional.bin", std::ios::binary);
  bin.write(reinterpret_cast<const char*>(pos.data()), std::streamsize(pos.size() * 4));
  bin.write(reinterpret_cast<const char*>(idx.data()), std::streamsize(idx.size() * 4));
  bin.close();
  const glm::quat q = glm::rotation(glm::vec3(0, 0, -1), kSunDirection);
  const glm::quat down = glm::rotation(glm::vec3(0, 0, -1), glm::vec3(0, -1, 0));
  auto quatJson = [](glm::quat r) {
    return "[" + std::to_string(r.x) + "," + std::to_string(r.y) + "," + std::to_string(r.z) + "," + std::to_string(r.w) + "]";
  };
  const size_t p = pos.size() * 4, n = idx.size() * 4;
  std::string gltf =
      "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2]}],"
      "\"nodes\":[{\"mesh\":0},{\"camera\":0,\"translation\":[0,2.5,0],\"rotation\":" + quatJson(down) + "},"
      "{\"rotation\":" + quatJson(q) + ",\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}],"
      "\"extensionsUsed\":[\"KHR_lights_punctual\"],"
      "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"directional\",\"intensity\":" +
      std::to_string(kIrradiance) + "}]}},"
      "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.9,\"znear\":0.05,\"zfar\":20}}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1,\"material\":0}]}],"
      "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.5,0.5,1]}}],"
      "\"buffers\":[{\"uri\":\"directional.bin\",\"byteLength\":" + std::to_string(p + n) + "}],"
      "\"bufferViews\":[{\"buffer\":0,\"byteLength\":" + std::to_string(p) + "},"
      "{\"buffer\":0,\"byteOffset\":" + std::to_string(p) + ",\"byteLength\":" + std::to_string(n) + "}],"
      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":" + std::to_string(pos.size() / 3) +
      ",\"type\":\"VEC3\"},{\"bufferView\":1,\"componentType\":5125,\"count\":" + std::to_string(idx.size()) +
      ",\"type\":\"SCALAR\"}]}";
  const std::string path = (dir / "directional.gltf").string();
  std::ofstream(path) << gltf;
  return path;
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
