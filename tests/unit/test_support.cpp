#include "test_support.h"

#include <filesystem>
#include <fstream>
#include <map>

#include <gtest/gtest.h>

#include <glm/gtx/string_cast.hpp>

#include "core/error.h"
#include "scene/scene.h"

namespace voxlab::testing_support {

namespace {
std::map<std::string, std::unique_ptr<HeadlessSession>> sessions;
}  // namespace

HeadlessSession& freshSession(const RunRequest& r) {
  sessions.clear();
  auto& fresh = sessions["fresh: not cached"];  // no request key: session() never returns it
  fresh = std::make_unique<HeadlessSession>(r);
  return *fresh;
}

HeadlessSession& session(const RunRequest& r) {
  std::string key = r.technique + "|" + r.scene + "|" + r.until + "|" + std::to_string(r.width) + "x" +
                    std::to_string(r.height) + "|" + std::to_string(r.camera);
  auto point = [](const glm::vec3& p) { return std::to_string(p.x) + "," + std::to_string(p.y) + "," + std::to_string(p.z); };
  if (r.lookFrom) key += "|from " + point(*r.lookFrom);
  if (r.lookAt) key += "|at " + point(*r.lookAt);
  for (const auto& s : r.sets) key += "|" + s;
  if (r.lookFrom) key += "|from " + glm::to_string(*r.lookFrom) + " at " + glm::to_string(*r.lookAt);
  auto& slot = sessions[key];
  if (!slot) {
    // One GL context per process: drop the others first (each session owns its context).
    sessions.clear();
    auto& fresh = sessions[key];
    fresh = std::make_unique<HeadlessSession>(r);
    fresh->run();
    return *fresh;
  }
  return *slot;
}

void expectSceneRejected(const std::string& path, const std::string& expected) {
  try {
    loadScene(path);
    ADD_FAILURE() << path << " loaded; expected an error containing '" << expected << "'";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(std::filesystem::path(path).filename().string()), std::string::npos) << what;
    EXPECT_NE(what.find(expected), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

CapturedOutput capture(HeadlessSession& s, const std::string& stage, const std::string& output) {
  auto [index, desc] = s.cursor().technique().findOutput(stage, output);
  (void)index;
  return captureOutput(s.cursor().board(), *desc);
}

std::string writeFloorAndWallScene(const std::string& name, const std::string& lightJson,
                                   const std::string& lightNodeJson) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(::testing::TempDir()) / ("voxlab-" + name);
  fs::create_directories(dir);
  // Floor (2 triangles, +y) and the wall as a closed box (12 triangles).
  std::vector<float> pos = {-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1};
  std::vector<uint32_t> idx = {0, 2, 1, 0, 3, 2};
  const glm::vec3 lo(0.6f, 0.0f, -0.2f), hi(0.62f, 0.5f, 0.2f);
  for (int k = 0; k < 8; ++k) {
    pos.push_back((k & 1) ? hi.x : lo.x);
    pos.push_back((k & 2) ? hi.y : lo.y);
    pos.push_back((k & 4) ? hi.z : lo.z);
  }
  const uint32_t box[36] = {0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2,
                            1, 3, 7, 1, 7, 5, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6};
  for (uint32_t i : box) idx.push_back(4 + i);
  std::ofstream bin(dir / (name + ".bin"), std::ios::binary);
  bin.write(reinterpret_cast<const char*>(pos.data()), std::streamsize(pos.size() * 4));
  bin.write(reinterpret_cast<const char*>(idx.data()), std::streamsize(idx.size() * 4));
  bin.close();
  const size_t p = pos.size() * 4, n = idx.size() * 4;
  // The camera's rotation turns -z onto -y (90 degrees about x).
  const std::string gltf =
      "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2]}],"
      "\"nodes\":[{\"mesh\":0},{\"camera\":0,\"translation\":[0,2.5,0],\"rotation\":[-0.7071068,0,0,0.7071068]},"
      "{" + lightNodeJson + ",\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}],"
      "\"extensionsUsed\":[\"KHR_lights_punctual\"],"
      "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[" + lightJson + "]}},"
      "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.9,\"znear\":0.05,\"zfar\":20}}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1,\"material\":0}]}],"
      "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.5,0.5,1]}}],"
      "\"buffers\":[{\"uri\":\"" + name + ".bin\",\"byteLength\":" + std::to_string(p + n) + "}],"
      "\"bufferViews\":[{\"buffer\":0,\"byteLength\":" + std::to_string(p) + "},"
      "{\"buffer\":0,\"byteOffset\":" + std::to_string(p) + ",\"byteLength\":" + std::to_string(n) + "}],"
      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":" + std::to_string(pos.size() / 3) +
      ",\"type\":\"VEC3\"},{\"bufferView\":1,\"componentType\":5125,\"count\":" + std::to_string(idx.size()) +
      ",\"type\":\"SCALAR\"}]}";
  const std::string path = (dir / (name + ".gltf")).string();
  std::ofstream(path) << gltf;
  return path;
}

}  // namespace voxlab::testing_support
