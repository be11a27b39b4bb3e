// The shared cone-trace set-up (cone_setup.h).
#include "techniques/common/cone_setup.h"

#include <algorithm>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "techniques/common/cone_layout.h"

namespace voxlab {

static constexpr float kRadiansPerDegree = 3.14159265358979f / 180.0f;

void declareConeParams(StageBuilder& b, const ConeDefaults& d) {
  b.param(ParamDesc::integer("cone.count", d.count, 1, VOXLAB_MAX_CONES, "number of diffuse cones", "cones"));
  b.param(ParamDesc::real("cone.aperture", d.aperture, 5.0, 120.0, d.apertureHelp, "degrees"));
  b.param(ParamDesc::choice("cone.layout", {"ring", "fibonacci"}, 0,
                            "ring: one cone on the normal and the rest around it; fibonacci: a cosine-distributed spiral"));
  b.param(ParamDesc::choice("cone.weighting", {"cosine", "equal"}, 0,
                            "cone weights, normalised to sum to 1: proportional to the cosine of each cone's axis, or equal"));
  b.param(ParamDesc::real("cone.start-offset", d.startOffset, 0.0, 8.0, d.startOffsetHelp, "voxels"));
  b.param(ParamDesc::real("cone.step", 0.5, 0.1, 1.0, "step length as a fraction of the sample diameter"));
  b.param(ParamDesc::real("cone.lod-bias", -1.0, -2.0, 1.0, d.lodBiasHelp));
  b.param(ParamDesc::real("cone.max-distance", d.maxDistance, 0.05, d.maxDistanceLimit, d.maxDistanceHelp));
  b.param(ParamDesc::real("ao.range", d.aoRange, 0.01, d.aoRangeLimit, d.aoRangeHelp));
  b.param(ParamDesc::real("specular.roughness", 0.2, 0.0, 1.0,
                          "specular cone aperture = max(2, 90 * roughness) degrees"));
  if (d.softShadowCone)
    b.param(ParamDesc::real("shadow.cone-aperture", 8.0, 1.0, 60.0, "opening angle of the soft-shadow cone", "degrees"));
  b.param(ParamDesc::real("probe.x", 0.5, 0.0, 1.0, "horizontal position of the probed pixel (0 left, 1 right)"));
  b.param(ParamDesc::real("probe.y", 0.5, 0.0, 1.0, "vertical position of the probed pixel (0 top, 1 bottom)"));
  b.probe(ProbeDesc::screen("probe.x", "probe.y"));
}

std::vector<glm::vec4> diffuseConeTable(const ParamSet& p) {
  std::vector<glm::vec4> table;
  for (const auto& c : diffuseCones(p.getInt("cone.count"), p.getFloat("cone.aperture") * kRadiansPerDegree,
                                         p.getChoice("cone.layout"), p.getChoice("cone.weighting")))
    table.push_back(glm::vec4(c.direction, c.weight));
  return table;
}

glm::ivec2 setConeUniforms(GLuint program, const ParamSet& p, const ViewState& view, float startOffsetUnit,
                           float distanceUnit, glm::ivec2 traced, int scale) {
  std::vector<glm::vec4> cones = diffuseConeTable(p);
  glProgramUniform4fv(program, glGetUniformLocation(program, "u_cones"), GLsizei(cones.size()), &cones[0].x);
  setUniform(program, "u_coneCount", int(cones.size()));
  setUniform(program, "u_diffuseAperture", p.getFloat("cone.aperture") * kRadiansPerDegree);
  setUniform(program, "u_specularAperture", std::max(2.0f, 90.0f * p.getFloat("specular.roughness")) * kRadiansPerDegree);
  if (p.has("shadow.cone-aperture"))
    setUniform(program, "u_shadowAperture", p.getFloat("shadow.cone-aperture") * kRadiansPerDegree);
  setUniform(program, "u_startOffset", p.getFloat("cone.start-offset") * startOffsetUnit);
  setUniform(program, "u_stepScale", p.getFloat("cone.step"));
  setUniform(program, "u_lodBias", p.getFloat("cone.lod-bias"));
  setUniform(program, "u_maxSteps", 512);
  setUniform(program, "u_maxDistance", p.getFloat("cone.max-distance") * distanceUnit);
  setUniform(program, "u_aoRange", p.getFloat("ao.range") * distanceUnit);
  setUniform(program, "u_cameraPos", view.position);
  setUniform(program, "u_scale", scale);
  // probe.y counts from the top of the image; GL rows count from the bottom.
  glm::ivec2 probe(std::min(int(p.getFloat("probe.x") * traced.x), traced.x - 1),
                   std::min(int((1.0f - p.getFloat("probe.y")) * traced.y), traced.y - 1));
  glProgramUniform2i(program, glGetUniformLocation(program, "u_probePixel"), probe.x, probe.y);
  return probe;
}

glm::ivec2 setConeUniforms(GLuint program, const ParamSet& p, const ViewState& view, const VoxelSpace& space,
                           glm::ivec2 traced, int scale) {
  return setConeUniforms(program, p, view, space.voxelSize, space.edge(), traced, scale);
}

size_t coneSamplesBytes() { return sizeof(gpu::ConeSample) * VOXLAB_MAX_CONES * VOXLAB_MAX_SAMPLES_PER_CONE; }

OutputDesc& coneSamplesOutput(StageBuilder& b, const std::string& help) {
  b.write("cone-samples.count");
  BufferLayout samples;
  samples.stride = sizeof(gpu::ConeSample);
  samples.fields = {{"position", FieldType::Vec4, 0, FieldRole::Position},
                    {"accumulated", FieldType::Vec4, 16, FieldRole::Color},
                    {"info", FieldType::Vec4, 32, FieldRole::Other}};
  samples.countResource = "cone-samples.count";
  OutputDesc& probed = b.output("cone-samples", OutputKind::Buffer, Semantic::ConeSamples, help);
  probed.alongside = true;  // a probe record of one pixel
  probed.layout = samples;
  probed.probeRecord = true;  // the records of the pixel the screen probe points at
  b.buffer("cone-samples", [](const ParamSet&, const ViewState&) { return coneSamplesBytes(); });
  b.buffer("cone-samples.count", [](const ParamSet&, const ViewState&) { return size_t(4); });
  return probed;
}

}  // namespace voxlab
