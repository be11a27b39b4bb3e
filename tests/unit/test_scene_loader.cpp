// Scene loading: the Cornell box as authored by scripts/make_scenes.py, the loader's handling of
// index types, node transforms and missing normals (tiny files written here), and one-line errors
// for every malformed file in tests/data/bad/ (written by scripts/make_bad_scenes.py).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/paths.h"
#include "scene/light_model.h"
#include "scene/scene.h"

namespace voxlab {
namespace {

namespace fs = std::filesystem;

// --- helpers: tiny glTF files written into a temp dir ------------------------------------------

std::string base64(const std::vector<uint8_t>& data) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < data.size(); i += 3) {
    uint32_t v = (uint32_t(data[i]) << 16) | (uint32_t(data[i + 1]) << 8) | data[i + 2];
    for (int k = 3; k >= 0; --k) out += table[(v >> (6 * k)) & 63];
  }
  if (i + 1 == data.size()) {
    uint32_t v = uint32_t(data[i]) << 16;
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == data.size()) {
    uint32_t v = (uint32_t(data[i]) << 16) | (uint32_t(data[i + 1]) << 8);
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += table[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

template <typename T>
void append(std::vector<uint8_t>& buf, const std::vector<T>& values) {
  while (buf.size() % 4) buf.push_back(0);
  size_t at = buf.size();
  buf.resize(at + values.size() * sizeof(T));
  std::memcpy(buf.data() + at, values.data(), values.size() * sizeof(T));
}

class TempDir {
 public:
  TempDir() {
    path_ = fs::temp_directory_path() /
            ("voxlab-scene-test-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "-" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string write(const std::string& name, const std::string& text) const {
    std::string p = (path_ / name).string();
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }

 private:
  fs::path path_;
};

// A one-primitive glTF: positions (float VEC3), optional indices of the given component type,
// and a node list given as JSON text referring to mesh 0.
std::string primitiveGltf(const std::vector<float>& positions, const std::vector<uint32_t>& indices,
                          int indexComponentType, const std::string& nodesJson, const std::string& sceneNodes,
                          const std::string& extra = "") {
  std::vector<uint8_t> buf;
  append(buf, positions);
  size_t posBytes = buf.size();
  size_t idxOffset = 0, idxBytes = 0;
  if (!indices.empty()) {
    while (buf.size() % 4) buf.push_back(0);
    idxOffset = buf.size();
    if (indexComponentType == 5121) {
      std::vector<uint8_t> v(indices.begin(), indices.end());
      append(buf, v);
    } else if (indexComponentType == 5123) {
      std::vector<uint16_t> v(indices.begin(), indices.end());
      append(buf, v);
    } else {
      append(buf, indices);
    }
    idxBytes = buf.size() - idxOffset;
  }
  while (buf.size() % 4) buf.push_back(0);
  std::string views = "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":" + std::to_string(posBytes) + "}";
  std::string accessors = "{\"bufferView\":0,\"componentType\":5126,\"count\":" +
                          std::to_string(positions.size() / 3) + ",\"type\":\"VEC3\"}";
  std::string prim = "{\"attributes\":{\"POSITION\":0}";
  if (!indices.empty()) {
    views += ",{\"buffer\":0,\"byteOffset\":" + std::to_string(idxOffset) + ",\"byteLength\":" +
             std::to_string(idxBytes) + "}";
    accessors += ",{\"bufferView\":1,\"componentType\":" + std::to_string(indexComponentType) +
                 ",\"count\":" + std::to_string(indices.size()) + ",\"type\":\"SCALAR\"}";
    prim += ",\"indices\":1";
  }
  prim += "}";
  return "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":" + sceneNodes + "}]," +
         "\"nodes\":" + nodesJson + ",\"meshes\":[{\"name\":\"m\",\"primitives\":[" + prim + "]}]," +
         "\"accessors\":[" + accessors + "],\"bufferViews\":[" + views + "]," +
         "\"buffers\":[{\"byteLength\":" + std::to_string(buf.size()) +
         ",\"uri\":\"data:application/octet-stream;base64," + base64(buf) + "\"}]" + extra + "}";
}

// One triangle in the z = 0 plane, counter-clockwise seen from +z (front normal +z).
const std::vector<float> kTriangle = {0, 0, 0, 1, 0, 0, 0, 1, 0};

glm::vec3 faceNormal(const Scene& s, size_t tri) {
  glm::vec3 a = s.positions[s.indices[tri * 3]], b = s.positions[s.indices[tri * 3 + 1]],
            c = s.positions[s.indices[tri * 3 + 2]];
  return glm::normalize(glm::cross(b - a, c - a));
}

void expectNear(const glm::vec3& a, const glm::vec3& b, float eps = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

// --- the Cornell box ---------------------------------------------------------------------------

const Material* findMaterial(const Scene& s, const std::string& name) {
  for (const Material& m : s.materials)
    if (m.name == name) return &m;
  return nullptr;
}

TEST(SceneLoader, CornellBoxGeometry) {
  Scene s = loadScene(resolveScenePath("cornell-box"));
  EXPECT_EQ(s.name, "cornell-box");
  // 5 walls + light panel (1 quad each) + 2 blocks x 5 quads, 2 triangles per quad.
  EXPECT_EQ(s.triangleCount(), 32u);
  ASSERT_TRUE(s.bounds.valid());
  expectNear(s.bounds.min, glm::vec3(0.0f, 0.0f, 0.0f), 1e-5f);
  expectNear(s.bounds.max, glm::vec3(0.556f, 0.5488f, 0.5592f), 1e-5f);
  EXPECT_EQ(s.positions.size(), s.normals.size());
  EXPECT_EQ(s.positions.size(), s.uvs.size());
  // Normals are unit and agree with the winding.
  for (size_t t = 0; t < s.triangleCount(); ++t) {
    glm::vec3 fn = faceNormal(s, t);
    for (int k = 0; k < 3; ++k) {
      glm::vec3 n = s.normals[s.indices[t * 3 + k]];
      EXPECT_NEAR(glm::length(n), 1.0f, 1e-4f);
      EXPECT_GT(glm::dot(n, fn), 0.99f) << "triangle " << t;
    }
  }
}

TEST(SceneLoader, CornellBoxMaterialsAndWallsFaceInward) {
  Scene s = loadScene(resolveScenePath("cornell-box"));
  ASSERT_EQ(s.materials.size(), 8u);
  for (const char* name : {"floor", "ceiling", "back-wall", "left-wall-red", "right-wall-green", "short-block",
                           "tall-block", "light-panel"}) {
    EXPECT_NE(findMaterial(s, name), nullptr) << name;
  }
  const glm::vec3 room(0.278f, 0.274f, 0.28f);
  // Every wall triangle faces the room centre; the red wall is at +x, the green one at x = 0.
  for (size_t t = 0; t < s.triangleCount(); ++t) {
    const Material& m = s.materials[s.triangleMaterial(t)];
    glm::vec3 a = s.positions[s.indices[t * 3]];
    glm::vec3 fn = faceNormal(s, t);
    if (m.name == "left-wall-red") {
      EXPECT_GT(a.x, 0.54f);
      EXPECT_LT(fn.x, -0.99f);
      EXPECT_GT(m.baseColor.x, 0.6f);
      EXPECT_LT(m.baseColor.y, 0.1f);
    } else if (m.name == "right-wall-green") {
      EXPECT_NEAR(a.x, 0.0f, 1e-6f);
      EXPECT_GT(fn.x, 0.99f);
      EXPECT_GT(m.baseColor.y, 0.4f);
    } else if (m.name == "floor") {
      EXPECT_GT(fn.y, 0.99f);
    } else if (m.name == "ceiling" || m.name == "light-panel") {
      EXPECT_LT(fn.y, -0.99f);
    }
    if (m.name == "floor" || m.name == "ceiling" || m.name == "back-wall" || m.name == "left-wall-red" ||
        m.name == "right-wall-green") {
      EXPECT_GT(glm::dot(fn, room - a), 0.0f) << m.name;
    }
  }
  const Material* panel = findMaterial(s, "light-panel");
  ASSERT_NE(panel, nullptr);
  expectNear(panel->emissive, glm::vec3(1.0f));
  expectNear(findMaterial(s, "floor")->emissive, glm::vec3(0.0f));
  expectNear(glm::vec3(findMaterial(s, "back-wall")->baseColor), glm::vec3(0.725f, 0.71f, 0.68f));
  // Draw ranges are contiguous, cover every index and have one material each.
  uint32_t next = 0;
  for (const DrawRange& d : s.draws) {
    EXPECT_EQ(d.firstIndex, next);
    EXPECT_LT(d.material, s.materials.size());
    next += d.indexCount;
  }
  EXPECT_EQ(next, s.indices.size());
}

TEST(SceneLoader, CornellBoxLightAndCamera) {
  Scene s = loadScene(resolveScenePath("cornell-box"));
  ASSERT_EQ(s.lights.size(), 1u);
  const Light& l = s.lights[0];
  EXPECT_EQ(l.type, LightType::Spot);
  expectNear(l.position, glm::vec3(0.278f, 0.538f, 0.2795f));
  expectNear(l.direction, glm::vec3(0.0f, -1.0f, 0.0f));
  expectNear(l.color, glm::vec3(1.0f, 0.85f, 0.65f));
  EXPECT_NEAR(l.innerConeAngle, 0.6f, 1e-6f);
  EXPECT_NEAR(l.outerConeAngle, 1.3f, 1e-6f);
  // About 3 W/m^2 (times colour) on the floor straight below.
  LightSample ls = sampleLight(l, glm::vec3(0.278f, 0.0f, 0.2795f));
  EXPECT_NEAR(ls.irradianceAtNormalIncidence.x, 3.0f, 0.01f);
  EXPECT_NEAR(ls.toLight.y, 1.0f, 1e-5f);

  ASSERT_EQ(s.cameras.size(), 1u);
  const Camera& c = s.cameras[0];
  expectNear(c.position, glm::vec3(0.278f, 0.273f, -0.8f));
  expectNear(c.forward, glm::vec3(0.0f, 0.0f, 1.0f));
  expectNear(c.up, glm::vec3(0.0f, 1.0f, 0.0f));
  EXPECT_NEAR(c.yfov, 0.6860f, 1e-4f);
  // The box centre projects near the image centre; the box fills most of the view.
  glm::vec4 clip = c.projection(1.0f) * c.view() * glm::vec4(0.278f, 0.2744f, 0.2796f, 1.0f);
  glm::vec3 ndc = glm::vec3(clip) / clip.w;
  EXPECT_NEAR(ndc.x, 0.0f, 1e-3f);
  EXPECT_NEAR(ndc.y, 0.0f, 0.01f);
  EXPECT_GT(ndc.z, -1.0f);
  EXPECT_LT(ndc.z, 1.0f);
}

TEST(SceneLoader, TestScenesLoad) {
  // Triangle counts from scripts/make_scenes.py: a quad is 2 triangles, a box 12.
  const std::pair<const char*, size_t> counts[] = {
      {"furnace-box", 12},     {"furnace-colour", 12}, {"wall-floor", 4},      {"thin-wall", 24},
      {"lid-floor", 4},        {"textured-floor", 2},  {"boundary-quad", 4},   {"long-hall", 2 * 2 + 1 + 12 + 4},
      {"voxel-ties-64", 20},   {"voxel-ties-256", 20}, {"dense-sheet", 2 * 96 * 96 + 2}, {"huge-triangles", 4}};
  for (auto [name, triangles] : counts) {
    Scene s = loadScene(projectPath(std::string("tests/data/scenes/") + name + ".gltf"));
    EXPECT_EQ(s.triangleCount(), triangles) << name;
    EXPECT_FALSE(s.cameras.empty()) << name;  // its own or one framing the bounds
  }
  Scene furnace = loadScene(projectPath("tests/data/scenes/furnace-box.gltf"));
  EXPECT_EQ(furnace.triangleCount(), 12u);
  // Seen from inside: every face normal points towards the centre.
  for (size_t t = 0; t < furnace.triangleCount(); ++t) {
    glm::vec3 a = furnace.positions[furnace.indices[t * 3]];
    EXPECT_GT(glm::dot(faceNormal(furnace, t), -a), 0.0f);
  }
  EXPECT_NEAR(furnace.materials[0].baseColor.x, 0.5f, 1e-6f);
}

// --- scene names ---------------------------------------------------------------------------------

TEST(SceneLoader, ResolveAndListScenes) {
  std::vector<std::string> names = listScenes();
  EXPECT_NE(std::find(names.begin(), names.end(), "cornell-box"), names.end());
  EXPECT_EQ(resolveScenePath("cornell-box"), projectPath("scenes/cornell-box.gltf"));
  std::string direct = projectPath("tests/data/scenes/wall-floor.gltf");
  EXPECT_EQ(resolveScenePath(direct), direct);
  try {
    resolveScenePath("no-such-scene");
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find("unknown scene 'no-such-scene'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("cornell-box"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos);
  }
  EXPECT_THROW(resolveScenePath("/nonexistent/dir/x.gltf"), Error);
}

// --- loader behaviour on small files -------------------------------------------------------------

TEST(SceneLoader, IndexTypes) {
  TempDir dir;
  for (int type : {5121, 5123, 5125}) {
    std::string p = dir.write("tri-" + std::to_string(type) + ".gltf",
                              primitiveGltf(kTriangle, {0, 1, 2}, type, "[{\"mesh\":0}]", "[0]"));
    Scene s = loadScene(p);
    ASSERT_EQ(s.triangleCount(), 1u) << type;
    EXPECT_EQ(s.indices, (std::vector<uint32_t>{0, 1, 2}));
    expectNear(s.positions[1], glm::vec3(1, 0, 0));
  }
  // Non-indexed.
  Scene s = loadScene(dir.write("plain.gltf", primitiveGltf(kTriangle, {}, 0, "[{\"mesh\":0}]", "[0]")));
  EXPECT_EQ(s.triangleCount(), 1u);
  // Default material and framing camera.
  ASSERT_EQ(s.materials.size(), 1u);
  expectNear(glm::vec3(s.materials[0].baseColor), glm::vec3(1.0f));
  ASSERT_EQ(s.cameras.size(), 1u);
  EXPECT_GT(s.cameras[0].position.z, 0.5f);
  expectNear(s.cameras[0].forward, glm::vec3(0, 0, -1));
}

TEST(SceneLoader, LoadsGlb) {
  // The same triangle as a binary container: JSON chunk + BIN chunk, buffer 0 without a uri.
  std::vector<uint8_t> bin;
  append(bin, kTriangle);
  std::vector<uint8_t> idx = {0, 1, 2, 0};  // u8 indices, padded to 4 bytes
  bin.insert(bin.end(), idx.begin(), idx.end());
  std::string json =
      "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
      "{\"bufferView\":1,\"componentType\":5121,\"count\":3,\"type\":\"SCALAR\"}],"
      "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":3}],"
      "\"buffers\":[{\"byteLength\":40}]}";
  while (json.size() % 4) json += ' ';
  std::string glb;
  auto u32 = [&](uint32_t v) { glb.append(reinterpret_cast<const char*>(&v), 4); };
  glb += "glTF";
  u32(2);
  u32(uint32_t(12 + 8 + json.size() + 8 + bin.size()));
  u32(uint32_t(json.size()));
  u32(0x4E4F534Au);
  glb += json;
  u32(uint32_t(bin.size()));
  u32(0x004E4942u);
  glb.append(reinterpret_cast<const char*>(bin.data()), bin.size());
  TempDir dir;
  Scene s = loadScene(dir.write("tri.glb", glb));
  ASSERT_EQ(s.triangleCount(), 1u);
  expectNear(s.positions[s.indices[2]], glm::vec3(0, 1, 0));
  EXPECT_EQ(s.name, "tri");
}

TEST(SceneLoader, TexturesAndEmissiveStrength) {
  // A 2x1 RGB PNG (red, green) as base colour texture; emissive (0.5,0.25,0) x strength 4.
  const std::string png = "iVBORw0KGgoAAAANSUhEUgAAAAIAAAABCAIAAAB7QOjdAAAAD0lEQVR42mP4z8DA8J8BAAf/Af+4BDXgAAAAAElFTkSuQmCC";
  std::string extra =
      ",\"materials\":[{\"name\":\"tex\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,1],"
      "\"baseColorTexture\":{\"index\":0}},\"emissiveFactor\":[0.5,0.25,0],"
      "\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":4}}}]"
      ",\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"data:image/png;base64," + png + "\"}]"
      ",\"extensionsUsed\":[\"KHR_materials_emissive_strength\"]"
      ",\"extensionsRequired\":[\"KHR_materials_emissive_strength\"]";
  std::string text = primitiveGltf(kTriangle, {0, 1, 2}, 5123, "[{\"mesh\":0}]", "[0]", extra);
  // Give the primitive its material.
  text.replace(text.find("\"indices\":1}"), 12, "\"indices\":1,\"material\":0}");
  TempDir dir;
  Scene s = loadScene(dir.write("tex.gltf", text));
  ASSERT_EQ(s.materials.size(), 1u);
  ASSERT_EQ(s.materials[0].baseColorTexture, 0);
  expectNear(s.materials[0].emissive, glm::vec3(2.0f, 1.0f, 0.0f));
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].width, 2);
  EXPECT_EQ(s.textures[0].height, 1);
  EXPECT_EQ(s.textures[0].rgba8, (std::vector<uint8_t>{255, 0, 0, 255, 0, 255, 0, 255}));
}

TEST(SceneLoader, ComputedNormalsFollowWinding) {
  TempDir dir;
  Scene s = loadScene(dir.write("n.gltf", primitiveGltf(kTriangle, {0, 1, 2}, 5123, "[{\"mesh\":0}]", "[0]")));
  for (const glm::vec3& n : s.normals) expectNear(n, glm::vec3(0, 0, 1));
  // Reversed winding: normals flip.
  Scene r = loadScene(dir.write("r.gltf", primitiveGltf(kTriangle, {0, 2, 1}, 5123, "[{\"mesh\":0}]", "[0]")));
  for (const glm::vec3& n : r.normals) expectNear(n, glm::vec3(0, 0, -1));
}

TEST(SceneLoader, NodeTransformsCompose) {
  TempDir dir;
  // Parent: translate (10,0,0) and rotate 90 deg about +y; child: scale 2 and translate (0,1,0).
  const float h = std::sqrt(0.5f);
  std::string nodes = "[{\"name\":\"parent\",\"translation\":[10,0,0],\"rotation\":[0," + std::to_string(h) +
                      ",0," + std::to_string(h) + "],\"children\":[1]}," +
                      "{\"name\":\"child\",\"mesh\":0,\"translation\":[0,1,0],\"scale\":[2,2,2]}]";
  Scene s = loadScene(dir.write("tr.gltf", primitiveGltf(kTriangle, {0, 1, 2}, 5123, nodes, "[0]")));
  ASSERT_EQ(s.triangleCount(), 1u);
  // Rotation about +y by 90 deg maps x -> -z; child scale 2 then translation (0,1,0).
  expectNear(s.positions[0], glm::vec3(10, 1, 0), 1e-4f);
  expectNear(s.positions[1], glm::vec3(10, 1, -2), 1e-4f);
  expectNear(s.positions[2], glm::vec3(10, 3, 0), 1e-4f);
  for (const glm::vec3& n : s.normals) expectNear(n, glm::vec3(1, 0, 0), 1e-4f);  // +z -> +x

  // The same through a column-major matrix on the parent.
  std::string matrixNodes =
      "[{\"matrix\":[0,0,-1,0, 0,1,0,0, 1,0,0,0, 10,0,0,1],\"children\":[1]},"
      "{\"mesh\":0,\"translation\":[0,1,0],\"scale\":[2,2,2]}]";
  Scene m = loadScene(dir.write("mat.gltf", primitiveGltf(kTriangle, {0, 1, 2}, 5123, matrixNodes, "[0]")));
  for (int i = 0; i < 3; ++i) expectNear(m.positions[size_t(i)], s.positions[size_t(i)], 1e-4f);
}

TEST(SceneLoader, MirroringFlipsWinding) {
  TempDir dir;
  std::string nodes = "[{\"mesh\":0,\"scale\":[-1,1,1]}]";
  Scene s = loadScene(dir.write("mirror.gltf", primitiveGltf(kTriangle, {0, 1, 2}, 5123, nodes, "[0]")));
  // The mirrored triangle still faces +z: winding was flipped with the negative determinant.
  EXPECT_GT(faceNormal(s, 0).z, 0.99f);
  for (const glm::vec3& n : s.normals) expectNear(n, glm::vec3(0, 0, 1));
}

TEST(SceneLoader, InstancesAndSkippedLines) {
  TempDir dir;
  // Mesh 0 referenced by two nodes; a camera and a point light on a rotated node.
  std::string nodes =
      "[{\"mesh\":0},{\"mesh\":0,\"translation\":[0,0,5]},"
      "{\"camera\":0,\"translation\":[1,2,3]},"
      "{\"rotation\":[0.7071068,0,0,0.7071068],\"translation\":[0,4,0],"
      "\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}]";
  std::string extra =
      ",\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.5,\"znear\":0.1}}]"
      ",\"extensionsUsed\":[\"KHR_lights_punctual\"]"
      ",\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"point\",\"intensity\":2}]}}";
  Scene s = loadScene(dir.write("inst.gltf", primitiveGltf(kTriangle, {0, 1, 2}, 5123, nodes, "[0,1,2,3]", extra)));
  EXPECT_EQ(s.triangleCount(), 2u);
  EXPECT_NEAR(s.bounds.max.z, 5.0f, 1e-6f);
  ASSERT_EQ(s.cameras.size(), 1u);
  expectNear(s.cameras[0].position, glm::vec3(1, 2, 3));
  expectNear(s.cameras[0].forward, glm::vec3(0, 0, -1));
  EXPECT_NEAR(s.cameras[0].yfov, 0.5f, 1e-6f);
  EXPECT_EQ(s.cameras[0].zfar, 100.0f);  // infinite in the file
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].type, LightType::Point);
  EXPECT_NEAR(s.lights[0].intensity, 2.0f, 1e-6f);
  expectNear(s.lights[0].position, glm::vec3(0, 4, 0));
  expectNear(s.lights[0].direction, glm::vec3(0, 1, 0), 1e-5f);  // +90 deg about x: -z -> +y
}

TEST(SceneLoader, WrongTopLevelTypeIsOneLine) {
  TempDir dir;
  std::string p = dir.write("nodes5.gltf", "{\"asset\":{\"version\":\"2.0\"},\"nodes\":5}");
  try {
    loadScene(p);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find("'nodes' must be an array"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

TEST(SceneLoader, FrameBoundsSeesEverything) {
  Bounds b;
  b.extend(glm::vec3(-1, 0, -2));
  b.extend(glm::vec3(3, 1, 2));
  Camera c = frameBounds(b, 0.8f);
  expectNear(c.forward, glm::vec3(0, 0, -1));
  EXPECT_GT(c.position.z, b.max.z);
  glm::mat4 vp = c.projection(1.0f) * c.view();
  for (int i = 0; i < 8; ++i) {
    glm::vec3 p((i & 1) ? b.max.x : b.min.x, (i & 2) ? b.max.y : b.min.y, (i & 4) ? b.max.z : b.min.z);
    glm::vec4 clip = vp * glm::vec4(p, 1.0f);
    glm::vec3 ndc = glm::vec3(clip) / clip.w;
    EXPECT_LE(std::abs(ndc.x), 1.0f);
    EXPECT_LE(std::abs(ndc.y), 1.0f);
    EXPECT_GT(ndc.z, -1.0f);
    EXPECT_LT(ndc.z, 1.0f);
  }
}

// --- malformed files -------------------------------------------------------------------------------

struct BadCase {
  const char* file;
  const char* phrase;
};

class BadScene : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadScene, ThrowsOneLineErrorNamingTheDefect) {
  const BadCase& c = GetParam();
  std::string path = projectPath(std::string("tests/data/bad/") + c.file);
  try {
    loadScene(path);
    FAIL() << c.file << " loaded without an error";
  } catch (const Error& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find(c.file), std::string::npos) << msg;
    EXPECT_NE(msg.find(c.phrase), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\r'), std::string::npos) << msg;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Files, BadScene,
    ::testing::Values(BadCase{"missing-buffer.gltf", "buffer 0 refers to external file 'missing-buffer.bin' which does not exist"},
                      BadCase{"index-out-of-range.gltf", "index 7 (entry 2) is out of range"},
                      BadCase{"nan-position.gltf", "mesh 0 ('triangle') primitive 0: vertex 1 has a NaN position"},
                      BadCase{"inf-position.gltf", "mesh 0 ('triangle') primitive 0: vertex 2 has an infinite (Inf) position"},
                      BadCase{"wrong-types.gltf", "accessors[0].count must be a non-negative integer, got a string"},
                      BadCase{"node-cycle.gltf", "node hierarchy has a cycle"},
                      BadCase{"unsupported-required-extension.gltf",
                              "requires unsupported extension KHR_draco_mesh_compression (supported: KHR_lights_punctual"},
                      BadCase{"gltf-1.0.gltf", "glTF version 1.0 is not supported"},
                      BadCase{"no-triangles.gltf", "contains no triangles"},
                      BadCase{"not-json.gltf", "is not valid JSON"},
                      BadCase{"empty-file.gltf", "file is empty"},
                      BadCase{"accessor-out-of-range.gltf", "is out of range"},
                      BadCase{"missing-texture.gltf", "image 0 refers to external file 'missing-texture.png' which does not exist"},
                      BadCase{"corrupt-texture.gltf", "image 0 ('corrupt-texture.png') cannot be decoded (stb_image:"},
                      BadCase{"bad-alpha-mode.gltf", "materials[0].alphaMode 'CUTOUT' is not one of OPAQUE, MASK, BLEND"}),
    [](const ::testing::TestParamInfo<BadCase>& info) {
      std::string name;
      for (const char* p = info.param.file; *p && *p != '.'; ++p) name += std::isalnum((unsigned char)*p) ? *p : '_';
      return name;
    });

TEST(SceneLoader, MissingFileIsOneLineError) {
  try {
    loadScene("/nonexistent/dir/scene.gltf");
    FAIL();
  } catch (const Error& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find("cannot read file"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos);
  }
}

}  // namespace
}  // namespace voxlab
