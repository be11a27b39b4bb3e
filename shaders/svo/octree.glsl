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
