#include "ao_next_to_wall.h"

#include <cmath>

namespace voxlab::testing_support {

double visibleFractionNextToWall(double px, double pz) {
  const int nTheta = 400, nPhi = 800;
  double visible = 0, total = 0;
  for (int i = 0; i < nTheta; ++i) {
    double theta = (i + 0.5) / nTheta * M_PI / 2;
    for (int j = 0; j < nPhi; ++j) {
      double phi = (j + 0.5) / nPhi * 2 * M_PI;
      double dx = std::sin(theta) * std::cos(phi), dy = std::cos(theta), dz = std::sin(theta) * std::sin(phi);
      double w = std::cos(theta) * std::sin(theta);
      total += w;
      bool blocked = false;
      if (dz > 0) {
        double t = (0.1 - pz) / dz;
        double x = px + t * dx, y = t * dy;
        blocked = x >= -1 && x <= 1 && y >= 0 && y <= 2;
      }
      if (!blocked) visible += w;
    }
  }
  return visible / total;
}

size_t floorTexelNearest(const LevelData& position, glm::vec3 target, float& distance) {
  const std::vector<float>& v = position.values;
  size_t best = 0;
  distance = 1e30f;
  for (size_t t = 0; t < position.texelCount(); ++t) {
    if (v[t * 4 + 3] == 0 || std::abs(v[t * 4 + 1]) > 1e-3f) continue;
    float d = glm::length(glm::vec3(v[t * 4], v[t * 4 + 1], v[t * 4 + 2]) - target);
    if (d < distance) { distance = d; best = t; }
  }
  return best;
}

}  // namespace voxlab::testing_support
