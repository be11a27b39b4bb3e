#include "techniques/common/cone_layout.h"

#include <algorithm>
#include <cmath>

namespace voxlab {

std::vector<Cone> diffuseCones(int count, float aperture, const std::string& layout, const std::string& weighting) {
  const float pi = 3.14159265358979f;
  std::vector<Cone> cones;
  if (layout == "fibonacci") {
    const float golden = pi * (3.0f - std::sqrt(5.0f));
    for (int k = 0; k < count; ++k) {
      float r = std::sqrt((k + 0.5f) / float(count));
      float phi = golden * float(k);
      cones.push_back({{r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - r * r))}, 1.0f});
    }
  } else {
    cones.push_back({{0.0f, 0.0f, 1.0f}, 1.0f});
    float tilt = std::min(aperture, 0.5f * pi - 0.25f * aperture);
    for (int k = 1; k < count; ++k) {
      float phi = 2.0f * pi * float(k - 1) / float(count - 1);
      cones.push_back({{std::sin(tilt) * std::cos(phi), std::sin(tilt) * std::sin(phi), std::cos(tilt)}, 1.0f});
    }
  }
  float sum = 0.0f;
  for (auto& c : cones) {
    c.weight = weighting == "equal" ? 1.0f : std::max(c.direction.z, 0.0f);
    sum += c.weight;
  }
  for (auto& c : cones) c.weight /= sum;
  return cones;
}

}  // namespace voxlab
