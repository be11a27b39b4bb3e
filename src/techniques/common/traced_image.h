// Images traced at a fraction of the view (cone and ray tracers): the resolution parameter (full,
// or half: one trace per 2x2 block, whose top-left G-buffer pixel it shades), the scale it gives
// and the images' descriptions. The composite upsamples such images along surfaces
// (shaders/common/upsample.glsl).
#pragma once
#include <string>

#include <glm/glm.hpp>

#include "gpu/resources.h"
#include "graph/param.h"
#include "graph/stage.h"

namespace voxlab {

// A view-sized (or any-sized) 2D image read texel by texel: nearest filtering, one level.
TextureDesc imageDesc(int width, int height, GLenum format);
inline TextureDesc viewImageDesc(const ViewState& view, GLenum format) { return imageDesc(view.width, view.height, format); }

struct TracedImages {
  const char* param;   // the resolution parameter: "cone.resolution"
  const char* traces;  // what is traced, for its help: "cones"

  ParamDesc resolutionParam() const;  // half (the default) or full
  int scale(const ParamSet& params) const;  // G-buffer pixels per traced pixel along each axis: 2 or 1
  glm::ivec2 size(const ParamSet& params, const ViewState& view) const;  // the view / scale, rounded up
  TextureDesc desc(const ParamSet& params, const ViewState& view, GLenum format) const;
  // Declares the traced image 'name' for the resource budget.
  void declareImage(StageBuilder& b, const std::string& name, GLenum format) const;
};

inline constexpr TracedImages kTracedCones{"cone.resolution", "cones"};
inline constexpr TracedImages kTracedRays{"rays.resolution", "rays"};

}  // namespace voxlab
