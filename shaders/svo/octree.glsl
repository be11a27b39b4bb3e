// Octree lookups shared by the svo passes. The including shader declares the node pool
// `SvoNode nodes[]` (binding SVO_BINDING_NODES) and `uniform int u_depth` (D: level of the voxels).

// The node of 'level' whose cell (in that level's integer coordinates) is 'cell', found by a
// descent from the root along the bits of 'cell'; SVO_ABSENT when a node on the way has no
// children (the region is empty at that level).
uint svoFind(uvec3 cell, int level) {
  uint node = 0u;
  for (int l = 1; l <= level; ++l) {
    uint first = nodes[node].word & SVO_CHILD_MASK;
    if (first == 0u) return SVO_ABSENT;
    uvec3 bit = (cell >> uint(level - l)) & 1u;
    node = first + bit.x + 2u * bit.y + 4u * bit.z;
  }
  return node;
}

// The node at cell 'm' of the same level as node 'from' (whose cell is 'c'), found through their
// closest common ancestor: up the parent links until the cells agree, then down along the bits of
// 'm'. Near neighbours share an ancestor one or two levels up, so this reads far fewer nodes than
// a descent from the root. SVO_ABSENT when a node on the way down has no children.
uint svoNeighbour(uint from, uvec3 c, uvec3 m) {
  uint node = from;
  int up = 0;
  while (any(notEqual(c >> uint(up), m >> uint(up)))) {
    node = nodes[node].parent;
    ++up;
  }
  for (int l = up - 1; l >= 0; --l) {
    uint first = nodes[node].word & SVO_CHILD_MASK;
    if (first == 0u) return SVO_ABSENT;
    uvec3 bit = (m >> uint(l)) & 1u;
    node = first + bit.x + 2u * bit.y + 4u * bit.z;
  }
  return node;
}

// floor(n / d) for n < SVO_MAX_BRICKS (2^22) and 0 < d < 2^12 without an integer division, which
// the CPU's vector units lack (llvmpipe divides lane by lane: the cone tracer's brick addresses
// cost 11 % of its time that way). The float quotient is within 2 of the exact one (relative
// error below 2^-21), and two correction steps make it exact.
uint svoDivide(uint n, uint d) {
  uint q = uint(float(n) / float(d));
  for (int k = 0; k < 2; ++k) {
    if (q * d > n) q -= 1u;
    else if ((q + 1u) * d <= n) q += 1u;
  }
  return q;
}

// The coordinates of brick b in a pool of perAxis.x x perAxis.y x ... bricks, x fastest:
// (b mod X, b / X mod Y, b / XY), the bricks stage's layout.
uvec3 svoBrickCoords(uint b, uvec2 perAxis) {
  uint row = svoDivide(b, perAxis.x);
  uint slab = svoDivide(row, perAxis.y);
  return uvec3(b - row * perAxis.x, row - slab * perAxis.y, slab);
}
