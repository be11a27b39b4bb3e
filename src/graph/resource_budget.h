// Resource budget: what a technique will allocate for a parameter set and view, computed from
// its stages' ResourceDecls (graph/stage.h) before any GL allocation, and checked against the
// GL limits and a memory budget (the parameter gpu.memory-budget, every technique has it).
// A run that would not fit is refused with one line naming the parameter that made it too
// large and the largest value of it that fits.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "graph/technique.h"

namespace voxlab {

// The memory budget parameter every technique declares (Technique::defaultParams adds it).
ParamDesc memoryBudgetParam();

struct ResourceLimits {
  int max3DTextureSize = 2048;        // GL_MAX_3D_TEXTURE_SIZE
  int max2DTextureSize = 16384;       // GL_MAX_TEXTURE_SIZE
  size_t maxBufferBytes = size_t(1) << 31;  // GL_MAX_SHADER_STORAGE_BLOCK_SIZE (buffers are bound whole)
  // Limits of the current GL context (needs one current).
  static ResourceLimits query();
};

struct ResourceEstimateItem {
  std::string stage;
  std::string resource;
  bool isTexture = false;
  bool is3D = false;
  glm::ivec3 size{0};  // textures
  size_t bytes = 0;    // all levels for textures
  bool pool = false;   // a starting size that may grow with the scene
};

struct ResourceEstimate {
  std::vector<ResourceEstimateItem> items;
  size_t totalBytes = 0;
};

ResourceEstimate estimateResources(const Technique& technique, const ParamSet& params, const ViewState& view);

// "" when the estimate fits the limits and params' gpu.memory-budget; otherwise one line: what
// does not fit, the parameter that made it too large and the largest value of it that fits.
std::string checkResourceBudget(const Technique& technique, const ParamSet& params, const ViewState& view,
                                const ResourceLimits& limits);

// "1.5 GiB", "300 MiB", "12 KiB"
std::string formatBytes(size_t bytes);

}  // namespace voxlab
