// Scene helpers that do not depend on the glTF parser: cameras, draw-range lookups and the
// mapping from a scene name ("cornell-box") to a file in scenes/.
#include "scene/scene.h"
#include "scene/animation.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <glm/gtc/matrix_transform.hpp>

#include "core/error.h"
#include "core/paths.h"

namespace voxlab {

glm::mat4 Camera::view() const { return glm::lookAtRH(position, position + forward, up); }

glm::mat4 Camera::projection(float aspect) const {
  // Right-handed eye space looking down -z, GL clip space with depth in -1..1.
  return glm::perspectiveRH_NO(yfov, aspect > 0.0f ? aspect : 1.0f, znear, zfar);
}

glm::vec3 sunDirection(float azimuthDeg, float elevationDeg) {
  float az = glm::radians(azimuthDeg), el = glm::radians(elevationDeg);
  // cos(el) >= 0 for el in -90..90; in float cos(radians(90)) is -4e-8, which would turn the azimuth by 180.
  float horizontal = std::max(std::cos(el), 0.0f);
  return -glm::vec3(horizontal * std::sin(az), std::sin(el), horizontal * std::cos(az));
}

void sunAngles(const glm::vec3& direction, float& azimuthDeg, float& elevationDeg) {
  glm::vec3 toSun = -glm::normalize(direction);
  elevationDeg = glm::degrees(std::asin(std::clamp(toSun.y, -1.0f, 1.0f)));
  float az = glm::degrees(std::atan2(toSun.x, toSun.z));
  azimuthDeg = az < 0.0f ? az + 360.0f : az;
}

Light defaultSun() {
  Light l;
  l.name = kDefaultSunName;
  l.type = LightType::Directional;
  l.direction = sunDirection(30.0f, 60.0f);
  l.color = glm::vec3(1.0f);
  l.intensity = 5.0f;
  return l;
}

Camera frameBounds(const Bounds& bounds, float yfov) {
  Camera cam;
  cam.name = "framing-camera";
  cam.yfov = yfov;
  glm::vec3 center = bounds.valid() ? bounds.center() : glm::vec3(0.0f);
  float radius = bounds.valid() ? 0.5f * glm::length(bounds.extent()) : 1.0f;
  radius = std::max(radius, 1e-3f);
  // Distance at which the bounding sphere fits the vertical field of view.
  float distance = radius / std::sin(0.5f * std::clamp(yfov, 0.01f, 3.0f));
  cam.position = center + glm::vec3(0.0f, 0.0f, distance);
  cam.forward = glm::vec3(0.0f, 0.0f, -1.0f);
  cam.up = glm::vec3(0.0f, 1.0f, 0.0f);
  cam.znear = std::max(1e-3f * radius, 0.5f * (distance - radius));  // relative: any unit
  cam.zfar = std::max(cam.znear * 10.0f, distance + 4.0f * radius);
  return cam;
}

bool Scene::triangleMoves(size_t triangle) const {
  const uint32_t v = indices[triangle * 3];
  for (const VertexRange& r : movingVertices)
    if (v >= r.first && v - r.first < r.count) return true;
  return false;
}

size_t Scene::movingTriangleCount() const {
  if (movingVertices.empty()) return 0;
  size_t moving = 0;
  for (size_t t = 0; t < triangleCount(); ++t) moving += triangleMoves(t) ? 1 : 0;
  return moving;
}

uint32_t Scene::triangleMaterial(size_t triangle) const {
  // Draw ranges are sorted by firstIndex and contiguous; binary search the containing one.
  size_t first = triangle * 3;
  auto it = std::upper_bound(draws.begin(), draws.end(), first,
                             [](size_t f, const DrawRange& d) { return f < d.firstIndex; });
  if (it == draws.begin()) return 0;
  --it;
  if (first < size_t(it->firstIndex) + it->indexCount) return it->material;
  return 0;
}

namespace {

bool hasSceneExtension(const std::filesystem::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".gltf" || ext == ".glb";
}

}  // namespace

std::vector<std::string> listScenes() {
  std::vector<std::string> names;
  std::error_code ec;
  std::filesystem::directory_iterator it(projectPath("scenes"), ec), end;
  for (; !ec && it != end; it.increment(ec)) {
    if (it->is_directory(ec)) {
      // A scene with its own files: scenes/<name>/<name>.gltf (or .glb).
      std::string name = it->path().filename().string();
      for (const char* ext : {".gltf", ".glb"})
        if (fileExists((it->path() / (name + ext)).string())) {
          names.push_back(name);
          break;
        }
      continue;
    }
    if (!it->is_regular_file(ec)) continue;
    if (hasSceneExtension(it->path())) names.push_back(it->path().stem().string());
  }
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  return names;
}

std::string resolveScenePath(const std::string& nameOrPath) {
  if (nameOrPath.empty()) {
    throw Error("empty scene name; valid scene names: " + joinNames(listScenes()));
  }
  if (fileExists(nameOrPath)) return nameOrPath;
  const std::filesystem::path p(nameOrPath);
  bool looksLikeName = nameOrPath.find('/') == std::string::npos && !hasSceneExtension(p);
  if (looksLikeName) {
    for (const std::string& stem : {"scenes/" + nameOrPath, "scenes/" + nameOrPath + "/" + nameOrPath})
      for (const char* ext : {".gltf", ".glb"}) {
        std::string candidate = projectPath(stem + ext);
        if (fileExists(candidate)) return candidate;
      }
  } else if (nameOrPath.find('/') == std::string::npos) {
    // "cornell-box.gltf": a file name inside scenes/.
    std::string candidate = projectPath("scenes/" + nameOrPath);
    if (fileExists(candidate)) return candidate;
  } else if (p.is_relative()) {
    // "tests/data/scenes/thin-wall.gltf": a path relative to the project root (lessons name
    // scenes this way and are played from any working directory).
    std::string candidate = projectPath(nameOrPath);
    if (fileExists(candidate)) return candidate;
  }
  std::vector<std::string> names = listScenes();
  std::string valid = names.empty() ? std::string("(none found in ") + projectPath("scenes") + ")"
                                    : joinNames(names);
  if (looksLikeName) {
    throw Error("unknown scene '" + nameOrPath + "'; valid scene names: " + valid +
                " (or a path to a .gltf/.glb file)");
  }
  throw Error("scene file '" + nameOrPath + "' does not exist; valid scene names: " + valid);
}

}  // namespace voxlab

namespace voxlab {

namespace {

// Origin and -z / +y axes of a placement's world matrix: where a light or camera on it stands and looks.
struct NodeFrame {
  glm::vec3 origin, minusZ, plusY;
};
NodeFrame frameOf(const glm::mat4& world) {
  return {glm::vec3(world * glm::vec4(0, 0, 0, 1)), glm::mat3(world) * glm::vec3(0, 0, -1),
          glm::mat3(world) * glm::vec3(0, 1, 0)};
}

}  // namespace

ScenePoseChange poseScene(Scene& scene, const SceneAnimation& anim, float t) {
  ScenePoseChange change;
  if (!anim.animated()) return change;
  t = std::clamp(t, 0.0f, anim.duration);
  const std::vector<glm::mat4> world = anim.worldMatrices(t);
  for (const MovingVertices& m : anim.moving) {
    const glm::mat4& w = world[size_t(m.placement)];
    const glm::mat3 linear(w);
    const float det = glm::determinant(linear);
    const glm::mat3 normalMatrix = std::abs(det) > 1e-20f ? glm::transpose(glm::inverse(linear)) : glm::mat3(1.0f);
    for (uint32_t i = 0; i < m.count; ++i) {
      glm::vec3 p = glm::vec3(w * glm::vec4(m.localPositions[i], 1.0f));
      glm::vec3 n = normalMatrix * m.localNormals[i];
      const float len = glm::length(n);
      n = len > 1e-20f ? n / len : m.localNormals[i];
      // A position that is not finite (a degenerate key) keeps the last good one.
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
      glm::vec3& position = scene.positions[m.first + i];
      glm::vec3& normal = scene.normals[m.first + i];
      if (position != p || normal != n) change.geometry = true;
      position = p;
      normal = n;
    }
  }
  for (size_t l = 0; l < scene.lights.size() && l < anim.lightPlacement.size(); ++l) {
    const int p = anim.lightPlacement[l];
    if (p < 0 || !anim.placements[size_t(p)].moves) continue;
    const NodeFrame f = frameOf(world[size_t(p)]);
    Light& light = scene.lights[l];
    const glm::vec3 direction = glm::length(f.minusZ) > 0.0f ? glm::normalize(f.minusZ) : light.direction;
    if (light.position != f.origin || light.direction != direction) change.lights = true;
    light.position = f.origin;
    light.direction = direction;
  }
  for (size_t c = 0; c < scene.cameras.size() && c < anim.cameraPlacement.size(); ++c) {
    const int p = anim.cameraPlacement[c];
    if (p < 0 || !anim.placements[size_t(p)].moves) continue;
    const NodeFrame f = frameOf(world[size_t(p)]);
    if (glm::length(f.minusZ) <= 0.0f) continue;
    Camera& camera = scene.cameras[c];
    const glm::vec3 forward = glm::normalize(f.minusZ);
    glm::vec3 up = f.plusY - glm::dot(f.plusY, forward) * forward;
    up = glm::length(up) > 1e-12f ? glm::normalize(up) : camera.up;
    if (camera.position != f.origin || camera.forward != forward || camera.up != up) change.cameras = true;
    camera.position = f.origin;
    camera.forward = forward;
    camera.up = up;
  }
  return change;
}

}  // namespace voxlab
