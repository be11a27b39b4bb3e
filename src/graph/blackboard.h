// Blackboard: the named GPU resources a technique's stages share. A stage creates or reuses a
// resource by name (ensure*), later stages look it up, and outputs refer to it by name, so
// readback, export and inspection work on any resource without knowing which stage made it.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <variant>

#include <optional>

#include <glm/glm.hpp>

#include "gpu/resources.h"

namespace voxlab {

// Where a volume sits in the world: level 0 spans [lo, hi] (every mip level spans the same box).
struct WorldBox {
  glm::vec3 lo{0.0f}, hi{1.0f};
};

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

  // The memory budget of the run (gpu.memory-budget, set by the step cursor before each stage;
  // 0 = none). The run's estimate is checked before any allocation (graph/resource_budget.h), but
  // pools are sized from the scene's counts as the stages go: an ensure* that would take the
  // blackboard's resources over the budget throws one line naming the resource and the sizes, and
  // allocates nothing (the resource keeps its former size).
  void setMemoryBudget(size_t bytes) { memoryBudget_ = bytes; }

  // World placement of volumes, so viewers and exports can show voxels in the scene without
  // knowing the stage: the voxel space (set by the stage that defines it) applies to every 3D
  // texture without a placement of its own (e.g. a clip level or a propagation grid sets one).
  void setVoxelSpace(const WorldBox& box) { voxelSpace_ = box; }
  void place(const std::string& texture, const WorldBox& box) { placements_[texture] = box; }
  std::optional<WorldBox> placementOf(const std::string& texture) const;
  const std::optional<WorldBox>& voxelSpace() const { return voxelSpace_; }

  // The camera the camera images were rendered from, recorded by the stage that rasterizes them
  // (the shared G-buffer stage): the cursor's view, or one a stage derived from it (clipmap renders
  // from the end of its camera path). The viewer draws its overlays on camera images from it, so
  // boxes and voxels line up with the picture whatever camera made it.
  struct RenderedCamera {
    glm::vec3 position{0.0f};
    glm::mat4 view{1.0f}, projection{1.0f};
  };
  void setRenderedCamera(const RenderedCamera& c) { renderedCamera_ = c; }
  const std::optional<RenderedCamera>& renderedCamera() const { return renderedCamera_; }

 private:
  std::map<std::string, std::unique_ptr<Texture>> textures_;
  std::map<std::string, std::unique_ptr<Buffer>> buffers_;
  std::optional<WorldBox> voxelSpace_;
  std::optional<RenderedCamera> renderedCamera_;
  std::map<std::string, WorldBox> placements_;
  size_t memoryBudget_ = 0;
  void checkGrowth(const std::string& name, size_t oldBytes, size_t newBytes) const;
};

}  // namespace voxlab
