#version 450
// The covered block of level k (k >= 1) from its children at level k-1: face 0 (isotropic) is
// the mean of the 8 premultiplied children; with six faces, face +x composites each pair of
// children along x front to back for a cone travelling +x (near + (1 - near.a) far, the "under"
// operator of seed 004 section 2-3-2) and averages the four pairs; the other faces likewise
// (common/anisotropic_mip.glsl, the reduction of vct-grid's directional volumes: the faces hold
// the fronts each direction sees, resolve.comp.glsl).
// Children are read at their toroidal addresses: nothing depends on where the seam lies.
#include "clipmap/clipmap.glsl"
#include "common/anisotropic_mip.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(std430, binding = CLIPMAP_BINDING_COUNTERS) buffer Counters { uint counters[]; };
layout(CLIPMAP_ATLAS_FORMAT, binding = 0) uniform image3D u_atlas;
// The finer level's filled cells (clipmap.fill-unreached), one word per physical texel (1: filled).
layout(std430, binding = CLIPMAP_BINDING_FILLED) readonly buffer Filled { uint filled[]; };
uniform ivec3 u_boxLo;
uniform ivec3 u_boxSize;
uniform int u_level;
uniform int u_faces;
uniform int u_readFilled;  // 1: the finer level has filled cells (Filled is bound)

bool childFilled(ivec3 phys) {
  return u_readFilled != 0 && filled[(phys.z * u_clipN + phys.y) * u_clipN + phys.x] != 0u;
}

void main() {
  ivec3 g = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(g, u_boxSize))) return;
  ivec3 cell = u_boxLo + g;
  ivec3 phys = toroidalAddress(cell);
  // A cell that holds a surface of the finer level takes its surfaces only, not the filled space
  // behind them: the filled cells would show a cone leaving the surface its own light, which the
  // finer level keeps a layer of empty cells away from it (src/techniques/clipmap/unreached_cells.h).
  bool dropFilled = false;
  bool isFilled[8];
  for (int i = 0; i < 8; ++i) {
    ivec3 c = toroidalAddress(2 * cell + ivec3(i & 1, (i >> 1) & 1, i >> 2));
    isFilled[i] = childFilled(c);
    if (!isFilled[i] && imageLoad(u_atlas, atlasTexel(0, u_level - 1, c)).a > 0.0) dropFilled = true;
  }
  for (int f = 0; f < u_faces; ++f) {
    vec4 child[8];
    for (int i = 0; i < 8; ++i) {
      child[i] = imageLoad(u_atlas, atlasTexel(f, u_level - 1, toroidalAddress(2 * cell + ivec3(i & 1, (i >> 1) & 1, i >> 2))));
      if (dropFilled && isFilled[i]) child[i] = vec4(0.0);
    }
    vec4 value = vec4(0.0);
    if (f == 0) {
      for (int i = 0; i < 8; ++i) value += child[i];
      value *= 0.125;
    } else {
      value = anisotropicReduce(child, f - 1);  // faces 1..6: +x -x +y -y +z -z (the cone's direction)
    }
    imageStore(u_atlas, atlasTexel(f, u_level, phys), value);
  }
  atomicAdd(counters[5 * u_level + 3], 1u);
}
