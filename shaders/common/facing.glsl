// Which way a voxel's surfaces face, per travel direction of a cone (d = 2 * axis + (0: +, 1: -),
// the order of the six directional volumes): a cone travelling along unit axis vector e sees the
// front of a surface of normal n with weight max(0, -n.e), the projected area of the surface's
// front across e. A voxel keeps, per direction, the largest weight of its fragments, in 5 steps of
// 0.2 as a thermometer code (q lowest bits of a 5-bit field set for q steps), so that OR-ing the
// fragments' codes (imageAtomicOr) takes the maximum. 6 fields of 5 bits: 30 bits of an R32UI.
// The anisotropic mips build each direction's leaves from it (vct-grid's mipmap_anisotropic).
#ifndef VOXLAB_FACING_GLSL
#define VOXLAB_FACING_GLSL

const int kFacingSteps = 5;

uint facingCode(vec3 n) {
  uint code = 0u;
  for (int d = 0; d < 6; ++d) {
    float front = max((d & 1) == 0 ? -n[d >> 1] : n[d >> 1], 0.0);
    uint q = uint(clamp(front * float(kFacingSteps) + 0.5, 0.0, float(kFacingSteps)));
    code |= ((1u << q) - 1u) << uint(kFacingSteps * d);
  }
  return code;
}

// The largest front weight a voxel's fragments have for travel direction d, in [0, 1].
float facingFront(uint code, int d) {
  return float(bitCount((code >> uint(kFacingSteps * d)) & ((1u << uint(kFacingSteps)) - 1u))) / float(kFacingSteps);
}

// The fronts a cone travelling along d sees of a leaf voxel (radiance L, opacity a): their
// premultiplied radiance and their coverage, a times the front weight. Behind a surface or edge-on
// to it the coverage is 0: the voxel still blocks the cone (its opacity is kept apart), but it
// says nothing about the radiance the cone sees.
vec4 facingLeaf(vec4 voxel, uint code, int d) {
  float front = facingFront(code, d);
  return vec4(voxel.rgb, voxel.a) * front;
}
#endif
