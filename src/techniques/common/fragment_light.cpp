// The direct light of voxel fragments (fragment_light.h).
#include "techniques/common/fragment_light.h"

#include "gpu/shader_library.h"
#include "graph/scene_inputs.h"

namespace voxlab {

void declareFragmentLightParams(StageBuilder& b) {
  b.param(ParamDesc::choice("inject.mode", {"direct-light", "uniform"}, 0,
                            "what voxels hold: the scene's direct light, or one uniform radiance (a furnace test)"));
  b.param(ParamDesc::real("inject.uniform-radiance", 0.5, 0.0, 1.0,
                          "radiance every voxel gets in uniform mode", "W/(m^2 sr)"));
  b.param(ParamDesc::real("inject.shadow-offset", 0.5, 0.0, 2.0,
                          "the shadow map is read this far from the voxel centre along the fragment's normal: an "
                          "axis-aligned surface passes up to half a voxel from the centre, and a centre behind the "
                          "surface is shadowed by the surface itself (0 = at the centre)",
                          "voxels"));
  b.read(kSceneLightsInput);  // the light's type (lightKindDefines)
}

void setFragmentLightUniforms(GLuint program, const ParamSet& p, const VoxelSpace& space) {
  setUniform(program, "u_mode", p.getInt("inject.mode"));
  setUniform(program, "u_uniformRadiance", glm::vec3(p.getFloat("inject.uniform-radiance")));
  setUniform(program, "u_shadowOffset", p.getFloat("inject.shadow-offset") * space.voxelSize);
}

}  // namespace voxlab
