#version 450
// Anisotropic mipmapping (Crassin et al. 2011): six prefiltered volumes, one per direction a cone
// can travel (+x, -x, +y, -y, +z, -z), each texel the 2x2x2 block below it as that direction sees
// it (common/anisotropic_mip.glsl: pairs composited front to back along the axis, then averaged).
// Level 1 of the hierarchy is built from the isotropic level-0 voxels; higher levels from the
// direction's own previous level.
// The radiance grids' image format: rgba8 unless the stage builds the program with
// "#define VOXLAB_GRID_FORMAT rgba16f" (voxel.format=rgba16f).
#ifndef VOXLAB_GRID_FORMAT
#define VOXLAB_GRID_FORMAT rgba8
#endif
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(binding = 0) uniform sampler3D u_isotropic;  // level 0 voxels
// The directional volumes, read at u_sourceLevel (+x -x +y -y +z -z).
layout(binding = 1) uniform sampler3D u_dir0;
layout(binding = 2) uniform sampler3D u_dir1;
layout(binding = 3) uniform sampler3D u_dir2;
layout(binding = 4) uniform sampler3D u_dir3;
layout(binding = 5) uniform sampler3D u_dir4;
layout(binding = 6) uniform sampler3D u_dir5;
layout(VOXLAB_GRID_FORMAT, binding = 0) uniform writeonly image3D u_target0;
layout(VOXLAB_GRID_FORMAT, binding = 1) uniform writeonly image3D u_target1;
layout(VOXLAB_GRID_FORMAT, binding = 2) uniform writeonly image3D u_target2;
layout(VOXLAB_GRID_FORMAT, binding = 3) uniform writeonly image3D u_target3;
layout(VOXLAB_GRID_FORMAT, binding = 4) uniform writeonly image3D u_target4;
layout(VOXLAB_GRID_FORMAT, binding = 5) uniform writeonly image3D u_target5;
uniform int u_fromIsotropic;
uniform int u_sourceLevel;
#include "common/anisotropic_mip.glsl"

vec4 child(int direction, ivec3 v) {
  if (u_fromIsotropic != 0) return texelFetch(u_isotropic, v, 0);
  switch (direction) {
    case 0: return texelFetch(u_dir0, v, u_sourceLevel);
    case 1: return texelFetch(u_dir1, v, u_sourceLevel);
    case 2: return texelFetch(u_dir2, v, u_sourceLevel);
    case 3: return texelFetch(u_dir3, v, u_sourceLevel);
    case 4: return texelFetch(u_dir4, v, u_sourceLevel);
    default: return texelFetch(u_dir5, v, u_sourceLevel);
  }
}

// Direction d = 2 * axis + (0 for +, 1 for -).
vec4 reduce(int d, ivec3 base) {
  vec4 children[8];
  for (int k = 0; k < 8; ++k) children[k] = child(d, base + ivec3(k & 1, (k >> 1) & 1, k >> 2));
  return anisotropicReduce(children, d);
}

void main() {
  ivec3 v = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(v, imageSize(u_target0)))) return;
  ivec3 base = 2 * v;
  imageStore(u_target0, v, reduce(0, base));
  imageStore(u_target1, v, reduce(1, base));
  imageStore(u_target2, v, reduce(2, base));
  imageStore(u_target3, v, reduce(3, base));
  imageStore(u_target4, v, reduce(4, base));
  imageStore(u_target5, v, reduce(5, base));
}
