// Images traced at a fraction of the view (traced_image.h).
#include "techniques/common/traced_image.h"

namespace voxlab {

TextureDesc imageDesc(int width, int height, GLenum format) {
  TextureDesc d;
  d.format = format;
  d.size = {width, height, 1};
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}

ParamDesc TracedImages::resolutionParam() const {
  return ParamDesc::choice(param, {"half", "full"}, 0,
                           std::string("trace ") + traces + " for every pixel (full) or every 2x2 block (half, 4x "
                           "cheaper; composite upsamples along surfaces)");
}

int TracedImages::scale(const ParamSet& params) const { return params.getChoice(param) == "half" ? 2 : 1; }

glm::ivec2 TracedImages::size(const ParamSet& params, const ViewState& view) const {
  const int s = scale(params);
  return {(view.width + s - 1) / s, (view.height + s - 1) / s};
}

TextureDesc TracedImages::desc(const ParamSet& params, const ViewState& view, GLenum format) const {
  const glm::ivec2 traced = size(params, view);
  return imageDesc(traced.x, traced.y, format);
}

void TracedImages::declareImage(StageBuilder& b, const std::string& name, GLenum format) const {
  b.texture(name, [images = *this, format](const ParamSet& p, const ViewState& v) { return images.desc(p, v, format); });
}

}  // namespace voxlab
