#version 450
// Anisotropic mipmapping (Crassin et al. 2011): six prefiltered volumes, one per direction a cone
// can travel (+x, -x, +y, -y, +z, -z). For direction +x, each pair of children along x is first
// composited front to back (the child with the smaller x in front: c = c0 + (1 - a0) c1,
// a = a0 + (1 - a0) a1), then the four composited columns are averaged. A one-voxel wall seen
// face-on therefore stays opaque at every level, where the isotropic average halves its opacity
// per level.
// Level 1 of the hierarchy is built from the isotropic level-0 voxels; higher levels from the
// direction's own previous level.
// Each direction keeps apart what a cone gathers radiance from and what blocks it:
//  - the fronts (the volume's rgba): a leaf shows its radiance only to the directions that see
//    its surfaces' fronts, with their coverage as alpha (common/facing.glsl, codes from
//    inject.comp.glsl); behind a surface or edge-on to it the leaf is empty. Composited front to
//    back by that coverage, so a cone travelling up sees the underside of a ceiling slab, never
//    its sun-lit top, and the volume that sees a slab edge-on holds neither face: averaging both
//    there let the sun-lit outside of a closed room leak in;
//  - the solid opacity (u_opacityPos/Neg, one channel per axis: +x +y +z and -x -y -z): a voxel
//    is a cube, opaque from every direction; ambient occlusion and cone-traced shadows read it.
// The cone sampler combines both (common/cone_trace.glsl, sampleVolume).
// The radiance grids' image format: rgba8 unless the stage builds the program with
// "#define VOXLAB_GRID_FORMAT rgba16f" (voxel.format=rgba16f).
#ifndef VOXLAB_GRID_FORMAT
#define VOXLAB_GRID_FORMAT rgba8
#endif
#include "common/facing.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(binding = 0) uniform sampler3D u_isotropic;  // level 0 voxels
// The directional volumes, read at u_sourceLevel (+x -x +y -y +z -z).
layout(binding = 1) uniform sampler3D u_dir0;
layout(binding = 2) uniform sampler3D u_dir1;
layout(binding = 3) uniform sampler3D u_dir2;
layout(binding = 4) uniform sampler3D u_dir3;
layout(binding = 5) uniform sampler3D u_dir4;
layout(binding = 6) uniform sampler3D u_dir5;
layout(binding = 7) uniform usampler3D u_facing;  // level 0: the voxels' facing codes
layout(binding = 8) uniform sampler3D u_opacityPos;  // opacity seen travelling +x, +y, +z (rgb)
layout(binding = 9) uniform sampler3D u_opacityNeg;  // travelling -x, -y, -z
layout(VOXLAB_GRID_FORMAT, binding = 0) uniform writeonly image3D u_target0;
layout(VOXLAB_GRID_FORMAT, binding = 1) uniform writeonly image3D u_target1;
layout(VOXLAB_GRID_FORMAT, binding = 2) uniform writeonly image3D u_target2;
layout(VOXLAB_GRID_FORMAT, binding = 3) uniform writeonly image3D u_target3;
layout(VOXLAB_GRID_FORMAT, binding = 4) uniform writeonly image3D u_target4;
layout(VOXLAB_GRID_FORMAT, binding = 5) uniform writeonly image3D u_target5;
layout(rgba8, binding = 6) uniform writeonly image3D u_opacityPosTarget;
layout(rgba8, binding = 7) uniform writeonly image3D u_opacityNegTarget;
uniform int u_fromIsotropic;
uniform int u_sourceLevel;
uniform int u_writeOpacity;  // 0: the opacity volumes are already built (a bounce's grid, same geometry)
uniform int u_classicDirectional;  // 1: mipmap.fronts=false, every voxel seen from all sides (Crassin's)

// A child texel as direction d sees it: the fronts' premultiplied radiance and coverage, and the
// solid opacity.
struct Seen { vec4 fronts; float opacity; };

// Child k of the block at 'base' is at base + (k & 1, (k >> 1) & 1, k >> 2). What every direction
// shares is fetched once per child (the voxels and their facing codes at level 1, the solid
// opacities above), not once per direction: 16 fetches per texel where 96 were.
vec4 g_voxel[8];
uint g_code[8];
vec3 g_opacityPos[8], g_opacityNeg[8];

ivec3 childAt(ivec3 base, int k) { return base + ivec3(k & 1, (k >> 1) & 1, k >> 2); }

Seen child(int d, ivec3 base, int k) {
  if (u_fromIsotropic != 0) {
    vec4 voxel = g_voxel[k];
    if (u_classicDirectional != 0) return Seen(voxel, voxel.a);
    return Seen(facingLeaf(voxel, g_code[k], d), voxel.a);
  }
  const ivec3 v = childAt(base, k);
  const float a = ((d & 1) == 0 ? g_opacityPos[k] : g_opacityNeg[k])[d >> 1];
  switch (d) {
    case 0: return Seen(texelFetch(u_dir0, v, u_sourceLevel), a);
    case 1: return Seen(texelFetch(u_dir1, v, u_sourceLevel), a);
    case 2: return Seen(texelFetch(u_dir2, v, u_sourceLevel), a);
    case 3: return Seen(texelFetch(u_dir3, v, u_sourceLevel), a);
    case 4: return Seen(texelFetch(u_dir4, v, u_sourceLevel), a);
    default: return Seen(texelFetch(u_dir5, v, u_sourceLevel), a);
  }
}

// Direction d = 2 * axis + (0 for +, 1 for -): pairs along the axis composited front to back, the
// four pairs averaged.
Seen reduce(int d, ivec3 base) {
  int axis = d >> 1;
  bool negative = (d & 1) == 1;
  Seen sum = Seen(vec4(0.0), 0.0);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      ivec3 lo = ivec3(0);
      // (i, j) index the two axes other than 'axis'.
      lo[(axis + 1) % 3] = i;
      lo[(axis + 2) % 3] = j;
      ivec3 hi = lo;
      hi[axis] = 1;
      const int kLo = lo.x + 2 * lo.y + 4 * lo.z, kHi = hi.x + 2 * hi.y + 4 * hi.z;
      Seen near = child(d, base, negative ? kHi : kLo), far = child(d, base, negative ? kLo : kHi);
      sum.fronts += near.fronts + (1.0 - near.fronts.a) * far.fronts;
      sum.opacity += near.opacity + (1.0 - near.opacity) * far.opacity;
    }
  sum.fronts *= 0.25;
  sum.opacity *= 0.25;
  return sum;
}

void main() {
  ivec3 v = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(v, imageSize(u_target0)))) return;
  ivec3 base = 2 * v;
  for (int k = 0; k < 8; ++k) {
    const ivec3 c = childAt(base, k);
    if (u_fromIsotropic != 0) {
      g_voxel[k] = texelFetch(u_isotropic, c, 0);
      g_code[k] = u_classicDirectional != 0 ? 0u : texelFetch(u_facing, c, 0).r;
    } else {
      g_opacityPos[k] = texelFetch(u_opacityPos, c, u_sourceLevel).rgb;
      g_opacityNeg[k] = texelFetch(u_opacityNeg, c, u_sourceLevel).rgb;
    }
  }
  Seen s[6];
  for (int d = 0; d < 6; ++d) s[d] = reduce(d, base);
  imageStore(u_target0, v, s[0].fronts);
  imageStore(u_target1, v, s[1].fronts);
  imageStore(u_target2, v, s[2].fronts);
  imageStore(u_target3, v, s[3].fronts);
  imageStore(u_target4, v, s[4].fronts);
  imageStore(u_target5, v, s[5].fronts);
  if (u_writeOpacity != 0) {
    imageStore(u_opacityPosTarget, v, vec4(s[0].opacity, s[2].opacity, s[4].opacity, 1.0));
    imageStore(u_opacityNegTarget, v, vec4(s[1].opacity, s[3].opacity, s[5].opacity, 1.0));
  }
}
