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

// The front weight a cone travelling along direction d sees of a surface of normal n, in steps of
// 1 / kFacingSteps (0: behind the surface or edge-on to it).
uint frontSteps(vec3 n, int d) {
  float front = max((d & 1) == 0 ? -n[d >> 1] : n[d >> 1], 0.0);
  return uint(clamp(front * float(kFacingSteps) + 0.5, 0.0, float(kFacingSteps)));
}

uint facingCode(vec3 n) {
  uint code = 0u;
  for (int d = 0; d < 6; ++d) code |= ((1u << frontSteps(n, d)) - 1u) << uint(kFacingSteps * d);
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

// Transmittance of a texel whose fronts are opaque in the optical-depth blend of seenFronts:
// exp(-69), so that a weight of 0.05 still leaves 3 %.
const float kOpaqueTransmittance = 1e-30;

// What a cone travelling along a direction sees of the three directional values facing it (sx, sy,
// sz: the fronts' premultiplied radiance and coverage as their volumes, or faces, hold them),
// weighted by w = anisotropicWeights(dir) (common/anisotropic_mip.glsl): premultiplied radiance
// and opacity. The values show only the fronts of the surfaces they see: what a volume sees from
// behind or edge-on is empty in it. Their optical depths add, weighted (extinction is additive;
// the weights sum to 1, so a homogeneous texel keeps its opacity): a front that one volume sees
// opaque stops every ray of the cone, whatever the others see. So a floor seen at 45 degrees is
// opaque and keeps its radiance although the volume along the floor sees it edge-on, where
// blending the opacities would make it half transparent; the surface a cone starts from (seen
// from behind or edge-on) does not block it; and the volume that sees a slab edge-on does not
// average its sun-lit outside face with its inside one. The radiance is the volumes' average
// weighted by the fronts each sees. Every cone tracer with directional values uses it (vct-grid's
// common/cone_trace.glsl, svo's bricks, clipmap's faces).
// Where the optical depth is small, 1 - exp(-depth) is its series: llvmpipe's exp answers in steps
// of 2^-24 just below 1, and a cone that sees an opaque wall with weight 1e-15 (a ring cone along a
// tangent) got an opacity of 6e-8 for one of 1e-13, its radiance (its premultiplied colour over its
// weight) times that ratio: pixels a million times too bright.
vec4 seenFronts(vec3 w, vec4 sx, vec4 sy, vec4 sz) {
  vec3 fronts = vec3(sx.a, sy.a, sz.a);
  float depth = -dot(w, log(max(1.0 - fronts, kOpaqueTransmittance)));
  float opacity = depth < 1e-3 ? depth * (1.0 - 0.5 * depth) : 1.0 - exp(-depth);
  float weight = dot(w, fronts);
  vec3 radiance = weight > 0.0 ? (w.x * sx.rgb + w.y * sy.rgb + w.z * sz.rgb) / weight : vec3(0.0);
  return vec4(radiance * opacity, opacity);
}
#endif
