// The direct light voxel fragments carry into the voxels, shared by vct-grid's inject and svo's
// leaves (shaders/common/fragment_light.glsl): its parameters and uniforms.
#pragma once
#include "gpu/gl.h"
#include "graph/stage.h"
#include "techniques/common/voxel_space.h"

namespace voxlab {

// inject.mode, inject.uniform-radiance, inject.shadow-offset; and the read of the scene's lights,
// as a program that includes common/fragment_light.glsl is built for the light's type
// (lightKindDefines, techniques/common/light_stage.h).
void declareFragmentLightParams(StageBuilder& b);
// u_mode, u_uniformRadiance, u_shadowOffset (metres: inject.shadow-offset voxels of 'space').
void setFragmentLightUniforms(GLuint program, const ParamSet& params, const VoxelSpace& space);

}  // namespace voxlab
