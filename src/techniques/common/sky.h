// The constant sky: an optional environment radiance L (W/(m^2 sr), grey) for open scenes; by
// default the scene's own (glTF scene extras sky_radiance, 0 when absent, as the closed Cornell
// box has). Every ray or cone that escapes (shaders/common/
// sky.glsl says when) sees L through the transmittance it has left; the reference path tracer's escaping rays see the
// same L (reference::ReferenceTracer::setSkyRadiance, `voxlab reference --sky L`), so an albedo-1
// object under it has radiance L everywhere (the sky furnace, tests/unit/test_sky.cpp).
//
// The mechanism, the same for every technique: a stage that traces cones or rays out of the
// volume, or composites the camera image, calls declareSky(builder) in its declare() and
// setSkyUniforms(program, params, scene) before it dispatches; its shader includes
// shaders/common/sky.glsl, which holds the escape rule and the background (written once). A technique has the sky when one
// of its stages declares sky.radiance (`voxlab list`); nothing names a technique.
#pragma once
#include "gpu/gl.h"
#include "graph/param.h"
#include "graph/stage.h"
#include "scene/scene.h"

namespace voxlab {

inline constexpr const char* kSkyRadiance = "sky.radiance";
ParamDesc skyRadianceParam();
void declareSky(StageBuilder& b);                           // b.param(skyRadianceParam())
// The sky radiance a run uses: the parameter, or the scene's own (Scene::skyRadiance) at "scene".
float skyRadianceOf(const ParamSet& params, const Scene& scene);
// u_skyRadiance = (L, L, L) and the scene bounds beyond which a ray escapes (shaders/common/sky.glsl).
void setSkyUniforms(GLuint program, const ParamSet& params, const Scene& scene);

}  // namespace voxlab
