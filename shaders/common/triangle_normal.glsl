// A triangle's plane normal (n = (v1 - v0) x (v2 - v0), unnormalised, non-zero) turned to the side
// of its vertex normals' sum: the normal every voxelizer gives a triangle's fragments (the raster
// pass's records as the compute pass writes them, clipmap's cells).
vec3 facingPlaneNormal(vec3 n, vec3 vertexNormalSum) {
  return normalize(n) * (dot(n, vertexNormalSum) < 0.0 ? -1.0 : 1.0);
}
