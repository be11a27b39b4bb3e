// Which voxel cells a triangle overlaps, by the setup of Schwarz & Seidel 2010 (seed 002 section 3):
// the plane test between the cell's critical corner and its opposite, and for each of the three
// projections (xy, yz, zx) three 2D edge functions shifted to their critical corner. Computed once
// per triangle, each cell then costs a few products. Inside the triangle's bounding box of cells
// (the caller's loop, or triangleCellsBoxHolds) this is exactly the 13-axis separating axis test
// of the CPU reference (src/reference/cpu_voxelizer.cpp), with the
// same half-open cells [i, i+1)^3: a test whose critical corner lies on the cell's upper side (a
// direction with a positive component) is strict, so a triangle that only touches an upper face,
// edge or corner is out.
// In double, like the CPU reference: float products of coordinates near 256 round by ~1e-5 voxel,
// which decided near-touching voxels differently (docs/voxelization.md, "Ties on voxel faces").
// The triangle is taken relative to the integer origin floor(w0): every pass that uses this setup
// with the same vertex order gets the same bits, so the raster and compute voxelizers agree.

// 2D edge functions of one projection, each (n.x, n.y, d): inside when dot(n, p) + d >= 0 for the
// box corner p with the smallest coordinates (d already moved to the critical corner, box edge 1
// voxel); > 0 when n has a positive component, as that critical corner lies on an upper face
// (half-open). Three named members, no arrays: with the edges in arrays inside the struct the test
// cost llvmpipe's raster pass as much as the rest of the pass (15.6 against 8.7 ms of CPU per
// voxelization of the Cornell box at 128^3, one thread).
struct Edges2D { dvec3 e0, e1, e2; };

dvec3 setupEdge(dvec2 p, dvec2 q, double orientation) {
  dvec2 edge = q - p;
  dvec2 n = dvec2(-edge.y, edge.x) * orientation;
  return dvec3(n, -dot(n, p) + max(0.0, n.x) + max(0.0, n.y));
}

Edges2D setupEdges(dvec2 a, dvec2 b, dvec2 c, double normalComponent) {
  double orientation = normalComponent >= 0.0 ? 1.0 : -1.0;  // make the edge normals point inwards
  return Edges2D(setupEdge(a, b, orientation), setupEdge(b, c, orientation), setupEdge(c, a, orientation));
}

bool insideEdge(dvec3 e, dvec2 p) {
  double f = dot(e.xy, p) + e.z;
  return (e.x > 0.0 || e.y > 0.0) ? f > 0.0 : f >= 0.0;
}
bool insideEdges(Edges2D e, dvec2 p) { return insideEdge(e.e0, p) && insideEdge(e.e1, p) && insideEdge(e.e2, p); }

struct TriangleCells {
  vec3 origin;                      // floor(w0): the triangle-local frame's integer origin
  dvec3 normal;                     // plane normal, triangle-local
  double above, below;              // n.(corner - v0) at the largest and the smallest corner, less n.p
  bool upperStrict, lowerStrict;    // the critical corners on an upper / a lower face
  Edges2D xy, yz, zx;               // edge functions of the projections (normal part z, x, y)
  ivec3 boxLo, boxHi;               // the cells the triangle's bounding box meets
};

// w0, w1, w2 in voxel coordinates.
TriangleCells triangleCellsSetup(vec3 w0, vec3 w1, vec3 w2) {
  TriangleCells t;
  t.origin = floor(w0);
  // Triangle-local in double from the float voxel coordinates: exact (a float minus an integer
  // needs at most 34 bits), where a float difference rounds once a vertex is far from the origin.
  dvec3 v0 = dvec3(w0) - dvec3(t.origin), v1 = dvec3(w1) - dvec3(t.origin), v2 = dvec3(w2) - dvec3(t.origin);
  t.normal = cross(v1 - v0, v2 - v0);
  dvec3 c = dvec3(t.normal.x > 0.0 ? 1.0 : 0.0, t.normal.y > 0.0 ? 1.0 : 0.0, t.normal.z > 0.0 ? 1.0 : 0.0);
  t.above = dot(t.normal, c - v0);
  t.below = dot(t.normal, (dvec3(1.0) - c) - v0);
  t.upperStrict = any(greaterThan(t.normal, dvec3(0.0)));
  t.lowerStrict = any(lessThan(t.normal, dvec3(0.0)));
  t.xy = setupEdges(v0.xy, v1.xy, v2.xy, t.normal.z);
  t.yz = setupEdges(v0.yz, v1.yz, v2.yz, t.normal.x);
  t.zx = setupEdges(v0.zx, v1.zx, v2.zx, t.normal.y);
  // A vertex on a voxel face is in the upper cell.
  t.boxLo = ivec3(floor(min(w0, min(w1, w2))));
  t.boxHi = ivec3(floor(max(w0, max(w1, w2))));
  return t;
}

// Whether the cell 'voxel' lies in the triangle's bounding box of cells (the box-face axes of the
// separating axis test).
bool triangleCellsBoxHolds(TriangleCells t, ivec3 voxel) {
  return all(greaterThanEqual(voxel, t.boxLo)) && all(lessThanEqual(voxel, t.boxHi));
}

// The plane and the nine edge tests for the cell 'voxel' (a cell of the bounding box).
bool triangleMeetsCell(TriangleCells t, vec3 voxel) {
  dvec3 p = dvec3(voxel - t.origin);  // box minimum corner, triangle-local (integers)
  double np = dot(t.normal, p);
  double above = np + t.above, below = np + t.below;
  if (t.upperStrict ? above <= 0.0 : above < 0.0) return false;
  if (t.lowerStrict ? below >= 0.0 : below > 0.0) return false;
  return insideEdges(t.xy, p.xy) && insideEdges(t.yz, p.yz) && insideEdges(t.zx, p.zx);
}
