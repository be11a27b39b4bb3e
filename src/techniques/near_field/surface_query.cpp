#include "techniques/near_field/surface_query.h"

#include <algorithm>
#include <cmath>

#include "techniques/common/binary_voxels_stage.h"
#include "techniques/near_field/near_field.h"

namespace voxlab::nearfield {
namespace {

// Bilinear alpha (8-bit / 255) with REPEAT wrap; row 0 of the image is v = 0.
float textureAlpha(const TextureImage& t, glm::vec2 uv) {
  if (t.width <= 0 || t.height <= 0 || t.rgba8.size() < size_t(t.width) * t.height * 4) return 1.0f;
  const float x = uv.x * t.width - 0.5f, y = uv.y * t.height - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y), ax = x - fx, ay = y - fy;
  auto wrap = [](long i, int n) { long m = i % n; return int(m < 0 ? m + n : m); };
  const int x0 = wrap(long(fx), t.width), x1 = wrap(long(fx) + 1, t.width);
  const int y0 = wrap(long(fy), t.height), y1 = wrap(long(fy) + 1, t.height);
  auto at = [&](int xx, int yy) { return float(t.rgba8[(size_t(yy) * t.width + xx) * 4 + 3]) / 255.0f; };
  return (at(x0, y0) * (1 - ax) + at(x1, y0) * ax) * (1 - ay) + (at(x0, y1) * (1 - ax) + at(x1, y1) * ax) * ay;
}

bool cutAway(const Scene& scene, size_t tri, double b1, double b2) {
  const uint32_t mi = scene.triangleMaterial(tri);
  if (mi >= scene.materials.size()) return false;
  const Material& m = scene.materials[mi];
  if (m.alphaMode != AlphaMode::Mask) return false;
  float a = m.baseColor.w;
  if (m.baseColorTexture >= 0 && size_t(m.baseColorTexture) < scene.textures.size() &&
      scene.uvs.size() == scene.positions.size()) {
    const glm::vec2 u0 = scene.uvs[scene.indices[3 * tri]], u1 = scene.uvs[scene.indices[3 * tri + 1]],
                    u2 = scene.uvs[scene.indices[3 * tri + 2]];
    const glm::vec2 uv = u0 * float(1.0 - b1 - b2) + u1 * float(b1) + u2 * float(b2);
    a *= textureAlpha(scene.textures[size_t(m.baseColorTexture)], uv);
  }
  return a < m.alphaCutoff;
}

}  // namespace

SurfaceHit firstSurfaceAlong(const Scene& scene, glm::vec3 o, glm::vec3 d, float tMax) {
  SurfaceHit best;
  double bestT = double(tMax);
  const glm::dvec3 O(o), D(d);
  const size_t n = scene.triangleCount();
  for (size_t k = 0; k < n; ++k) {
    const glm::dvec3 p0(scene.positions[scene.indices[3 * k]]);
    const glm::dvec3 e1 = glm::dvec3(scene.positions[scene.indices[3 * k + 1]]) - p0;
    const glm::dvec3 e2 = glm::dvec3(scene.positions[scene.indices[3 * k + 2]]) - p0;
    const glm::dvec3 pv = glm::cross(D, e2);
    const double det = glm::dot(e1, pv);
    if (det == 0.0) continue;  // the ray lies in the triangle's plane: it grazes, no crossing
    const double inv = 1.0 / det;
    const glm::dvec3 s = O - p0;
    const double b1 = glm::dot(s, pv) * inv;
    if (b1 < 0.0 || b1 > 1.0) continue;
    const glm::dvec3 q = glm::cross(s, e1);
    const double b2 = glm::dot(D, q) * inv;
    if (b2 < 0.0 || b1 + b2 > 1.0) continue;
    const double t = glm::dot(e2, q) * inv;
    if (t <= 0.0 || t > bestT) continue;
    if (cutAway(scene, k, b1, b2)) continue;
    bestT = t;
    best.hit = true;
    best.t = float(t);
    best.triangle = uint32_t(k);
  }
  return best;
}

VoxelGap gapToVoxel(const BinaryGridGeometry& geo, glm::ivec3 voxel, glm::vec3 p) {
  const glm::vec3 dims(float(geo.resolution), float(geo.resolution), float(kBinarySlices));
  const glm::vec3 c = (p - geo.origin) / geo.edge * dims;  // p in cells
  const glm::vec3 lo(voxel), hi = lo + 1.0f;
  const glm::vec3 off = glm::max(glm::max(lo - c, c - hi), glm::vec3(0.0f));
  VoxelGap g;
  g.chebyshev = std::max({off.x, off.y, off.z});
  g.euclidean = glm::length(off);
  return g;
}

}  // namespace voxlab::nearfield
