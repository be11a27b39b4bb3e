// Exact triangle / voxel cell overlap by the separating axis theorem (Akenine-Moller): the 3 box
// face normals, the triangle normal and the 9 edge cross products. Voxels are half-open cells
// [i, i+1)^3 (docs/voxelization.md, "Ties on voxel faces"): along an axis with a positive
// component the cell's projection lacks its upper end, along one with a negative component its
// lower end, and a triangle that only touches a missing end is separated. The CPU reference
// voxelizer (src/reference/cpu_voxelizer.cpp) evaluates the same formulas in double.
bool axisSeparates(dvec3 axis, dvec3 v0, dvec3 v1, dvec3 v2, dvec3 h) {
  double p0 = dot(v0, axis), p1 = dot(v1, axis), p2 = dot(v2, axis);
  double r = dot(h, abs(axis));
  double lo = min(p0, min(p1, p2)), hi = max(p0, max(p1, p2));
  bool upperOpen = any(greaterThan(axis, dvec3(0.0)));
  bool lowerOpen = any(lessThan(axis, dvec3(0.0)));
  return (upperOpen ? lo >= r : lo > r) || (lowerOpen ? hi <= -r : hi < -r);
}

// The same test with the triangle already relative to the box centre (in double: callers that
// compute exact triangle-local coordinates keep them exact).
bool triangleOverlapsCenteredBox(dvec3 v0, dvec3 v1, dvec3 v2, dvec3 h) {
  // Box face normals: the triangle's bounding box against the cell [-h, h).
  if (any(greaterThanEqual(min(v0, min(v1, v2)), h)) || any(lessThan(max(v0, max(v1, v2)), -h))) return false;
  dvec3 e0 = v1 - v0, e1 = v2 - v1, e2 = v0 - v2;
  // Triangle plane.
  if (axisSeparates(cross(e0, e1), v0, v1, v2, h)) return false;
  // Edge cross products.
  dvec3 axes[3] = dvec3[3](dvec3(1, 0, 0), dvec3(0, 1, 0), dvec3(0, 0, 1));
  dvec3 edges[3] = dvec3[3](e0, e1, e2);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      dvec3 axis = cross(axes[i], edges[j]);
      if (dot(axis, axis) > 1e-30 && axisSeparates(axis, v0, v1, v2, h)) return false;
    }
  return true;
}

bool triangleOverlapsBox(vec3 a, vec3 b, vec3 c, vec3 center, vec3 halfSize) {
  return triangleOverlapsCenteredBox(dvec3(a) - dvec3(center), dvec3(b) - dvec3(center), dvec3(c) - dvec3(center),
                                     dvec3(halfSize));
}
