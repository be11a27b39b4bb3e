// The cone-trace set-up shared by the cone-tracing stages (vct-grid, svo, clipmap): the
// parameters of the cone table and the distances, with one set of names and ranges and
// per-technique defaults (ConeDefaults), so techniques trace the same cones for the same
// settings; the uniforms of shaders/common/cone_setup.glsl (plus the tracer's u_stepScale,
// u_lodBias, u_maxSteps); and the probed pixel's cone-samples output (lrsm's too).
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gpu/gl.h"
#include "graph/stage.h"
#include "techniques/common/voxel_space.h"

namespace voxlab {

// What differs between techniques: defaults, the largest distances and the wording (clipmap
// measures distances in its coarsest level's edge, the others in the volume's edge).
// The defaults are those of cones in one voxel volume (vct-grid, svo: 45-degree cones that
// may run past the volume's diagonal); a technique with other units (clipmap) overrides them.
struct ConeDefaults {
  int count = 6;           // diffuse cones
  double aperture = 45.0;  // degrees, full angle
  std::string apertureHelp = "full opening angle of each diffuse cone (ring layout: the outer cones are tilted by as much; "
                             "at 60 their lower edges graze the surface, which then occludes and lights itself)";
  double startOffset = 1.75;  // voxels: about a voxel diagonal
  std::string startOffsetHelp = "cones start this far from the surface along its normal (avoids self-occlusion)";
  std::string lodBiasHelp = "mip level = log2(diameter / voxel) + bias; -1 makes the filter support equal the diameter";
  double maxDistance = 1.75, maxDistanceLimit = 2.0;  // fractions of the distance unit
  std::string maxDistanceHelp = "longest cone, as a fraction of the volume edge (1.75: past the diagonal, so a cone can "
                                "reach any wall; cones also stop where they leave the volume)";
  double aoRange = 0.25, aoRangeLimit = 2.0;
  std::string aoRangeHelp = "ambient occlusion counts occluders up to this distance, as a fraction of the volume edge";
  bool softShadowCone = true;  // declares shadow.cone-aperture
};

// cone.count, cone.aperture, cone.layout, cone.weighting, cone.start-offset, cone.step,
// cone.lod-bias, cone.max-distance, ao.range, specular.roughness, shadow.cone-aperture (when
// defaults.softShadowCone), probe.x, probe.y and the screen probe on probe.x / probe.y.
void declareConeParams(StageBuilder& b, const ConeDefaults& defaults);

// The diffuse cone table of the parameters: tangent-space direction (z = normal), weight.
std::vector<glm::vec4> diffuseConeTable(const ParamSet& params);

// Sets every uniform of cone_setup.glsl and the step uniforms on 'program' ('traced': the traced
// image's size, 'scale': G-buffer pixels per traced pixel). cone.start-offset is multiplied by
// 'startOffsetUnit', cone.max-distance and ao.range by 'distanceUnit'. Returns the probed pixel of
// the traced image (x, GL row from the bottom).
glm::ivec2 setConeUniforms(GLuint program, const ParamSet& params, const ViewState& view, float startOffsetUnit,
                           float distanceUnit, glm::ivec2 traced, int scale);
// The same in a voxel volume: start offset in its voxels, distances in its edge.
glm::ivec2 setConeUniforms(GLuint program, const ParamSet& params, const ViewState& view, const VoxelSpace& space,
                           glm::ivec2 traced, int scale);

// Bytes of the "cone-samples" buffer: VOXLAB_MAX_CONES x VOXLAB_MAX_SAMPLES_PER_CONE records.
size_t coneSamplesBytes();
// Declares the probe record "cone-samples" (gpu::ConeSample records: position, accumulated,
// info; counted by "cone-samples.count", which the stage writes) and both buffers. 'help' says
// what the records hold in this technique.
OutputDesc& coneSamplesOutput(StageBuilder& b, const std::string& help);

}  // namespace voxlab
