// The shared cone-trace set-up (cone_setup.h).
#include "techniques/common/cone_setup.h"

#include <algorithm>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "techniques/vct_grid/cone_layout.h"

namespace voxlab {

static constexpr float kRadiansPerDegree = 3.14159265358979f / 180.0f;

void declareConeParams(StageBuilder& b) {
  b.param(ParamDesc::integer("cone.count", 6, 1, VOXLAB_MAX_CONES, "number of diffuse cones", "cones"));
  b.param(ParamDesc::real("cone.aperture", 60.0, 5.0, 120.0, "full opening angle of each diffuse cone", "degrees"));
  b.param(ParamDesc::choice("cone.layout", {"ring", "fibonacci"}, 0,
                            "ring: one cone on the normal and the rest around it; fibonacci: a cosine-distributed spiral"));
  b.param(ParamDesc::choice("cone.weighting", {"cosine", "equal"}, 0,
                            "cone weights, normalised to sum to 1: proportional to the cosine of each cone's axis, or equal"));
  b.param(ParamDesc::real("cone.start-offset", 1.75, 0.0, 8.0,
                          "cones start this far from the surface along its normal (avoids self-occlusion)", "voxels"));
  b.param(ParamDesc::real("cone.step", 0.5, 0.1, 1.0, "step length as a fraction of the sample diameter"));
  b.param(ParamDesc::real("cone.lod-bias", -1.0, -2.0, 1.0,
                          "mip level = log2(diameter / voxel) + bias; -1 makes the filter support equal the diameter"));
  b.param(ParamDesc::real("cone.max-distance", 1.0, 0.05, 2.0, "longest cone, as a fraction of the volume edge"));
  b.param(ParamDesc::real("ao.range", 0.25, 0.01, 2.0,
                          "ambient occlusion counts occluders up to this distance, as a fraction of the volume edge"));
  b.param(ParamDesc::real("specular.roughness", 0.2, 0.0, 1.0,
                          "specular cone aperture = max(2, 90 * roughness) degrees"));
  b.param(ParamDesc::real("shadow.cone-aperture", 8.0, 1.0, 60.0, "opening angle of the soft-shadow cone", "degrees"));
  b.param(ParamDesc::real("probe.x", 0.5, 0.0, 1.0, "horizontal position of the probed pixel (0 left, 1 right)"));
  b.param(ParamDesc::real("probe.y", 0.5, 0.0, 1.0, "vertical position of the probed pixel (0 top, 1 bottom)"));
  b.probe(ProbeDesc::screen("probe.x", "probe.y"));
}

std::vector<glm::vec4> diffuseConeTable(const ParamSet& p) {
  std::vector<glm::vec4> table;
  for (const auto& c : vct::diffuseCones(p.getInt("cone.count"), p.getFloat("cone.aperture") * kRadiansPerDegree,
                                         p.getChoice("cone.layout"), p.getChoice("cone.weighting")))
    table.push_back(glm::vec4(c.direction, c.weight));
  return table;
}

glm::ivec2 setConeUniforms(GLuint program, const ParamSet& p, const ViewState& view, const VoxelSpace& space,
                           glm::ivec2 traced, int scale) {
  std::vector<glm::vec4> cones = diffuseConeTable(p);
  glProgramUniform4fv(program, glGetUniformLocation(program, "u_cones"), GLsizei(cones.size()), &cones[0].x);
  setUniform(program, "u_coneCount", int(cones.size()));
  setUniform(program, "u_diffuseAperture", p.getFloat("cone.aperture") * kRadiansPerDegree);
  setUniform(program, "u_specularAperture", std::max(2.0f, 90.0f * p.getFloat("specular.roughness")) * kRadiansPerDegree);
  setUniform(program, "u_shadowAperture", p.getFloat("shadow.cone-aperture") * kRadiansPerDegree);
  setUniform(program, "u_startOffset", p.getFloat("cone.start-offset") * space.voxelSize);
  setUniform(program, "u_stepScale", p.getFloat("cone.step"));
  setUniform(program, "u_lodBias", p.getFloat("cone.lod-bias"));
  setUniform(program, "u_maxSteps", 512);
  setUniform(program, "u_maxDistance", p.getFloat("cone.max-distance") * space.edge());
  setUniform(program, "u_aoRange", p.getFloat("ao.range") * space.edge());
  setUniform(program, "u_cameraPos", view.position);
  setUniform(program, "u_scale", scale);
  // probe.y counts from the top of the image; GL rows count from the bottom.
  glm::ivec2 probe(std::min(int(p.getFloat("probe.x") * traced.x), traced.x - 1),
                   std::min(int((1.0f - p.getFloat("probe.y")) * traced.y), traced.y - 1));
  glProgramUniform2i(program, glGetUniformLocation(program, "u_probePixel"), probe.x, probe.y);
  return probe;
}

}  // namespace voxlab
