// Crytek Sponza (scenes/sponza, written by scripts/make_sponza.py): what the scene file promises
// (metres, 262,267 triangles, the three MASK materials, the sun, the cameras, textures at most
// 1024 px), and the voxelization exactness check: every conservative method agrees
// with the CPU reference at 128^3, leaves and chains included.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/paths.h"
#include "reference/cpu_voxelizer.h"
#include "scene/scene.h"
#include "techniques/common/voxel_space.h"
#include "test_support.h"

namespace voxlab {
namespace {

const Scene& sponza() {
  static const Scene scene = [] {
    auto t0 = std::chrono::steady_clock::now();
    Scene s = loadScene(resolveScenePath("sponza"));
    double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    ::testing::Test::RecordProperty("sponza_load_ms", int(ms));
    return s;
  }();
  return scene;
}

TEST(Sponza, SceneInMetresWithMasksSunAndCameras) {
  const Scene& s = sponza();
  EXPECT_EQ(s.triangleCount(), 262267u);
  EXPECT_EQ(s.materials.size(), 25u);
  // The source's bounds (centimetres) x 0.01: min (-19.2, -1.264, -11.825), max (17.9875, 14.2875, 11.05).
  EXPECT_NEAR(s.bounds.min.x, -19.2f, 0.01f);
  EXPECT_NEAR(s.bounds.max.y, 14.2875f, 0.01f);
  EXPECT_NEAR(s.bounds.extent().z, 22.875f, 0.02f);
  // MASK materials: chain and vase plant at 0.5, leaves at 0.3, all double-sided.
  std::set<std::string> masked;
  for (const Material& m : s.materials)
    if (m.alphaMode == AlphaMode::Mask) {
      masked.insert(m.name);
      EXPECT_TRUE(m.doubleSided) << m.name;
      EXPECT_FLOAT_EQ(m.alphaCutoff, m.name == "leaf" ? 0.3f : 0.5f) << m.name;
      ASSERT_GE(m.baseColorTexture, 0) << m.name;
    }
  EXPECT_EQ(masked, (std::set<std::string>{"chain", "leaf", "Material__57"}));
  // Base-colour textures only (normal maps are not decoded), none above 1024 px.
  EXPECT_EQ(s.textures.size(), 24u);
  for (const TextureImage& t : s.textures) {
    EXPECT_LE(std::max(t.width, t.height), 1024) << t.name;
    EXPECT_EQ(t.rgba8.size(), size_t(t.width) * t.height * 4) << t.name;
  }
  // The sun: directional, mostly downward, tilted towards -z (through the roof onto the floor and
  // the -z gallery).
  ASSERT_EQ(s.lights.size(), 1u);
  const Light& sun = s.lights[0];
  EXPECT_EQ(sun.type, LightType::Directional);
  const glm::vec3 expected = glm::normalize(glm::vec3(0.15f, -1.0f, -0.25f));
  EXPECT_GT(glm::dot(sun.direction, expected), 0.99999f);
  EXPECT_GT(sun.intensity, 0.0f);
  // Cameras: the nave view (the default) looks along -x, the second at the lit floor (down, -z).
  ASSERT_EQ(s.cameras.size(), 2u);
  EXPECT_EQ(s.cameras[0].name, "nave");
  EXPECT_LT(s.cameras[0].forward.x, -0.95f);
  EXPECT_EQ(s.cameras[1].name, "lit-floor-curtains");
  EXPECT_LT(s.cameras[1].forward.y, 0.0f);
  EXPECT_LT(s.cameras[1].forward.z, 0.0f);
}

TEST(Sponza, ListedAndResolvedByName) {
  std::vector<std::string> names = listScenes();
  EXPECT_NE(std::find(names.begin(), names.end(), "sponza"), names.end());
  EXPECT_NE(resolveScenePath("sponza").find("scenes/sponza/sponza.gltf"), std::string::npos);
}

// The voxelization CPU reference agrees exactly with the conservative methods on
// Sponza at 128^3, leaves and chains included (their alpha coverage follows one rule on both
// sides, scene/alpha_coverage.h). About 6 s here (the CPU reference visits every triangle's
// voxel box in double); the whole check runs in this one test.
TEST(Sponza, ConservativeMethodsEqualCpuReferenceAt128) {
  const int res = 128;
  RunRequest r;
  r.technique = "voxelization";
  r.scene = "sponza";
  r.sets = {"voxel.resolution=" + std::to_string(res)};
  r.until = "voxelize";
  r.width = r.height = 32;
  HeadlessSession& s = testing_support::session(r);
  const Scene& scene = s.cursor().scene();
  std::vector<uint32_t> ref = referenceVoxelSet(scene, VoxelSpace::fromScene(scene, res));
  std::set<uint32_t> refSet(ref.begin(), ref.end());
  ::testing::Test::RecordProperty("sponza_128_reference_voxels", int(ref.size()));
  EXPECT_GT(ref.size(), 90000u);  // measured 97592
  for (const char* method : {"fragment-parallel", "triangle-parallel"}) {
    s.cursor().setParamText("voxelize.method", method);
    s.cursor().runThrough(s.cursor().technique().stageIndex("voxelize"));
    CapturedOutput fragments = testing_support::capture(s, "voxelize", "fragments");
    std::set<uint32_t> gpu;
    for (uint32_t i = 0; i < fragments.recordCount; ++i) {
      uint32_t packed;
      std::memcpy(&packed, &fragments.records[size_t(i) * fragments.desc.layout.stride], 4);
      gpu.insert(packed);
    }
    size_t missed = 0, added = 0;
    for (uint32_t k : ref) missed += gpu.count(k) ? 0 : 1;
    for (uint32_t k : gpu) added += refSet.count(k) ? 0 : 1;
    ::testing::Test::RecordProperty(std::string("sponza_128_") + method + "_missed", int(missed));
    ::testing::Test::RecordProperty(std::string("sponza_128_") + method + "_added", int(added));
    EXPECT_EQ(missed, 0u) << method << " misses " << missed << " of " << ref.size() << " reference voxels";
    EXPECT_EQ(added, 0u) << method << " adds " << added << " voxels";
  }
}

// `voxlab run --technique T --scene sponza` for both techniques, as a user runs it (the binary,
// a fresh process): exit status 0 and a complete manifest; the voxelization's compare stage
// reports 0 missed and 0 added voxels, vct-grid's final image is not black.
TEST(Sponza, CommandLineRunsBothTechniques) {
  const std::string out = ::testing::TempDir() + "voxlab-sponza-run";
  for (const char* technique : {"voxelization", "vct-grid"}) {
    const std::string dir = out + "-" + technique;
    std::string cmd = std::string(VOXLAB_BINARY) + " run --technique " + technique +
                      " --scene sponza --set voxel.resolution=64 --size 64x64 --final-only --out " + dir +
                      " > /dev/null";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    nlohmann::json m = nlohmann::json::parse(readTextFile(dir + "/manifest.json"));
    EXPECT_TRUE(m["complete"].get<bool>()) << technique;
    EXPECT_EQ(m["scene"], "sponza");
    for (const auto& stage : m["stages"]) {
      if (stage["id"] == "compare") {
        EXPECT_EQ(stage["stats"]["missed_voxels"].get<double>(), 0.0);
        EXPECT_EQ(stage["stats"]["added_voxels"].get<double>(), 0.0);
        EXPECT_GT(stage["stats"]["reference_voxels"].get<double>(), 10000.0);
      }
      if (stage["id"] == "composite") {
        const auto& final = stage["outputs"].back();
        ASSERT_EQ(final["name"], "final");
        EXPECT_GT(final["statistics"]["levels"][0]["mean"][0].get<double>(), 0.01) << "vct-grid's final image is black";
      }
    }
  }
}

}  // namespace
}  // namespace voxlab
