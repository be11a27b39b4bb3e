#include "techniques/common/sky.h"

#include <glm/glm.hpp>

#include "gpu/shader_library.h"

namespace voxlab {

ParamDesc skyRadianceParam() {
  return ParamDesc::fromScene(kSkyRadiance, 0.0, 1000.0,
                              "constant sky radiance seen by every cone or ray that leaves the voxel volume, through "
                              "its remaining transmittance (0: no sky, a closed scene; scene: the scene's own, 0 "
                              "unless its glTF scene extras set sky_radiance)",
                              "W/(m^2 sr)")
      .groundTruth();
}

void declareSky(StageBuilder& b) { b.param(skyRadianceParam()); }

float skyRadianceOf(const ParamSet& params, const Scene& scene) {
  const double v = params.value(kSkyRadiance);
  return ParamDesc::isSceneValue(v) ? scene.skyRadiance : float(v);
}

void setSkyUniforms(GLuint program, const ParamSet& params, const Scene& scene) {
  setUniform(program, "u_skyRadiance", glm::vec3(skyRadianceOf(params, scene)));
  setUniform(program, "u_skySceneMin", scene.bounds.min);
  setUniform(program, "u_skySceneMax", scene.bounds.max);
}

}  // namespace voxlab
