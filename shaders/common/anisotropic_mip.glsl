// Anisotropic prefiltering (Crassin et al. 2011) of svo's directional bricks, and how every cone
// tracer weights the three directional values facing a cone (anisotropicWeights; they are blended
// by common/facing.glsl's seenFronts).
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
