// The constant sky: an optional environment radiance L (W/(m^2 sr), grey, 0 by default, which
// the closed Cornell box wants) for open scenes. Every ray or cone that leaves the voxel volume
// sees L through the transmittance it has left; the reference path tracer's escaping rays see the
// same L (reference::ReferenceTracer::setSkyRadiance, `voxlab reference --sky L`), so an albedo-1
// object under it has radiance L everywhere (the sky furnace, tests/unit/test_sky.cpp).
//
// A stage that traces out of the volume declares skyRadianceParam() and calls setSkyUniform on
// its program; shaders/common/cone_trace.glsl adds the escape term (u_skyRadiance).
#pragma once
#include "gpu/gl.h"
#include "graph/param.h"

namespace voxlab {

inline constexpr const char* kSkyRadiance = "sky.radiance";
ParamDesc skyRadianceParam();
void setSkyUniform(GLuint program, const ParamSet& params);  // u_skyRadiance = (L, L, L)

}  // namespace voxlab
