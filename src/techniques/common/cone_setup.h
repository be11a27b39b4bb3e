// The cone-trace set-up shared by the cone-tracing stages (svo's uses it; vct-grid's cone-trace
// declares and sets the same parameters and uniforms itself and can switch to these): the
// parameters of the cone table and the distances, with vct-grid's names, defaults and ranges, so
// techniques trace the same cones for the same settings, and the uniforms of
// shaders/common/cone_setup.glsl (plus the tracer's u_stepScale, u_lodBias, u_maxSteps).
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "gpu/gl.h"
#include "graph/stage.h"
#include "techniques/common/voxel_space.h"

namespace voxlab {

// cone.count, cone.aperture, cone.layout, cone.weighting, cone.start-offset, cone.step,
// cone.lod-bias, cone.max-distance, ao.range, specular.roughness, shadow.cone-aperture, probe.x,
// probe.y and the screen probe on probe.x / probe.y.
void declareConeParams(StageBuilder& b);

// The diffuse cone table of the parameters: tangent-space direction (z = normal), weight.
std::vector<glm::vec4> diffuseConeTable(const ParamSet& params);

// Sets every uniform of cone_setup.glsl and the step uniforms on 'program' ('traced': the traced
// image's size, 'scale': G-buffer pixels per traced pixel). Returns the probed pixel of the
// traced image (x, GL row from the bottom).
glm::ivec2 setConeUniforms(GLuint program, const ParamSet& params, const ViewState& view, const VoxelSpace& space,
                           glm::ivec2 traced, int scale);

}  // namespace voxlab
