// alphaMode MASK and textures in any format stb reads, on a small generated scene:
// a 1 x 1 m quad whose base-colour texture (a TGA written here) is transparent on its left half
// (u < 0.5) and opaque on its right half, plus a small opaque triangle that moves the scene's
// bounds so the quad does not lie on a voxel boundary.
//
//  - every GPU voxelizer keeps exactly the CPU reference's voxels (the coverage rule of
//    scene/alpha_coverage.h, shared by both), and that set has no voxel where the texture is
//    transparent and every voxel of the opaque half that the unmasked quad has;
//  - the G-buffer sees through the transparent half (depth stays at the far plane there);
//  - the reference path tracer's rays pass through the transparent half;
//  - BMP and TGA textures decode to the same texels.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "core/paths.h"
#include "reference/cpu_voxelizer.h"
#include "reference/path_tracer.h"
#include "scene/alpha_coverage.h"
#include "scene/scene.h"
#include "techniques/common/voxel_space.h"
#include "test_support.h"

namespace voxlab {
namespace {

namespace fs = std::filesystem;

constexpr int kTexels = 16;        // texture width and height
constexpr float kQuadZ = 0.37f;    // plane of the quad
constexpr int kResolution = 64;

// 32-bit uncompressed TGA, top-left origin: alpha 0 for x < kTexels / 2, else 255; colour (200, 100, 50).
std::string tga() {
  std::string t(18, '\0');
  t[2] = 2;  // uncompressed true colour
  t[12] = char(kTexels);
  t[14] = char(kTexels);
  t[16] = 32;
  t[17] = 0x28;  // 8 alpha bits, top-left origin
  for (int y = 0; y < kTexels; ++y)
    for (int x = 0; x < kTexels; ++x) t += std::string{char(50), char(100), char(200), char(x < kTexels / 2 ? 0 : 255)};
  return t;
}

// 32-bit BMP (BITMAPV4 header with an alpha mask) of the same texels, bottom-up rows.
std::string bmp() {
  const uint32_t pixels = kTexels * kTexels * 4, headerSize = 14 + 108;
  std::string b;
  auto u16 = [&](uint16_t v) { b.append(reinterpret_cast<const char*>(&v), 2); };
  auto u32 = [&](uint32_t v) { b.append(reinterpret_cast<const char*>(&v), 4); };
  b += "BM";
  u32(headerSize + pixels);
  u32(0);
  u32(headerSize);
  u32(108);
  u32(kTexels);
  u32(kTexels);
  u16(1);
  u16(32);
  u32(3);  // BI_BITFIELDS
  u32(pixels);
  u32(2835);
  u32(2835);
  u32(0);
  u32(0);
  u32(0x00ff0000u);  // red mask
  u32(0x0000ff00u);
  u32(0x000000ffu);
  u32(0xff000000u);  // alpha mask
  b.append(108 - 56, '\0');
  for (int y = kTexels - 1; y >= 0; --y)
    for (int x = 0; x < kTexels; ++x) b += std::string{char(50), char(100), char(200), char(x < kTexels / 2 ? 0 : 255)};
  return b;
}

// The quad (material 0: masked, or opaque with 'masked' false) and the small opaque triangle
// (material 1), written next to the texture 'textureFile' into 'dir'.
std::string writeScene(const fs::path& dir, const std::string& textureFile, bool masked) {
  // Corners slightly off a square and a triangle at odd coordinates, so that no edge passes
  // exactly through voxel corners (the face/edge tie convention is tested elsewhere).
  std::vector<float> pos = {0.004f, 0, kQuadZ, 1, 0.013f, kQuadZ, 1, 0.996f, kQuadZ, 0.011f, 0.985f, kQuadZ,
                            0.9f, 0.91f, kQuadZ + 0.3f, 1.0f, 0.93f, kQuadZ + 0.3f, 0.97f, 1.0f, kQuadZ + 0.3f};
  std::vector<float> uv = {0, 0, 1, 0, 1, 1, 0, 1, 0, 0, 0, 0, 0, 0};
  std::vector<uint32_t> quad = {0, 1, 2, 0, 2, 3}, tri = {4, 5, 6};
  std::string binName = "alpha-" + std::string(masked ? "mask" : "opaque") + ".bin";
  std::ofstream bin(dir / binName, std::ios::binary);
  bin.write(reinterpret_cast<const char*>(pos.data()), std::streamsize(pos.size() * 4));
  bin.write(reinterpret_cast<const char*>(uv.data()), std::streamsize(uv.size() * 4));
  bin.write(reinterpret_cast<const char*>(quad.data()), 24);
  bin.write(reinterpret_cast<const char*>(tri.data()), 12);
  bin.close();
  const size_t p = pos.size() * 4, u = uv.size() * 4;
  std::string material0 = std::string("{\"name\":\"cutout\",\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}") +
                          (masked ? ",\"alphaMode\":\"MASK\",\"alphaCutoff\":0.5,\"doubleSided\":true}" : "}");
  std::string gltf =
      "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"indices\":2,\"material\":0},"
      "{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"indices\":3,\"material\":1}]}],"
      "\"materials\":[" + material0 + ",{\"name\":\"grey\"}],"
      "\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"" + textureFile + "\"}],"
      "\"buffers\":[{\"uri\":\"" + binName + "\",\"byteLength\":" + std::to_string(p + u + 36) + "}],"
      "\"bufferViews\":[{\"buffer\":0,\"byteLength\":" + std::to_string(p) + "},"
      "{\"buffer\":0,\"byteOffset\":" + std::to_string(p) + ",\"byteLength\":" + std::to_string(u) + "},"
      "{\"buffer\":0,\"byteOffset\":" + std::to_string(p + u) + ",\"byteLength\":24},"
      "{\"buffer\":0,\"byteOffset\":" + std::to_string(p + u + 24) + ",\"byteLength\":12}],"
      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":7,\"type\":\"VEC3\"},"
      "{\"bufferView\":1,\"componentType\":5126,\"count\":7,\"type\":\"VEC2\"},"
      "{\"bufferView\":2,\"componentType\":5125,\"count\":6,\"type\":\"SCALAR\"},"
      "{\"bufferView\":3,\"componentType\":5125,\"count\":3,\"type\":\"SCALAR\"}],"
      "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.9,\"znear\":0.05,\"zfar\":20}}],"
      "\"extensionsUsed\":[]}";
  // A camera 1.5 m in front of the quad (+z), looking at its centre: add it as a second node.
  gltf.replace(gltf.find("\"nodes\":[0]}]"), 13, "\"nodes\":[0,1]}]");
  gltf.replace(gltf.find("\"nodes\":[{\"mesh\":0}]"), 20,
               "\"nodes\":[{\"mesh\":0},{\"camera\":0,\"translation\":[0.5,0.5," + std::to_string(kQuadZ + 1.5f) + "]}]");
  std::string path = (dir / (std::string(masked ? "alpha-mask" : "alpha-opaque") + ".gltf")).string();
  std::ofstream(path) << gltf;
  return path;
}

const fs::path& sceneDir() {
  static const fs::path dir = [] {
    fs::path d = fs::path(::testing::TempDir()) / "voxlab-alpha-mask";
    fs::create_directories(d);
    std::ofstream(d / "half.tga", std::ios::binary) << tga();
    std::ofstream(d / "half.bmp", std::ios::binary) << bmp();
    return d;
  }();
  return dir;
}
const std::string& maskedScene() {
  static const std::string p = writeScene(sceneDir(), "half.tga", true);
  return p;
}
const std::string& opaqueScene() {
  static const std::string p = writeScene(sceneDir(), "half.tga", false);
  return p;
}

std::set<uint32_t> gpuVoxels(const std::string& scene, const std::string& method) {
  RunRequest r;
  r.technique = "voxelization";
  r.scene = scene;
  r.sets = {"voxel.resolution=" + std::to_string(kResolution)};
  r.width = r.height = 64;
  HeadlessSession& s = testing_support::session(r);
  s.cursor().setParamText("voxelize.method", method);
  s.cursor().runAll();
  CapturedOutput fragments = testing_support::capture(s, "voxelize", "fragments");
  std::set<uint32_t> voxels;
  for (uint32_t i = 0; i < fragments.recordCount; ++i) {
    uint32_t packed;
    std::memcpy(&packed, &fragments.records[size_t(i) * fragments.desc.layout.stride], 4);
    voxels.insert(packed);
  }
  return voxels;
}

TEST(AlphaMask, TgaAndBmpTexturesDecodeToTheSameTexels) {
  Scene tgaScene = loadScene(maskedScene());
  Scene bmpScene = loadScene(writeScene(sceneDir(), "half.bmp", true));
  ASSERT_EQ(tgaScene.textures.size(), 1u);
  ASSERT_EQ(bmpScene.textures.size(), 1u);
  EXPECT_EQ(tgaScene.textures[0].width, kTexels);
  EXPECT_EQ(tgaScene.textures[0].rgba8, bmpScene.textures[0].rgba8);
  // Row 3, texels 7 and 8: the transparent and the opaque half.
  const uint8_t* t = &tgaScene.textures[0].rgba8[size_t(3 * kTexels + 7) * 4];
  EXPECT_EQ(std::vector<uint8_t>(t, t + 8), (std::vector<uint8_t>{200, 100, 50, 0, 200, 100, 50, 255}));
  const Material& m = tgaScene.materials[tgaScene.draws[0].material];
  EXPECT_EQ(m.alphaMode, AlphaMode::Mask);
  EXPECT_FLOAT_EQ(m.alphaCutoff, 0.5f);
  EXPECT_TRUE(m.doubleSided);
}

TEST(AlphaMask, CoveragePyramidIsAnOrOfTexels) {
  Scene scene = loadScene(maskedScene());
  AlphaCoverage cov = AlphaCoverage::build(scene);
  const uint32_t quad = scene.draws[0].material;
  ASSERT_TRUE(cov.masked(quad));
  EXPECT_FALSE(cov.masked(scene.draws[1].material));
  ASSERT_EQ(cov.levelCount[quad], 5u);  // 16, 8, 4, 2, 1
  const CoverageLevel& L0 = cov.levels[cov.firstLevel[quad]];
  const CoverageLevel& L3 = cov.levels[cov.firstLevel[quad] + 3];
  for (uint32_t x = 0; x < 16; ++x) EXPECT_EQ(cov.bit(L0, x, 5), x >= 8) << x;
  EXPECT_FALSE(cov.bit(L3, 0, 0));  // 2x2: left column covers texels 0..7 (all transparent)
  EXPECT_TRUE(cov.bit(L3, 1, 1));
  EXPECT_TRUE(cov.bit(cov.levels[cov.firstLevel[quad] + 4], 0, 0));
}

// The GPU voxelizers and the CPU reference apply one rule, so they agree exactly; and the rule
// does what MASK means: no voxel where the texture is transparent, every voxel of the opaque half.
TEST(AlphaMask, MaskedQuadLeavesNoVoxelsWhereTransparent) {
  Scene masked = loadScene(maskedScene());
  Scene opaque = loadScene(opaqueScene());
  const VoxelSpace space = VoxelSpace::fromScene(masked, kResolution);
  std::vector<uint32_t> ref = referenceVoxelSet(masked, space);
  std::vector<uint32_t> full = referenceVoxelSet(opaque, space);
  std::set<uint32_t> refSet(ref.begin(), ref.end()), fullSet(full.begin(), full.end());
  // Voxel centres along x (world) and whether the voxel holds the quad's plane.
  auto centreX = [&](uint32_t k) { return space.origin.x + (float(unpackVoxelKey(k).x) + 0.5f) * space.voxelSize; };
  auto onQuad = [&](uint32_t k) {
    float z0 = space.origin.z + float(unpackVoxelKey(k).z) * space.voxelSize;
    return z0 <= kQuadZ + 1e-4f && kQuadZ - 1e-4f <= z0 + space.voxelSize;
  };
  size_t leftFull = 0, leftMasked = 0, rightFull = 0, rightMissing = 0;
  // Within one texel (1/16 m) of the opaque texels voxels may stay (the 2x2 footprint), and the
  // texture repeats, so the quad's edge at u = 0 neighbours the opaque column u = 15/16: the
  // transparent region tested is u in (2/16, 6/16); u and x differ by < 0.015 on this quad.
  auto inLeft = [&](uint32_t k) { return centreX(k) > 2.0f / kTexels && centreX(k) < 6.0f / kTexels; };
  const float rightLimit = 0.5f + 0.02f + space.voxelSize;
  for (uint32_t k : full) {
    if (!onQuad(k)) continue;
    if (inLeft(k)) ++leftFull;
    if (centreX(k) > rightLimit) {
      ++rightFull;
      if (!refSet.count(k)) ++rightMissing;
    }
  }
  for (uint32_t k : ref)
    if (onQuad(k) && inLeft(k)) {
      if (++leftMasked < 4) {
        glm::ivec3 v = unpackVoxelKey(k);
        ADD_FAILURE() << "voxel " << v.x << "," << v.y << "," << v.z << " x " << centreX(k);
      }
    }
  EXPECT_GT(leftFull, 900u);  // the opaque quad has voxels there: the test can fail
  EXPECT_EQ(leftMasked, 0u) << "voxels where the texture is transparent";
  EXPECT_GT(rightFull, 1000u);
  EXPECT_EQ(rightMissing, 0u) << "voxels of the opaque half lost";
  for (uint32_t k : ref) EXPECT_TRUE(fullSet.count(k)) << "masking only removes voxels";

  for (const char* method : {"fragment-parallel", "triangle-parallel", "hybrid"}) {
    std::set<uint32_t> gpu = gpuVoxels(maskedScene(), method);
    size_t missed = 0, added = 0;
    for (uint32_t k : ref)
      if (!gpu.count(k)) {
        if (++missed < 4) {
          glm::ivec3 v = unpackVoxelKey(k);
          ADD_FAILURE() << method << " misses " << v.x << "," << v.y << "," << v.z;
        }
      }
    for (uint32_t k : gpu) added += refSet.count(k) ? 0 : 1;
    EXPECT_EQ(missed, 0u) << method;
    EXPECT_EQ(added, 0u) << method;
  }
}

// Both voxelizers take a fragment's albedo from the material's texture (the compute pass samples
// it per draw range at the voxel centre's projection): on the opaque variant of the scene every
// quad texel has sRGB colour (200, 100, 50), linear (0.578, 0.127, 0.032), and the small triangle
// (no texture, factor 1) is white. RGBA8 fragments: within 1.5/255 (texture filtering and
// 8-bit rounding, measured worst 1/255).
TEST(AlphaMask, VoxelFragmentsCarryTextureAlbedo) {
  for (const char* method : {"fragment-parallel", "triangle-parallel"}) {
    RunRequest r;
    r.technique = "voxelization";
    r.scene = opaqueScene();
    r.sets = {"voxel.resolution=" + std::to_string(kResolution)};
    r.width = r.height = 64;
    HeadlessSession& s = testing_support::session(r);
    s.cursor().setParamText("voxelize.method", method);
    s.cursor().runAll();
    CapturedOutput fragments = testing_support::capture(s, "voxelize", "fragments");
    const VoxelSpace space = VoxelSpace::fromScene(s.cursor().scene(), kResolution);
    const int quadLayer = int(std::floor(space.toVoxel(glm::vec3(0, 0, kQuadZ)).z));
    size_t quad = 0, white = 0, wrong = 0;
    for (uint32_t i = 0; i < fragments.recordCount; ++i) {
      const uint8_t* rec = &fragments.records[size_t(i) * fragments.desc.layout.stride];
      uint32_t packed;
      std::memcpy(&packed, rec, 4);
      const uint8_t* albedo = rec + 4;
      const bool onQuad = int(unpackVoxelKey(packed).z) <= quadLayer + 1;
      const glm::vec3 expected = onQuad ? glm::vec3(0.578f, 0.127f, 0.032f) : glm::vec3(1.0f);
      const glm::vec3 got(albedo[0] / 255.0f, albedo[1] / 255.0f, albedo[2] / 255.0f);
      (onQuad ? quad : white) += 1;
      if (glm::any(glm::greaterThan(glm::abs(got - expected), glm::vec3(1.5f / 255.0f)))) ++wrong;
    }
    EXPECT_GT(quad, 3000u) << method;
    EXPECT_GT(white, 10u) << method;
    EXPECT_EQ(wrong, 0u) << method;
  }
}

// The G-buffer discards cut-away fragments: looking at the quad, the transparent half shows the
// far plane (depth 1), the opaque half the quad.
TEST(AlphaMask, GBufferSeesThroughTransparentHalf) {
  RunRequest r;
  r.technique = "vct-grid";
  r.scene = maskedScene();
  r.sets = {"voxel.resolution=32"};
  r.until = "gbuffer";
  r.width = r.height = 64;
  HeadlessSession& s = testing_support::session(r);
  CapturedOutput depth = testing_support::capture(s, "gbuffer", "depth");
  const LevelData& d = depth.levels.at(0);
  auto at = [&](int x, int y) { return d.at(x, y, 0, 0); };
  // The quad spans about x 13..51 of 64 px at this distance; sample well inside each half.
  int farLeft = 0, nearRight = 0;
  for (int y = 24; y < 40; ++y) {
    farLeft += at(20, y) >= 0.9999f ? 1 : 0;
    nearRight += at(44, y) < 0.9999f ? 1 : 0;
  }
  EXPECT_EQ(farLeft, 16);
  EXPECT_EQ(nearRight, 16);
}

// The reference tracer's rays pass through cut-away texels: AO rays from a point in front of the
// transparent half, pointed straight at it, are never blocked; in front of the opaque half always.
TEST(AlphaMask, ReferenceTracerRaysPassThroughTransparentHalf) {
  Scene scene = loadScene(maskedScene());
  reference::ReferenceTracer tracer(scene);
  const glm::vec3 down(0, 0, -1);
  auto visible = [&](float x) {
    return tracer.estimateAO(glm::vec3(x, 0.5f, kQuadZ + 0.05f), down, 64, 0.1f).mean.x;
  };
  // Cosine-weighted rays at most 0.1 m long from 5 cm in front reach the plane when cos >= 0.5,
  // within 0.087 m of the point: at x = 0.2 only transparent texels, at x = 0.8 only opaque ones.
  // In front of the opaque half the rays with cos < 0.5 (a quarter of a cosine distribution) end
  // before the plane, so the visible fraction there is about 0.25 (64 rays: 0.25 +- 0.054).
  EXPECT_DOUBLE_EQ(visible(0.2f), 1.0);
  EXPECT_LT(visible(0.8f), 0.45);
}

}  // namespace
}  // namespace voxlab
