// Anisotropic prefiltering (Crassin et al. 2011) of svo's directional bricks, and how every cone
// tracer blends the three directional values facing a cone (anisotropicWeights, frontsBlend).
// (vct-grid's directional volumes composite the same way in their own pass:
// shaders/vct_grid/mipmap_anisotropic.comp.glsl.) A 2x2x2 block is seen differently by a cone travelling
// along each of six directions d = 2 * axis + sign (0 = towards +axis, 1 = towards -axis: +x -x
// +y -y +z -z): along the direction's axis each pair of children is composited front to back (the
// child the cone reaches first in front), then the four composited pairs are averaged. A one-voxel
// wall seen face-on stays opaque at every level, where the isotropic average halves its opacity
// per level. A cone reads the three directions facing it, weighted by dir^2.

// Premultiplied radiance + opacity of 'front' in front of 'back'.
vec4 frontToBack(vec4 front, vec4 back) { return front + (1.0 - front.a) * back; }

// The block as seen along direction d; child[k] is the child at offset (x, y, z), k = x + 2y + 4z.
vec4 anisotropicReduce(vec4 child[8], int d) {
  int axis = d >> 1;
  bool negative = (d & 1) == 1;
  int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  vec4 sum = vec4(0.0);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      // (i, j) index the two axes other than 'axis'.
      ivec3 lo = ivec3(0);
      lo[a1] = i;
      lo[a2] = j;
      ivec3 hi = lo;
      hi[axis] = 1;
      int kLo = lo.x + 2 * lo.y + 4 * lo.z, kHi = hi.x + 2 * hi.y + 4 * hi.z;
      sum += frontToBack(child[negative ? kHi : kLo], child[negative ? kLo : kHi]);
    }
  return sum * 0.25;
}

// Weights of the three directional values facing a cone travelling along the unit vector 'dir'
// (the volume of +axis where dir[axis] >= 0, of -axis where it is negative): dir^2, summing to 1.
vec3 anisotropicWeights(vec3 dir) { return dir * dir; }

// Transmittance of a texel whose fronts are opaque in the optical-depth blend of frontsBlend:
// exp(-69), so that a weight of 0.05 still leaves 3 %.
const float kOpaqueTransmittance = 1e-30;

// The three directional values facing a cone (sx, sy, sz: premultiplied radiance of the fronts
// each sees, alpha their coverage; common/facing.glsl), weighted w = anisotropicWeights(dir), as
// one premultiplied sample. Their optical depths add, weighted (extinction is additive; the
// weights sum to 1, so a homogeneous texel keeps its opacity): a front that one volume sees opaque
// stops every ray of the cone, whatever the others see. So a floor seen at 45 degrees is opaque
// and keeps its radiance although the volume along the floor sees it edge-on, where blending the
// opacities would make it half transparent; the surface a cone starts from (seen from behind or
// edge-on) does not block it; and the volume that sees a slab edge-on does not average its sun-lit
// outside face with its inside one. The radiance is the volumes' average weighted by the fronts
// each sees.
vec4 frontsBlend(vec4 sx, vec4 sy, vec4 sz, vec3 w) {
  vec3 fronts = vec3(sx.a, sy.a, sz.a);
  float opacity = 1.0 - exp(dot(w, log(max(1.0 - fronts, kOpaqueTransmittance))));
  float weight = dot(w, fronts);
  vec3 radiance = weight > 0.0 ? (w.x * sx.rgb + w.y * sy.rgb + w.z * sz.rgb) / weight : vec3(0.0);
  return vec4(radiance * opacity, opacity);
}
