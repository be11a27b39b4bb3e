#include "techniques/common/sky.h"

#include <glm/glm.hpp>

#include "gpu/shader_library.h"

namespace voxlab {

ParamDesc skyRadianceParam() {
  return ParamDesc::real(kSkyRadiance, 0.0, 0.0, 1000.0,
                         "constant sky radiance seen by every cone or ray that leaves the voxel volume, through "
                         "its remaining transmittance (0: no sky, a closed scene)",
                         "W/(m^2 sr)")
      .groundTruth();
}

void declareSky(StageBuilder& b) { b.param(skyRadianceParam()); }

void setSkyUniforms(GLuint program, const ParamSet& params, const Scene& scene) {
  setUniform(program, "u_skyRadiance", glm::vec3(params.getFloat(kSkyRadiance)));
  setUniform(program, "u_skySceneMin", scene.bounds.min);
  setUniform(program, "u_skySceneMax", scene.bounds.max);
}

}  // namespace voxlab
