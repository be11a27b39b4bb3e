#include "graph/resource_budget.h"

#include <algorithm>
#include <cstdio>
#include <set>

#include "gpu/resources.h"

namespace voxlab {

ParamDesc memoryBudgetParam() {
  return ParamDesc::integer("gpu.memory-budget", 4096, 64, 1 << 20,
                            "GPU memory a run may allocate; larger runs are refused before allocating", "MiB");
}

ResourceLimits ResourceLimits::query() {
  ResourceLimits l;
  GLint v = 0;
  glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &v);
  if (v > 0) l.max3DTextureSize = v;
  v = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &v);
  if (v > 0) l.max2DTextureSize = v;
  GLint64 b = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &b);
  if (b > 0) l.maxBufferBytes = size_t(b);
  return l;
}

ResourceEstimate estimateResources(const Technique& technique, const ParamSet& params, const ViewState& view) {
  ResourceEstimate e;
  // A resource two stages declare (scratch they share, e.g. vct-grid's packed directional volumes)
  // is one blackboard object: counted once, as its first declaration sizes it.
  std::set<std::string> counted;
  for (int i = 0; i < technique.stageCount(); ++i) {
    for (const ResourceDecl& r : technique.decl(i).resources) {
      if (!counted.insert(r.resource).second) continue;
      ResourceEstimateItem item;
      item.stage = technique.stage(i).id();
      item.resource = r.resource;
      item.pool = r.pool;
      if (r.texture) {
        TextureDesc d = r.texture(params, view);
        item.isTexture = true;
        item.is3D = d.target == GL_TEXTURE_3D;
        item.size = d.size;
        item.bytes = textureBytes(d);
      } else if (r.bufferBytes) {
        item.bytes = r.bufferBytes(params, view);
      }
      e.totalBytes += item.bytes;
      e.items.push_back(item);
    }
  }
  return e;
}

std::string formatBytes(size_t bytes) {
  const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB"};
  double v = double(bytes);
  int u = 0;
  while (v >= 1024.0 && u < 4) { v /= 1024.0; ++u; }
  char text[64];
  if (u == 0) std::snprintf(text, sizeof text, "%zu bytes", bytes);
  else std::snprintf(text, sizeof text, v < 10 ? "%.1f %s" : "%.0f %s", v, units[u]);
  return text;
}

namespace {

// The first limit the estimate breaks, as a phrase; "" when it fits.
std::string firstExcess(const ResourceEstimate& e, const ParamSet& params, const ResourceLimits& limits) {
  for (const auto& item : e.items) {
    if (item.isTexture) {
      const int limit = item.is3D ? limits.max3DTextureSize : limits.max2DTextureSize;
      const int biggest = std::max(item.size.x, std::max(item.size.y, item.is3D ? item.size.z : 0));
      if (biggest > limit) {
        return std::string(item.is3D ? "3D" : "2D") + " texture '" + item.resource + "' of " + std::to_string(biggest) +
               " texels exceeds " + (item.is3D ? "GL_MAX_3D_TEXTURE_SIZE" : "GL_MAX_TEXTURE_SIZE") + " " +
               std::to_string(limit);
      }
    } else if (item.bytes > limits.maxBufferBytes) {
      return "buffer '" + item.resource + "' of " + formatBytes(item.bytes) +
             " exceeds GL_MAX_SHADER_STORAGE_BLOCK_SIZE " + formatBytes(limits.maxBufferBytes);
    }
  }
  const size_t budget = size_t(params.getInt(memoryBudgetParam().name)) << 20;
  if (e.totalBytes > budget) {
    return "the run needs " + formatBytes(e.totalBytes) + " of GPU memory, over " + memoryBudgetParam().name + "=" +
           std::to_string(params.getInt(memoryBudgetParam().name)) + " MiB";
  }
  return "";
}

bool fits(const Technique& t, const ParamSet& params, const ViewState& view, const ResourceLimits& limits) {
  return firstExcess(estimateResources(t, params, view), params, limits).empty();
}

// Valid values of an integer parameter from its minimum up to (excluding) 'below', ascending:
// count() of them, the i-th by at(i), without listing a long linear range.
struct ValuesBelow {
  std::vector<int> powers;  // power-of-two parameters
  long long lo = 0, n = 0;  // others: lo, lo + 1, ..., lo + n - 1
  bool pow2 = false;
  ValuesBelow(const ParamDesc& d, int below) : pow2(d.powerOfTwo) {
    const long long min = (long long)d.minValue;
    if (pow2) {
      for (long long v = 1; v < below; v *= 2)
        if (v >= min) powers.push_back(int(v));
    } else {
      lo = min;
      n = std::max(0LL, below - min);
    }
  }
  long long count() const { return pow2 ? (long long)powers.size() : n; }
  int at(long long i) const { return pow2 ? powers[size_t(i)] : int(lo + i); }
};

}  // namespace

std::string checkResourceBudget(const Technique& technique, const ParamSet& params, const ViewState& view,
                                const ResourceLimits& limits) {
  const std::string excess = firstExcess(estimateResources(technique, params, view), params, limits);
  if (excess.empty()) return "";
  // The parameter that made it too large: among integer parameters that fit when lowered alone,
  // the one furthest above its default (current / default). The budget itself is not lowered.
  std::string bestName;
  int bestFit = 0;
  double bestRatio = -1.0;
  for (const auto& [name, desc] : params.descs()) {
    if (desc.type != ParamType::Int || name == memoryBudgetParam().name) continue;
    const int current = params.getInt(name);
    const ValuesBelow values(desc, current);
    if (values.count() == 0) continue;
    ParamSet trial = params;
    trial.set(name, values.at(0));
    if (!fits(technique, trial, view, limits)) continue;
    // Fitting is monotonic in a size parameter: bisect for the largest value that fits.
    long long lo = 0, hi = values.count() - 1;
    while (lo < hi) {
      long long mid = (lo + hi + 1) / 2;
      trial.set(name, values.at(mid));
      if (fits(technique, trial, view, limits)) lo = mid; else hi = mid - 1;
    }
    const double ratio = double(current) / std::max(1.0, desc.defaultValue);
    if (ratio > bestRatio) {
      bestRatio = ratio;
      bestName = name;
      bestFit = values.at(lo);
    }
  }
  std::string line = technique.id() + ": " + excess;
  if (bestName.empty())
    return line + "; no single smaller parameter makes it fit (raise " + memoryBudgetParam().name + ")";
  return line + "; " + bestName + "=" + std::to_string(params.getInt(bestName)) + " is too large, the largest " +
         bestName + " that fits is " + std::to_string(bestFit);
}

}  // namespace voxlab
