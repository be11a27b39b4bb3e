#include "scene/animation.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace voxlab {

const char* animationPathName(AnimationPath path) {
  switch (path) {
    case AnimationPath::Translation: return "translation";
    case AnimationPath::Rotation: return "rotation";
    case AnimationPath::Scale: return "scale";
  }
  return "?";
}

const char* interpolationName(Interpolation interpolation) {
  switch (interpolation) {
    case Interpolation::Linear: return "LINEAR";
    case Interpolation::Step: return "STEP";
    case Interpolation::CubicSpline: return "CUBICSPLINE";
  }
  return "?";
}

namespace {

glm::vec4 unitQuaternion(glm::vec4 q) {
  const float len = glm::length(q);
  return len > 0.0f ? q / len : glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
}

// Spherical interpolation along the shorter arc between unit quaternions a and b (x, y, z, w).
glm::vec4 slerpShorter(glm::vec4 a, glm::vec4 b, float s) {
  float d = glm::dot(a, b);
  if (d < 0.0f) b = -b, d = -d;
  if (d > 0.9995f) return unitQuaternion(a + s * (b - a));  // nearly parallel: the chord is the arc
  const float angle = std::acos(std::min(d, 1.0f));
  const float sinAngle = std::sin(angle);
  return (std::sin((1.0f - s) * angle) / sinAngle) * a + (std::sin(s * angle) / sinAngle) * b;
}

glm::mat4 localMatrix(const NodeRest& rest, const glm::vec3& t, const glm::quat& r, const glm::vec3& s) {
  if (rest.hasMatrix) return rest.matrix;
  return glm::translate(glm::mat4(1.0f), t) * glm::mat4_cast(r) * glm::scale(glm::mat4(1.0f), s);
}

}  // namespace

glm::vec4 sampleAnimation(const AnimationSampler& sampler, AnimationPath path, float t) {
  const std::vector<float>& times = sampler.times;
  const bool cubic = sampler.interpolation == Interpolation::CubicSpline;
  auto value = [&](size_t key) { return sampler.values[cubic ? 3 * key + 1 : key]; };
  const bool rotation = path == AnimationPath::Rotation;
  auto finish = [&](glm::vec4 v) { return rotation ? unitQuaternion(v) : v; };
  if (times.empty()) return rotation ? glm::vec4(0, 0, 0, 1) : glm::vec4(0.0f);
  if (t <= times.front()) return finish(value(0));
  if (t >= times.back()) return finish(value(times.size() - 1));
  // The key interval [times[k], times[k + 1]) holding t.
  const size_t k = size_t(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
  const float dt = times[k + 1] - times[k];
  const float s = (t - times[k]) / dt;
  switch (sampler.interpolation) {
    case Interpolation::Step: return finish(value(k));
    case Interpolation::Linear:
      if (rotation) return slerpShorter(unitQuaternion(value(k)), unitQuaternion(value(k + 1)), s);
      return value(k) + s * (value(k + 1) - value(k));
    case Interpolation::CubicSpline: {
      // Hermite basis; the stored tangents are per second, so they are scaled by the interval.
      const float s2 = s * s, s3 = s2 * s;
      const glm::vec4 from = value(k), to = value(k + 1);
      const glm::vec4 outTangent = sampler.values[3 * k + 2], inTangent = sampler.values[3 * (k + 1)];
      return finish((2 * s3 - 3 * s2 + 1) * from + dt * (s3 - 2 * s2 + s) * outTangent + (-2 * s3 + 3 * s2) * to +
                    dt * (s3 - s2) * inTangent);
    }
  }
  return finish(value(k));
}

std::vector<glm::mat4> SceneAnimation::worldMatrices(float t) const {
  // Each node's local transform at t: its rest pose with the animated parts replaced.
  std::vector<glm::vec3> translation(nodes.size()), scale(nodes.size());
  std::vector<glm::quat> rotation(nodes.size());
  for (size_t n = 0; n < nodes.size(); ++n) {
    translation[n] = nodes[n].translation;
    rotation[n] = nodes[n].rotation;
    scale[n] = nodes[n].scale;
  }
  std::vector<bool> animatedNode(nodes.size(), false);
  for (const AnimationChannel& c : channels) {
    const glm::vec4 v = sampleAnimation(samplers[size_t(c.sampler)], c.path, t);
    const size_t n = size_t(c.node);
    animatedNode[n] = true;
    if (c.path == AnimationPath::Translation) translation[n] = glm::vec3(v);
    else if (c.path == AnimationPath::Scale) scale[n] = glm::vec3(v);
    else rotation[n] = glm::quat(v.w, v.x, v.y, v.z);
  }
  std::vector<glm::mat4> world(placements.size());
  for (size_t p = 0; p < placements.size(); ++p) {
    const size_t n = size_t(placements[p].node);
    NodeRest rest = nodes[n];
    // An animated node's TRS replaces its matrix (glTF forbids animating a node with a matrix).
    if (animatedNode[n]) rest.hasMatrix = false;
    const glm::mat4 local = localMatrix(rest, translation[n], rotation[n], scale[n]);
    world[p] = placements[p].parent >= 0 ? world[size_t(placements[p].parent)] * local : local;
  }
  return world;
}

}  // namespace voxlab
