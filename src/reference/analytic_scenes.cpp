#include "reference/analytic_scenes.h"

#include <cmath>

#include "core/error.h"

namespace voxlab::reference::analytic {

namespace {
constexpr double kPiD = 3.14159265358979323846;
}

SceneBuilder::SceneBuilder(std::string name) { base_.name = std::move(name); }

uint32_t SceneBuilder::material(const std::string& name, glm::vec3 albedo, glm::vec3 emissive) {
  Material m;
  m.name = name;
  m.baseColor = glm::vec4(albedo, 1.0f);
  m.emissive = emissive;
  base_.materials.push_back(m);
  perMaterial_.emplace_back();
  return uint32_t(base_.materials.size() - 1);
}

void SceneBuilder::triangle(glm::vec3 a, glm::vec3 b, glm::vec3 c, uint32_t material, glm::vec3 facing) {
  if (material >= perMaterial_.size()) throw Error("SceneBuilder: material index out of range");
  glm::vec3 n = glm::cross(b - a, c - a);
  if (glm::dot(n, facing) < 0.0f) {
    std::swap(b, c);
    n = -n;
  }
  float len = glm::length(n);
  perMaterial_[material].push_back(Tri{{a, b, c}, len > 0.0f ? n / len : glm::normalize(facing)});
}

void SceneBuilder::quad(glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3, uint32_t material,
                        glm::vec3 facing) {
  triangle(p0, p1, p2, material, facing);
  triangle(p0, p2, p3, material, facing);
}

void SceneBuilder::camera(const std::string& name, glm::vec3 position, glm::vec3 forward, glm::vec3 up,
                          float yfov) {
  Camera c;
  c.name = name;
  c.position = position;
  c.forward = glm::normalize(forward);
  glm::vec3 right = glm::normalize(glm::cross(c.forward, up));
  c.up = glm::cross(right, c.forward);
  c.yfov = yfov;
  base_.cameras.push_back(c);
}

Scene SceneBuilder::build() const {
  Scene s = base_;
  s.path = "(procedural)";
  for (uint32_t m = 0; m < perMaterial_.size(); ++m) {
    if (perMaterial_[m].empty()) continue;
    DrawRange d;
    d.firstIndex = uint32_t(s.indices.size());
    d.material = m;
    for (const Tri& t : perMaterial_[m]) {
      for (int k = 0; k < 3; ++k) {
        s.indices.push_back(uint32_t(s.positions.size()));
        s.positions.push_back(t.p[k]);
        s.normals.push_back(t.n);
        s.uvs.emplace_back(0.0f);
        s.bounds.extend(t.p[k]);
      }
    }
    d.indexCount = uint32_t(s.indices.size()) - d.firstIndex;
    s.draws.push_back(d);
  }
  if (s.materials.empty()) s.materials.push_back(Material{"default"});
  if (s.cameras.empty()) {
    Camera c;
    c.name = "default";
    glm::vec3 ctr = s.bounds.valid() ? s.bounds.center() : glm::vec3(0.0f);
    float r = s.bounds.valid() ? glm::length(s.bounds.extent()) : 1.0f;
    c.position = ctr + glm::vec3(0.0f, 0.0f, 1.5f * r);
    c.forward = glm::vec3(0.0f, 0.0f, -1.0f);
    s.cameras.push_back(c);
  }
  return s;
}

// --- White furnace -----------------------------------------------------------------------------
Scene furnaceBox(float rho, glm::vec3 Le, float size) {
  SceneBuilder b("furnace-box");
  uint32_t m = b.material("furnace", glm::vec3(rho), Le);
  float h = 0.5f * size;
  // Each face: a quad in the plane axis = +-h, front side facing the centre.
  for (int axis = 0; axis < 3; ++axis) {
    for (float sgn : {-1.0f, 1.0f}) {
      int u = (axis + 1) % 3, v = (axis + 2) % 3;
      glm::vec3 p[4];
      const float cu[4] = {-h, h, h, -h}, cv[4] = {-h, -h, h, h};
      for (int k = 0; k < 4; ++k) {
        p[k][axis] = sgn * h;
        p[k][u] = cu[k];
        p[k][v] = cv[k];
      }
      glm::vec3 inward(0.0f);
      inward[axis] = -sgn;
      b.quad(p[0], p[1], p[2], p[3], m, inward);
    }
  }
  b.camera("inside", glm::vec3(0.0f), glm::vec3(0, 0, -1), glm::vec3(0, 1, 0), 1.0f);
  return b.build();
}

double furnaceRadiance(double rho, double Le, int maxReflections) {
  if (maxReflections < 0) return Le / (1.0 - rho);
  return Le * (1.0 - std::pow(rho, maxReflections + 1)) / (1.0 - rho);
}

// --- Wall ----------------------------------------------------------------------------------------
Scene floorAndWall(float d, float h, float halfLength, float floorHalf) {
  SceneBuilder b("floor-and-wall");
  uint32_t floor = b.material("floor", glm::vec3(0.5f));
  uint32_t wall = b.material("wall", glm::vec3(0.5f));
  float f = floorHalf;
  b.quad({-f, 0, -f}, {f, 0, -f}, {f, 0, f}, {-f, 0, f}, floor, {0, 1, 0});
  float L = halfLength;
  b.quad({d, 0, -L}, {d, h, -L}, {d, h, L}, {d, 0, L}, wall, {-1, 0, 0});
  b.camera("overview", {-2.0f * d - h, 1.5f * h, 0.0f}, {1.0f, -0.5f, 0.0f}, {0, 1, 0}, 1.0f);
  return b.build();
}

double aoNextToInfiniteWall(double d, double h) { return 0.5 * (1.0 + d / std::sqrt(d * d + h * h)); }

double aoNextToFiniteWall(double d, double h, double halfLength) {
  // Occluded fraction = the form factor from the floor point (normal +y) to the wall:
  // (1/pi) * integral over the wall of cos_point cos_wall / r^2 with cos_point = y / r and
  // cos_wall = d / r, i.e. (1/pi) int_{-L}^{L} int_0^h y d / (d^2 + z^2 + y^2)^2 dy dz.
  // Inner integral: d/2 [1/(d^2+z^2) - 1/(d^2+z^2+h^2)];
  // outer: int_{-L}^{L} dz / (a^2 + z^2) = 2 atan(L/a) / a. Closed form, no quadrature needed.
  double a2 = d * d, b2 = d * d + h * h;
  double I = 0.5 * d * (2.0 * std::atan(halfLength / std::sqrt(a2)) / std::sqrt(a2) -
                        2.0 * std::atan(halfLength / std::sqrt(b2)) / std::sqrt(b2));
  return 1.0 - I / kPiD;
}

// --- Sphere --------------------------------------------------------------------------------------
Scene floorAndSphere(float r, float H, int segments, int rings) {
  SceneBuilder b("floor-and-sphere");
  uint32_t floor = b.material("floor", glm::vec3(0.5f));
  uint32_t ball = b.material("sphere", glm::vec3(0.5f));
  float f = 10.0f * (r + H);
  b.quad({-f, 0, -f}, {f, 0, -f}, {f, 0, f}, {-f, 0, f}, floor, {0, 1, 0});
  glm::vec3 c(0.0f, H, 0.0f);
  auto at = [&](int i, int j) {  // ring i in 0..rings (pole to pole), segment j
    double th = kPiD * i / rings, ph = 2.0 * kPiD * j / segments;
    return c + r * glm::vec3(float(std::sin(th) * std::cos(ph)), float(std::cos(th)),
                             float(std::sin(th) * std::sin(ph)));
  };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      glm::vec3 p00 = at(i, j), p01 = at(i, j + 1), p10 = at(i + 1, j), p11 = at(i + 1, j + 1);
      glm::vec3 mid = 0.25f * (p00 + p01 + p10 + p11) - c;
      if (i != 0) b.triangle(p00, p10, p01, ball, mid);
      if (i != rings - 1) b.triangle(p01, p10, p11, ball, mid);
    }
  b.camera("overview", {0.0f, 0.5f * H, 4.0f * (r + H)}, {0, 0, -1}, {0, 1, 0}, 0.8f);
  return b.build();
}

double aoUnderSphere(double r, double H) { return 1.0 - (r / H) * (r / H); }

// --- Rectangle emitter ---------------------------------------------------------------------------
Scene rectEmitterOverFloor(float x0, float x1, float z0, float z1, float c, glm::vec3 Le,
                           float floorAlbedo, float floorHalf) {
  SceneBuilder b("rect-emitter");
  uint32_t floor = b.material("floor", glm::vec3(floorAlbedo));
  uint32_t light = b.material("emitter", glm::vec3(0.0f), Le);
  float f = floorHalf;
  b.quad({-f, 0, -f}, {f, 0, -f}, {f, 0, f}, {-f, 0, f}, floor, {0, 1, 0});
  b.quad({x0, c, z0}, {x1, c, z0}, {x1, c, z1}, {x0, c, z1}, light, {0, -1, 0});
  b.camera("overview", {0.0f, 0.5f * c, 4.0f * c}, {0, -0.2f, -1}, {0, 1, 0}, 1.0f);
  return b.build();
}

double cornerFormFactor(double a, double b, double c) {
  if (a <= 0.0 || b <= 0.0) return 0.0;
  double X = a / c, Y = b / c;
  double sx = std::sqrt(1.0 + X * X), sy = std::sqrt(1.0 + Y * Y);
  return (X / sx * std::atan(Y / sx) + Y / sy * std::atan(X / sy)) / (2.0 * kPiD);
}

double formFactorUnderRectangle(double px, double pz, double x0, double x1, double z0, double z1,
                                double c) {
  if (px < x0 || px > x1 || pz < z0 || pz > z1)
    throw Error("formFactorUnderRectangle: the point must lie under the rectangle");
  return cornerFormFactor(px - x0, pz - z0, c) + cornerFormFactor(x1 - px, pz - z0, c) +
         cornerFormFactor(px - x0, z1 - pz, c) + cornerFormFactor(x1 - px, z1 - pz, c);
}

}  // namespace voxlab::reference::analytic
