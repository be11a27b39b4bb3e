// Pass 1 of loading a glTF file (loadScene, scene/gltf_loader.cpp): the structural check of its
// JSON before tinygltf sees it - types, version, required extensions, references in range, node
// cycles, external files present. tinygltf is lenient about several of these and its own messages
// span several lines; every defect found here is one line naming the file.
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "core/error.h"

namespace voxlab::gltf {

// Collapses any multi-line / control-character text into one trimmed line of bounded length.
std::string oneLine(const std::string& text, size_t maxLength = 400);
// The error of a scene file that cannot be loaded: "scene '<path>': <what>", on one line.
Error sceneError(const std::string& path, const std::string& what);

class JsonChecker {
 public:
  // path: the file, for messages; baseDir: its folder, where external buffers and images are looked for.
  JsonChecker(std::string path, std::string baseDir) : path_(std::move(path)), baseDir_(std::move(baseDir)) {}
  // Throws sceneError on the first defect of the parsed document 'root'.
  void check(const nlohmann::json& root);

 private:
  [[noreturn]] void fail(const std::string& what) const { throw sceneError(path_, what); }
  void checkJson(const nlohmann::json& root);
  void checkMaterialAlpha(const nlohmann::json& material, const std::string& where);
  void checkCycles(const nlohmann::json& root);
  void checkExternalFiles(const nlohmann::json& root);

  std::string path_;
  std::string baseDir_;
};

}  // namespace voxlab::gltf
