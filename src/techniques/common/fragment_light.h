// The direct light voxel fragments carry into the voxels, shared by vct-grid's inject and svo's
// leaves (shaders/common/fragment_light.glsl): its parameters and uniforms.
#pragma once
#include <string>

#include "gpu/gl.h"
#include "graph/stage.h"
#include "techniques/common/voxel_space.h"

namespace voxlab {

// inject.mode, inject.uniform-radiance, inject.shadow-offset; and the read of the scene's lights
// that fragmentLightDefines needs.
void declareFragmentLightParams(StageBuilder& b);
// The defines of a program that includes common/fragment_light.glsl: built for the type of the
// scene's light (lightKindDefines).
std::string fragmentLightDefines(const Scene& scene);
// u_mode, u_uniformRadiance, u_shadowOffset (metres: inject.shadow-offset voxels of 'space').
void setFragmentLightUniforms(GLuint program, const ParamSet& params, const VoxelSpace& space);

}  // namespace voxlab
