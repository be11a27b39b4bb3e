// Exact triangle / axis-aligned box overlap by the separating axis theorem (Akenine-Moller): the
// 3 box face normals, the triangle normal and the 9 edge cross products. Touching counts as
// overlap. The CPU reference voxelizer (src/reference/cpu_voxelizer.cpp) uses the same test.
bool axisSeparates(vec3 axis, vec3 v0, vec3 v1, vec3 v2, vec3 h) {
  float p0 = dot(v0, axis), p1 = dot(v1, axis), p2 = dot(v2, axis);
  float r = dot(h, abs(axis));
  return min(p0, min(p1, p2)) > r || max(p0, max(p1, p2)) < -r;
}

bool triangleOverlapsBox(vec3 a, vec3 b, vec3 c, vec3 center, vec3 halfSize) {
  vec3 v0 = a - center, v1 = b - center, v2 = c - center;
  vec3 h = halfSize;
  // Box face normals: the triangle's bounding box against the box.
  if (any(greaterThan(min(v0, min(v1, v2)), h)) || any(lessThan(max(v0, max(v1, v2)), -h))) return false;
  vec3 e0 = v1 - v0, e1 = v2 - v1, e2 = v0 - v2;
  // Triangle plane.
  vec3 n = cross(e0, e1);
  if (abs(dot(n, v0)) > dot(h, abs(n))) return false;
  // Edge cross products.
  vec3 axes[3] = vec3[3](vec3(1, 0, 0), vec3(0, 1, 0), vec3(0, 0, 1));
  vec3 edges[3] = vec3[3](e0, e1, e2);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      vec3 axis = cross(axes[i], edges[j]);
      if (dot(axis, axis) > 1e-20 && axisSeparates(axis, v0, v1, v2, h)) return false;
    }
  return true;
}
