#include "techniques/common/sky.h"

#include <glm/glm.hpp>

#include "gpu/shader_library.h"

namespace voxlab {

ParamDesc skyRadianceParam() {
  return ParamDesc::real(kSkyRadiance, 0.0, 0.0, 1000.0,
                         "constant sky radiance seen by every cone or ray that leaves the voxel volume, through "
                         "its remaining transmittance (0: no sky, a closed scene)",
                         "W/(m^2 sr)");
}

void setSkyUniform(GLuint program, const ParamSet& params) {
  setUniform(program, "u_skyRadiance", glm::vec3(params.getFloat(kSkyRadiance)));
}

}  // namespace voxlab
