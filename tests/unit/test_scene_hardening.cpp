// Hostile scene files: the loader rejects with one line, in bounded time and memory,
// the defect classes fuzzing aims at - an accessor claiming 3e9 (or 2e9) elements, a buffer
// shorter than its views, deep node trees and deep JSON, an image claiming a huge size - and
// every regression file the fuzzer ever found (tests/data/fuzz/) loads or is rejected cleanly.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "core/paths.h"
#include "scene/scene.h"
#include "test_support.h"

namespace voxlab {
namespace {

namespace fs = std::filesystem;

// One triangle: three VEC3 floats (36 bytes), base64.
const char* kTriangleData = "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA";

std::string writeScene(const std::string& name, const std::string& text) {
  fs::path dir = fs::temp_directory_path() / ("voxlab-hardening-" + std::to_string(getpid()));
  fs::create_directories(dir);
  fs::path p = dir / name;
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

// glTF with one node chain, one mesh whose POSITION accessor has 'count' elements over a view of
// 'viewLength' bytes of a buffer of 'bufferLength' bytes (the data holds 36).
std::string triangleScene(const std::string& count, int viewLength = 36, int bufferLength = 36,
                          const std::string& extraNodes = "", const std::string& rootNodes = "[0]") {
  return std::string(R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":)") + rootNodes +
         R"(}],"nodes":[{"mesh":0})" + extraNodes +
         R"(],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" + count +
         R"(,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],)"
         R"("bufferViews":[{"buffer":0,"byteLength":)" + std::to_string(viewLength) +
         R"(}],"buffers":[{"byteLength":)" + std::to_string(bufferLength) + R"(,"uri":")" + kTriangleData + R"("}]})";
}


TEST(SceneHardening, ValidTriangleLoads) {
  // The template itself is valid, so the rejections below are caused by the one change each makes.
  Scene s = loadScene(writeScene("triangle.gltf", triangleScene("3")));
  EXPECT_EQ(s.triangleCount(), 1u);
}

TEST(SceneHardening, AccessorClaiming3e9Elements) {
  testing_support::expectSceneRejected(writeScene("count-3e9.gltf", triangleScene("3000000000")), "too large");
}

TEST(SceneHardening, AccessorClaiming2e9ElementsOfASmallView) {
  // Below the 2^31 count limit: refused by the view check before 24 GB would be allocated.
  testing_support::expectSceneRejected(writeScene("count-2e9.gltf", triangleScene("2000000000")), "out of range");
}

TEST(SceneHardening, BufferShorterThanItsViews) {
  testing_support::expectSceneRejected(writeScene("short-buffer.gltf", triangleScene("3", 4096, 4096)), "buffer");
}

TEST(SceneHardening, AccessorWithoutDataIsBounded) {
  std::string text = triangleScene("100000000");
  const std::string view = R"("bufferView":0,)";
  text.erase(text.find(view), view.size());
  testing_support::expectSceneRejected(writeScene("no-view.gltf", text), "implied zeros");
}

TEST(SceneHardening, InstancingIsBounded) {
  testing_support::expectSceneRejected(projectPath("tests/data/fuzz/instanced-implied-zeros-12x2e20.gltf"), "flattened scene would have more than");
}

TEST(SceneHardening, DeepNodeChainLoads) {
  // 50000 nodes, each the only child of the previous one; the mesh sits at the bottom.
  const int depth = 50000;
  std::string nodes;
  for (int i = 1; i <= depth; ++i) nodes += R"(,{"children":[)" + std::to_string(i == depth ? 0 : i + 1) + "]}";
  Scene s = loadScene(writeScene("deep-chain.gltf", triangleScene("3", 36, 36, nodes, "[1]")));
  EXPECT_EQ(s.triangleCount(), 1u);
}

TEST(SceneHardening, DeepJsonNestingIsRejected) {
  // tinygltf parses "extras" recursively: 100000 levels must not overflow the stack.
  std::string text = triangleScene("3");
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  text.insert(text.size() - 1, R"(,"extras":)" + deep);
  testing_support::expectSceneRejected(writeScene("deep-json.gltf", text), "nest");
}

TEST(SceneHardening, ImageClaimingAHugeSize) {
  // A PNG header of 20000 x 20000 RGBA with no pixel data: refused before its 1.6 GB are allocated
  // (the allocation itself is what tests/data/fuzz/image-16000x16000-without-pixels.gltf checks under the fuzzer's
  // -malloc_limit_mb; here only the clean rejection is visible).
  const unsigned char png[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R',
                               0, 0, 0x4e, 0x20, 0, 0, 0x4e, 0x20, 8, 6, 0, 0, 0, 0x4d, 0x6b, 0x92, 0x66};
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string b64;
  for (size_t i = 0; i < sizeof png; i += 3) {
    uint32_t v = uint32_t(png[i]) << 16 | (i + 1 < sizeof png ? uint32_t(png[i + 1]) << 8 : 0) |
                 (i + 2 < sizeof png ? png[i + 2] : 0);
    b64 += table[v >> 18 & 63];
    b64 += table[v >> 12 & 63];
    b64 += i + 1 < sizeof png ? table[v >> 6 & 63] : '=';
    b64 += i + 2 < sizeof png ? table[v & 63] : '=';
  }
  std::string text = triangleScene("3");
  text.insert(text.size() - 1, R"(,"images":[{"uri":"data:image/png;base64,)" + b64 + R"("}],"textures":[{"source":0}])");
  const size_t meshAt = text.find(R"({"attributes")");
  text.insert(meshAt + 1, R"("material":0,)");
  text.insert(text.size() - 1, R"(,"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}])");
  testing_support::expectSceneRejected(writeScene("huge-image.gltf", text), "image");
}

// Every file the fuzzer found (tests/data/fuzz/, docs/testing.md#fuzzing-the-scene-loader):
// loads, or throws Error with one line. A crash, hang or sanitizer report fails the suite.
TEST(SceneHardening, FuzzRegressionFiles) {
  const fs::path dir = projectPath("tests/data/fuzz");
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file() || entry.path().filename() == "README.md") continue;
    ++files;
    SCOPED_TRACE(entry.path().string());
    try {
      loadScene(entry.path().string());
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
  EXPECT_GT(files, 0u) << "no regression files in " << dir;
}

}  // namespace
}  // namespace voxlab
