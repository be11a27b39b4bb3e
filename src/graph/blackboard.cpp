#include "graph/blackboard.h"

#include "core/error.h"

namespace voxlab {

Texture& Blackboard::ensureTexture(const std::string& name, const TextureDesc& desc) {
  auto& slot = textures_[name];
  if (!slot || !slot->matches(desc)) slot = std::make_unique<Texture>(name, desc);
  return *slot;
}

Buffer& Blackboard::ensureBuffer(const std::string& name, size_t bytes) {
  auto& slot = buffers_[name];
  if (!slot || slot->size() < bytes) slot = std::make_unique<Buffer>(name, bytes);
  return *slot;
}

Texture& Blackboard::texture(const std::string& name) {
  auto it = textures_.find(name);
  if (it == textures_.end()) throw Error("no texture '" + name + "' on the blackboard (has its stage run?)");
  return *it->second;
}

Buffer& Blackboard::buffer(const std::string& name) {
  auto it = buffers_.find(name);
  if (it == buffers_.end()) throw Error("no buffer '" + name + "' on the blackboard (has its stage run?)");
  return *it->second;
}

size_t Blackboard::totalBytes() const {
  size_t total = 0;
  for (const auto& [n, t] : textures_) total += t->byteSize();
  for (const auto& [n, b] : buffers_) total += b->size();
  return total;
}

std::optional<WorldBox> Blackboard::placementOf(const std::string& name) const {
  auto p = placements_.find(name);
  if (p != placements_.end()) return p->second;
  auto t = textures_.find(name);
  if (t == textures_.end() || t->second->desc().target != GL_TEXTURE_3D) return std::nullopt;
  return voxelSpace_;
}

void Blackboard::clear() {
  textures_.clear();
  buffers_.clear();
  voxelSpace_.reset();
  placements_.clear();
}

}  // namespace voxlab
