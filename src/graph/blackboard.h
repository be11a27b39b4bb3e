// Blackboard: the named GPU resources a technique's stages share. A stage creates or reuses a
// resource by name (ensure*), later stages look it up, and outputs refer to it by name, so
// readback, export and inspection work on any resource without knowing which stage made it.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <variant>

#include "gpu/resources.h"

namespace voxlab {

class Blackboard {
 public:
  // Returns the texture called 'name', (re)creating it when absent or when 'desc' differs.
  Texture& ensureTexture(const std::string& name, const TextureDesc& desc);
  // Returns the buffer called 'name', (re)creating it when absent or smaller than 'bytes'.
  Buffer& ensureBuffer(const std::string& name, size_t bytes);

  bool hasTexture(const std::string& name) const { return textures_.count(name) != 0; }
  bool hasBuffer(const std::string& name) const { return buffers_.count(name) != 0; }
  Texture& texture(const std::string& name);  // throws Error naming the missing resource
  Buffer& buffer(const std::string& name);
  const std::map<std::string, std::unique_ptr<Texture>>& textures() const { return textures_; }
  const std::map<std::string, std::unique_ptr<Buffer>>& buffers() const { return buffers_; }
  size_t totalBytes() const;
  void clear();

 private:
  std::map<std::string, std::unique_ptr<Texture>> textures_;
  std::map<std::string, std::unique_ptr<Buffer>> buffers_;
};

}  // namespace voxlab
