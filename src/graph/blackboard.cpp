#include "graph/blackboard.h"

#include "core/error.h"
#include "graph/resource_budget.h"

namespace voxlab {

void Blackboard::checkGrowth(const std::string& name, size_t oldBytes, size_t newBytes) const {
  if (memoryBudget_ == 0 || newBytes <= oldBytes) return;
  const size_t total = totalBytes() - oldBytes + newBytes;
  if (total <= memoryBudget_) return;
  throw Error(name + " needs " + formatBytes(newBytes) + ", which takes the run's GPU resources to " + formatBytes(total) +
              ", over " + memoryBudgetParam().name + "=" + std::to_string(memoryBudget_ >> 20) +
              " MiB (sized from the scene's counts; raise the budget or lower the resolution)");
}

Texture& Blackboard::ensureTexture(const std::string& name, const TextureDesc& desc) {
  auto it = textures_.find(name);
  if (it == textures_.end() || !it->second || !it->second->matches(desc)) {
    const size_t oldBytes = it != textures_.end() && it->second ? it->second->byteSize() : 0;
    checkGrowth(name, oldBytes, textureBytes(desc));
    auto& slot = textures_[name];
    slot.reset();  // the old storage first, so that the two never coexist
    slot = std::make_unique<Texture>(name, desc);
    return *slot;
  }
  return *it->second;
}

Buffer& Blackboard::ensureBuffer(const std::string& name, size_t bytes) {
  auto it = buffers_.find(name);
  if (it == buffers_.end() || !it->second || it->second->size() < bytes) {
    checkGrowth(name, it != buffers_.end() && it->second ? it->second->size() : 0, bytes);
    auto& slot = buffers_[name];
    slot = std::make_unique<Buffer>(name, bytes);
    return *slot;
  }
  return *it->second;
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
