#version 450
// Anisotropic mipmapping (Crassin et al. 2011): six prefiltered volumes, one per direction a cone
// can travel (+x, -x, +y, -y, +z, -z). For direction +x, each pair of children along x is first
// composited front to back (the child with the smaller x in front: c = c0 + (1 - a0) c1,
// a = a0 + (1 - a0) a1), then the four composited columns are averaged. A one-voxel wall seen
// face-on therefore stays opaque at every level, where the isotropic average halves its opacity
// per level.
// Level 1 of the hierarchy is built from the isotropic level-0 voxels (the program built with
// "#define VOXLAB_MIP_FROM_VOXELS"); higher levels from the direction's own previous level. The
// level-0 program also writes level 1 of the isotropic grid from the children it has fetched (the
// average of mipmap.comp.glsl, added in the same order, so the same bits), which saves that pass
// fetching them again.
// Each direction keeps apart what a cone gathers radiance from and what blocks it:
//  - the fronts (the volume's rgba): a leaf shows its radiance only to the directions that see
//    its surfaces' fronts, with their coverage as alpha (common/facing.glsl, codes from
//    inject.comp.glsl); behind a surface or edge-on to it the leaf is empty. Composited front to
//    back by that coverage, so a cone travelling up sees the underside of a ceiling slab, never
//    its sun-lit top, and the volume that sees a slab edge-on holds neither face: averaging both
//    there let the sun-lit outside of a closed room leak in;
//  - the solid opacity (u_solidOpacity, one channel per axis: x, y, z): a voxel is a cube, opaque
//    from every direction; ambient occlusion and cone-traced shadows read it. One volume serves
//    both directions of an axis: opacity alone composited front to back, a0 + (1 - a0) a1 =
//    1 - (1 - a0)(1 - a1), does not depend on which child is in front (stored: the smaller
//    coordinate in front, as +x, +y, +z composite).
// The cone sampler combines both (common/cone_trace.glsl, sampleVolume).
// Cost on llvmpipe: every child index below is a constant and each direction is written out (no
// loop over directions, no array indexed by a variable, no branch on a uniform): llvmpipe runs
// both sides of a branch and turns a variable index into a chain of selects, which made this pass
// twenty times the cost of the isotropic one.
// The radiance grids' image format: rgba8 unless the stage builds the program with
// "#define VOXLAB_GRID_FORMAT rgba16f" (voxel.format=rgba16f).
#ifndef VOXLAB_GRID_FORMAT
#define VOXLAB_GRID_FORMAT rgba8
#endif
#include "common/facing.glsl"
layout(local_size_x = 64) in;  // one invocation per listed texel (vct_grid/mip_blocks.glsl)
#include "vct_grid/mip_blocks.glsl"
layout(binding = 0) uniform sampler3D u_isotropic;  // level 0 voxels
// The directional volumes, read at u_sourceLevel (+x -x +y -y +z -z).
layout(binding = 1) uniform sampler3D u_dir0;
layout(binding = 2) uniform sampler3D u_dir1;
layout(binding = 3) uniform sampler3D u_dir2;
layout(binding = 4) uniform sampler3D u_dir3;
layout(binding = 5) uniform sampler3D u_dir4;
layout(binding = 6) uniform sampler3D u_dir5;
layout(binding = 7) uniform usampler3D u_facing;  // level 0: the voxels' facing codes
layout(binding = 8) uniform sampler3D u_solidOpacity;  // opacity seen along x, y, z (rgb), either way
layout(VOXLAB_GRID_FORMAT, binding = 0) uniform writeonly image3D u_target0;
layout(VOXLAB_GRID_FORMAT, binding = 1) uniform writeonly image3D u_target1;
layout(VOXLAB_GRID_FORMAT, binding = 2) uniform writeonly image3D u_target2;
layout(VOXLAB_GRID_FORMAT, binding = 3) uniform writeonly image3D u_target3;
layout(VOXLAB_GRID_FORMAT, binding = 4) uniform writeonly image3D u_target4;
layout(VOXLAB_GRID_FORMAT, binding = 5) uniform writeonly image3D u_target5;
layout(rgba8, binding = 6) uniform writeonly image3D u_solidOpacityTarget;
#ifdef VOXLAB_MIP_FROM_VOXELS
layout(VOXLAB_GRID_FORMAT, binding = 8) uniform writeonly image3D u_isotropicTarget;  // level 1 of the grid
#endif
uniform int u_sourceLevel;
uniform int u_writeOpacity;  // 0: the opacity volumes are already built (a bounce's grid, same geometry)
uniform int u_classicDirectional;  // 1: mipmap.fronts=false, every voxel seen from all sides (Crassin's)

// A child texel as one direction sees it: the fronts' premultiplied radiance and coverage, and the
// solid opacity.
struct Seen { vec4 fronts; float opacity; };

// Child k of the block at 'base' is at base + (k & 1, (k >> 1) & 1, k >> 2). What every direction
// shares is fetched once per child (the voxels and their facing codes at level 1, the solid
// opacities above), not once per direction.
vec4 g_voxel[8];
uint g_code[8];
vec3 g_solidOpacity[8];
ivec3 g_base;

ivec3 childAt(int k) { return g_base + ivec3(k & 1, (k >> 1) & 1, k >> 2); }

// Child k as direction d sees it (d and k are constants at every call).
Seen child(int d, int k) {
#ifdef VOXLAB_MIP_FROM_VOXELS
  vec4 voxel = g_voxel[k];
  return Seen(u_classicDirectional != 0 ? voxel : facingLeaf(voxel, g_code[k], d), voxel.a);
#else
  const ivec3 v = childAt(k);
  const float a = g_solidOpacity[k][d >> 1];
  switch (d) {
    case 0: return Seen(texelFetch(u_dir0, v, u_sourceLevel), a);
    case 1: return Seen(texelFetch(u_dir1, v, u_sourceLevel), a);
    case 2: return Seen(texelFetch(u_dir2, v, u_sourceLevel), a);
    case 3: return Seen(texelFetch(u_dir3, v, u_sourceLevel), a);
    case 4: return Seen(texelFetch(u_dir4, v, u_sourceLevel), a);
    default: return Seen(texelFetch(u_dir5, v, u_sourceLevel), a);
  }
#endif
}

// One pair of children along direction d's axis, 'lo' the one at the smaller coordinate: the
// child the cone reaches first in front, composited front to back.
Seen pair(int d, int lo, int hi) {
  const bool negative = (d & 1) == 1;
  Seen near = child(d, negative ? hi : lo), far = child(d, negative ? lo : hi);
  return Seen(near.fronts + (1.0 - near.fronts.a) * far.fronts, near.opacity + (1.0 - near.opacity) * far.opacity);
}

// Direction d = 2 * axis + (0 for +, 1 for -): the four pairs along the axis composited, then
// averaged. The pairs are added in the order (i, j) of the two other axes (axis + 1, axis + 2)
// the reduction has always used, so the sums round the same way.
Seen reduce(int d) {
  Seen p0, p1, p2, p3;
  if ((d >> 1) == 0) {  // x: (y, z) = (0,0) (0,1) (1,0) (1,1)
    p0 = pair(d, 0, 1); p1 = pair(d, 4, 5); p2 = pair(d, 2, 3); p3 = pair(d, 6, 7);
  } else if ((d >> 1) == 1) {  // y: (z, x)
    p0 = pair(d, 0, 2); p1 = pair(d, 1, 3); p2 = pair(d, 4, 6); p3 = pair(d, 5, 7);
  } else {  // z: (x, y)
    p0 = pair(d, 0, 4); p1 = pair(d, 2, 6); p2 = pair(d, 1, 5); p3 = pair(d, 3, 7);
  }
  Seen sum = Seen(vec4(0.0), 0.0);
  sum.fronts += p0.fronts; sum.opacity += p0.opacity;
  sum.fronts += p1.fronts; sum.opacity += p1.opacity;
  sum.fronts += p2.fronts; sum.opacity += p2.opacity;
  sum.fronts += p3.fronts; sum.opacity += p3.opacity;
  sum.fronts *= 0.25;
  sum.opacity *= 0.25;
  return sum;
}

void fetchChild(int k) {
  const ivec3 c = childAt(k);
#ifdef VOXLAB_MIP_FROM_VOXELS
  g_voxel[k] = texelFetch(u_isotropic, c, 0);
  g_code[k] = u_classicDirectional != 0 ? 0u : texelFetch(u_facing, c, 0).r;
#else
  g_solidOpacity[k] = texelFetch(u_solidOpacity, c, u_sourceLevel).rgb;
#endif
}

void main() {
  ivec3 v;
  if (!listedTexel(v)) return;
  g_base = 2 * v;
  fetchChild(0); fetchChild(1); fetchChild(2); fetchChild(3);
  fetchChild(4); fetchChild(5); fetchChild(6); fetchChild(7);
#ifdef VOXLAB_MIP_FROM_VOXELS
  vec4 sum = vec4(0.0);
  sum += g_voxel[0]; sum += g_voxel[1]; sum += g_voxel[2]; sum += g_voxel[3];
  sum += g_voxel[4]; sum += g_voxel[5]; sum += g_voxel[6]; sum += g_voxel[7];
  imageStore(u_isotropicTarget, v, sum * 0.125);
#endif
  Seen s0 = reduce(0), s1 = reduce(1), s2 = reduce(2), s3 = reduce(3), s4 = reduce(4), s5 = reduce(5);
  imageStore(u_target0, v, s0.fronts);
  imageStore(u_target1, v, s1.fronts);
  imageStore(u_target2, v, s2.fronts);
  imageStore(u_target3, v, s3.fronts);
  imageStore(u_target4, v, s4.fronts);
  imageStore(u_target5, v, s5.fronts);
  if (u_writeOpacity != 0) {
    // +x, +y, +z composite the smaller coordinate in front; -x, -y, -z give the same opacity.
    imageStore(u_solidOpacityTarget, v, vec4(s0.opacity, s2.opacity, s4.opacity, 1.0));
  }
}
