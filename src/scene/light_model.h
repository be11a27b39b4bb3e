// The one model of punctual lights that every renderer in voxlab uses (GPU techniques through
// shaders/common/lights.glsl, the CPU reference path tracer through this header).
//
// Irradiance on a surface with unit normal n at point p from light L:
//   point/spot:   E = I * color * spot(p) * window(d) * max(dot(n, l), 0) / d^2
//   directional:  E = I * color * max(dot(n, -L.direction), 0)
// with l the unit vector from p to the light and d the distance. spot() is the smooth falloff the
// KHR_lights_punctual extension recommends: t = clamp((cos(a) - cos(outer)) / (cos(inner) -
// cos(outer)), 0, 1), spot = t*t, a the angle between L.direction and -l. window() is 1 for an
// infinite range, else clamp(1 - (d/range)^4, 0, 1)^2 (the extension's recommendation).
// Outgoing Lambertian radiance is albedo / pi * E.
#pragma once
#include <algorithm>
#include <cmath>

#include "scene/scene.h"

namespace voxlab {

struct LightSample {
  glm::vec3 toLight{0.0f};  // unit vector from the shaded point toward the light
  float distance = 0.0f;    // to the light; infinity for directional lights
  glm::vec3 irradianceAtNormalIncidence{0.0f};  // E for a surface facing the light
};

inline LightSample sampleLight(const Light& light, const glm::vec3& p) {
  LightSample s;
  if (light.type == LightType::Directional) {
    s.toLight = -light.direction;
    s.distance = INFINITY;
    s.irradianceAtNormalIncidence = light.color * light.intensity;
    return s;
  }
  glm::vec3 d = light.position - p;
  float dist2 = std::max(glm::dot(d, d), 1e-8f);
  s.distance = std::sqrt(dist2);
  s.toLight = d / s.distance;
  float falloff = 1.0f / dist2;
  if (light.range > 0.0f) {
    float r = s.distance / light.range;
    float w = std::clamp(1.0f - r * r * r * r, 0.0f, 1.0f);
    falloff *= w * w;
  }
  if (light.type == LightType::Spot) {
    float cosOuter = std::cos(light.outerConeAngle);
    float cosInner = std::cos(light.innerConeAngle);
    float cosA = glm::dot(light.direction, -s.toLight);
    float t = std::clamp((cosA - cosOuter) / std::max(cosInner - cosOuter, 1e-4f), 0.0f, 1.0f);
    falloff *= t * t;
  }
  s.irradianceAtNormalIncidence = light.color * light.intensity * falloff;
  return s;
}

}  // namespace voxlab
