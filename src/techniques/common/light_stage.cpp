#include "techniques/common/light_stage.h"
#include "graph/scene_inputs.h"

#include <cmath>
#include <cstring>

namespace voxlab {

namespace {
constexpr const char* kResource = "light-source";

// Sets 'target' from the parameter unless it is "scene".
void override(const ParamSet& params, const char* name, float& target) {
  double v = params.value(name);
  if (!ParamDesc::isSceneValue(v)) target = float(v);
}
}  // namespace

Light applyLightParams(const Light& sceneLight, const ParamSet& params) {
  Light l = sceneLight;
  float az = 0.0f, el = 0.0f;
  sunAngles(l.direction, az, el);
  override(params, kLightAzimuth, az);
  override(params, kLightElevation, el);
  if (!ParamDesc::isSceneValue(params.value(kLightAzimuth)) || !ParamDesc::isSceneValue(params.value(kLightElevation)))
    l.direction = sunDirection(az, el);
  override(params, "light.0.x", l.position.x);
  override(params, "light.0.y", l.position.y);
  override(params, "light.0.z", l.position.z);
  override(params, "light.0.red", l.color.x);
  override(params, "light.0.green", l.color.y);
  override(params, "light.0.blue", l.color.z);
  override(params, "light.0.intensity", l.intensity);
  float inner = glm::degrees(l.innerConeAngle), outer = glm::degrees(l.outerConeAngle);
  override(params, "light.0.inner-cone", inner);
  override(params, "light.0.outer-cone", outer);
  l.innerConeAngle = glm::radians(std::min(inner, outer));
  l.outerConeAngle = glm::radians(outer);
  return l;
}

Light lightSource(Blackboard& board) {
  LightSourceRecord r;
  auto bytes = board.buffer(kResource).download(sizeof(r));
  std::memcpy(&r, bytes.data(), sizeof(r));
  Light l;
  l.type = LightType(r.type);
  l.intensity = r.intensity;
  l.range = r.range;
  l.innerConeAngle = r.innerConeAngle;
  l.outerConeAngle = r.outerConeAngle;
  l.position = glm::vec3(r.position[0], r.position[1], r.position[2]);
  l.direction = glm::vec3(r.direction[0], r.direction[1], r.direction[2]);
  l.color = glm::vec3(r.color[0], r.color[1], r.color[2]);
  return l;
}

std::string lightKindDefines(const Scene& scene) {
  const Light l = scene.lights.empty() ? defaultSun() : scene.lights[0];  // as LightStage takes it
  const char* value = l.type == LightType::Point ? "VOXLAB_LIGHT_POINT"
                      : l.type == LightType::Spot ? "VOXLAB_LIGHT_SPOT" : "VOXLAB_LIGHT_DIRECTIONAL";
  return std::string("#define VOXLAB_LIGHT_KIND ") + value + "\n";
}

void LightStage::declare(StageBuilder& b) const {
  b.read(kSceneLightsInput);  // the scene's first light, before the light.0.* parameters
  const char* scene = "";  // "scene" (the default) is named by rangeText
  b.param(ParamDesc::fromScene(kLightAzimuth, 0.0, 360.0,
                               std::string("direction the light comes from, about +y from +z toward +x (sun, spot)") + scene, "degrees").groundTruth());
  b.param(ParamDesc::fromScene(kLightElevation, -90.0, 90.0,
                               std::string("height of the light above the horizontal plane (sun, spot)") + scene, "degrees").groundTruth());
  for (const char* axis : {"x", "y", "z"})
    b.param(ParamDesc::fromScene(std::string("light.0.") + axis, -1e6, 1e6,
                                 std::string("position of a point or spot light, ") + axis + scene, "scene units").groundTruth());
  for (const char* c : {"red", "green", "blue"})
    b.param(ParamDesc::fromScene(std::string("light.0.") + c, 0.0, 10.0, std::string("linear colour, ") + c + scene).groundTruth());
  b.param(ParamDesc::fromScene("light.0.intensity", 0.0, 1e6,
                               std::string("irradiance of a sun (W/m^2), intensity of a point or spot light (W/sr)") + scene).groundTruth());
  b.param(ParamDesc::fromScene("light.0.inner-cone", 0.0, 90.0, std::string("spot: full intensity inside this angle") + scene, "degrees").groundTruth());
  b.param(ParamDesc::fromScene("light.0.outer-cone", 0.0, 90.0, std::string("spot: no light outside this angle") + scene, "degrees").groundTruth());
  b.write(kResource);
}

void LightStage::execute(StageContext& ctx) {
  // The loader gives every scene a light (a default sun when the file has none).
  Light l = ctx.scene.lights.empty() ? defaultSun() : ctx.scene.lights[0];
  l = applyLightParams(l, ctx.params);
  LightSourceRecord r;
  r.type = int32_t(l.type);
  r.intensity = l.intensity;
  r.range = l.range;
  r.innerConeAngle = l.innerConeAngle;
  r.outerConeAngle = l.outerConeAngle;
  glm::vec3 dir = glm::length(l.direction) > 0.0f ? glm::normalize(l.direction) : glm::vec3(0, -1, 0);
  for (int k = 0; k < 3; ++k) {
    r.position[k] = l.position[k];
    r.direction[k] = dir[k];
    r.color[k] = l.color[k];
  }
  ctx.board.ensureBuffer(kResource, sizeof(r)).upload(&r, sizeof(r));
  float az = 0, el = 0;
  sunAngles(dir, az, el);
  ctx.stats["azimuth_deg"] = az;
  ctx.stats["elevation_deg"] = el;
  ctx.stats["intensity"] = l.intensity;
  ctx.stats["type"] = double(r.type);  // 0 directional, 1 point, 2 spot (LightType)
  ctx.stats["default_sun"] = l.name == kDefaultSunName ? 1 : 0;
}

}  // namespace voxlab
