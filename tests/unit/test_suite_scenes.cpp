// The fidelity suite (scenes/suite.json, scripts/make_suite_scenes.py): every listed scene loads,
// has the four reference images `voxlab fidelity` compares with (direct, indirect-1, indirect-2,
// full) with their metadata and noise, and the references agree with each other and with the
// suite's own invariants: full >= indirect-1 + direct (more paths only add light), the scene in
// centimetres has the picture of the scene in metres, and the open scene's sky comes from the file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "run/reference_error.h"
#include "core/error.h"
#include "core/paths.h"
#include "reference/image_io.h"
#include "scene/scene.h"

namespace voxlab {
namespace {

namespace fs = std::filesystem;

struct SuiteEntry {
  std::string name;
  bool interior = false;
};

std::vector<SuiteEntry> suite() {
  std::ifstream in(projectPath("scenes/suite.json"));
  nlohmann::json doc = nlohmann::json::parse(in);
  std::vector<SuiteEntry> out;
  for (const auto& s : doc.at("scenes")) out.push_back({s.at("name"), s.at("interior")});
  return out;
}

struct Reference {
  reference::Image img;
  std::map<std::string, std::string> attrs;
  double mean() const {
    double sum = 0.0;
    for (float v : img.rgb) sum += v;
    return sum / double(img.rgb.size());
  }
};

Reference load(const std::string& scene, const std::string& mode) {
  Reference r;
  reference::ImageAttributes attrs;
  r.img = reference::readExr(referenceImagePath(scene, mode), &attrs);
  for (const auto& a : attrs) r.attrs[a.name] = a.value;
  return r;
}

TEST(SuiteScenes, EverySceneLoadsAndHasItsReferences) {
  const auto scenes = suite();
  // cornell-box and sponza and the six generated ones; an interior and an exterior at least.
  ASSERT_GE(scenes.size(), 8u);
  int interiors = 0;
  for (const auto& s : scenes) {
    SCOPED_TRACE(s.name);
    interiors += s.interior;
    const Scene scene = loadScene(resolveScenePath(s.name));
    EXPECT_GE(scene.lights.size(), 1u);
    EXPECT_NE(scene.lights[0].name, kDefaultSunName) << "every suite scene brings its own light";
    for (const char* mode : {"direct", "indirect-1", "indirect-2", "full"}) {
      SCOPED_TRACE(mode);
      ASSERT_TRUE(fileExists(referenceImagePath(s.name, mode))) << "scripts/make-references.sh makes it";
      const Reference r = load(s.name, mode);
      EXPECT_GE(r.img.width, 256);
      EXPECT_EQ(r.img.width, r.img.height);
      EXPECT_EQ(r.attrs.at("voxlab:scene"), scene.name);
      EXPECT_EQ(r.attrs.at("voxlab:mode"), mode);
      EXPECT_EQ(r.attrs.at("voxlab:camera_index"), "0");
      EXPECT_TRUE(r.attrs.count("voxlab:rms_stderr")) << "the noise figure";
      EXPECT_GT(r.mean(), 0.0) << "a reference with no light at all";
    }
  }
  EXPECT_GE(interiors, 6);
  EXPECT_LT(interiors, int(scenes.size())) << "the suite has an exterior scene";
}

// More light paths only add light: full counts every path that direct, indirect-1 and
// indirect-2 count. The means must be ordered within the noise; the margin is 4 standard errors of
// the mean image (the files' RMS standard error over sqrt(pixels x channels), about 1e-4 here).
TEST(SuiteScenes, ReferenceModesAreOrdered) {
  for (const auto& s : suite()) {
    SCOPED_TRACE(s.name);
    const Reference direct = load(s.name, "direct"), one = load(s.name, "indirect-1"), two = load(s.name, "indirect-2"),
                    full = load(s.name, "full");
    auto noise = [](const Reference& r) {
      return 4.0 * std::stod(r.attrs.at("voxlab:rms_stderr")) / std::sqrt(double(r.img.rgb.size()));
    };
    EXPECT_LE(one.mean(), two.mean() + noise(one) + noise(two));
    EXPECT_LE(direct.mean() + two.mean(), full.mean() + noise(two) + noise(full) + noise(direct));
    EXPECT_GT(one.mean(), 0.0);
  }
}

// spheres-room-cm is spheres-room with every length x100 and the spot's intensity x100^2: the
// same picture. The references were rendered separately from the two files with the same seed, so
// their paths take the same random numbers and differ only by the float rounding of positions
// 100 times larger: measured mean ratios 1.000000 (direct), 0.999997 (indirect-1, full). The
// bound, 1e-4, is 30 times that and fails any real difference of scale (a light not scaled by
// k^2 reads 1e-4 or 1e4).
TEST(SuiteScenes, CentimetreSceneHasTheMetreScenesPicture) {
  for (const char* mode : {"direct", "indirect-1", "full"}) {
    SCOPED_TRACE(mode);
    const Reference m = load("spheres-room", mode), cm = load("spheres-room-cm", mode);
    std::printf("spheres-room-cm / spheres-room, %s: %.6f\n", mode, cm.mean() / m.mean());
    EXPECT_NEAR(cm.mean() / m.mean(), 1.0, 1e-4);
  }
  const Scene m = loadScene(resolveScenePath("spheres-room")), cm = loadScene(resolveScenePath("spheres-room-cm"));
  EXPECT_NEAR(cm.bounds.extent().x / m.bounds.extent().x, 100.0, 1e-3);
  EXPECT_NEAR(cm.lights[0].intensity / m.lights[0].intensity, 1e4, 1.0);
}

TEST(SuiteScenes, SkyRadianceComesFromTheSceneExtras) {
  EXPECT_EQ(loadScene(resolveScenePath("cornell-box")).skyRadiance, 0.0f);
  EXPECT_FLOAT_EQ(loadScene(resolveScenePath("open-courtyard")).skyRadiance, 0.3f);
  EXPECT_EQ(load("open-courtyard", "full").attrs.at("voxlab:sky_radiance").substr(0, 3), "0.3")
      << "the reference saw the scene's sky";

  // A bad value is refused with one line naming it and the valid range.
  const fs::path dir = fs::temp_directory_path() / ("voxlab-suite-" + std::to_string(getpid()));
  fs::create_directories(dir);
  const fs::path path = dir / "negative-sky.gltf";
  std::ofstream(path) << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0],"extras":{"sky_radiance":-1}}],)"
                         R"("nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
                         R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],)"
                         R"("bufferViews":[{"buffer":0,"byteLength":36}],"buffers":[{"byteLength":36,"uri":)"
                         R"("data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]})";
  try {
    loadScene(path.string());
    ADD_FAILURE() << "a negative sky radiance loaded";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("sky_radiance must be a number in [0, 1000]"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace voxlab
