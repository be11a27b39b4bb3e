// Spherical harmonics L1 for light propagation volumes (shaders/lpv), the same maths as the C++
// twin src/techniques/lpv/sh.h (the CPU reference): every expression here has its twin there,
// written in the same order with `precise` so llvmpipe does not fuse multiply-adds and the two
// agree bit for bit.
//
// Storage: vec4 (c00, c1-1, c10, c11) per colour channel, Condon-Shortley basis
//   Y(d) = (0.2820948, -0.4886025 d.y, 0.4886025 d.z, -0.4886025 d.x).
// The band-1 vector of a cell is b = (-c11, -c1-1, c10): f(d) = 0.2820948 c00 + 0.4886025 b.d.
// Clamped cosine lobe around n: lobe(n) = (sqrt(pi)/2, -sqrt(pi/3) n.y, sqrt(pi/3) n.z, -sqrt(pi/3) n.x);
//   <lobe(a), Y(d)> = 0.25 + 0.5 a.d.
// Intensity is indexed by the direction light travels (a VPL on a surface with normal n is lobe(+n)).
#ifndef VOXLAB_SH_GLSL
#define VOXLAB_SH_GLSL

const float SH_Y00 = 0.282094792;    // 1 / (2 sqrt(pi))
const float SH_Y1 = 0.488602512;     // sqrt(3 / (4 pi))
const float SH_LOBE0 = 0.886226925;  // sqrt(pi) / 2
const float SH_LOBE1 = 1.023326708;  // sqrt(pi / 3)
const float SH_BEAM1 = 1.534990061;  // pi Y1 = sqrt(3 pi) / 2: band 1 of a narrow beam of the same flux as a lobe
const float SH_FLUX_PER_C00 = 3.544907702;  // 4 pi Y00 = 2 sqrt(pi): flux of an intensity field per unit c00
// Solid angles of a cell's faces seen from a face neighbour's centre (seed 000 Listing 4.32):
// far face 4 asin(0.1); the four side faces share the rest of the 2 pi / 3 the shared face subtends.
const float LPV_SOLID_ANGLE_FAR = 0.4006696846;
const float LPV_SOLID_ANGLE_SIDE = 0.4234313544;  // (2 pi / 3 - far) / 4 (public code's 0.4234413544 is a typo)
const float LPV_SIDE_ALONG = 0.894427191;   // 2 / sqrt(5): side-face direction along the neighbour axis
const float LPV_SIDE_ACROSS = 0.4472135955; // 1 / sqrt(5): side-face direction across it

vec4 shBasis(vec3 d) { return vec4(SH_Y00, -SH_Y1 * d.y, SH_Y1 * d.z, -SH_Y1 * d.x); }
vec4 shLobe(vec3 n) { return vec4(SH_LOBE0, -SH_LOBE1 * n.y, SH_LOBE1 * n.z, -SH_LOBE1 * n.x); }
// pi Y(d): the L1 projection of a narrow beam along d carrying the flux of lobe(d) (same c00, band 1
// 1.5 times the lobe's), so re-emitting a flux as beam keeps its direction whole.
vec4 shBeam(vec3 d) { return vec4(SH_LOBE0, -SH_BEAM1 * d.y, SH_BEAM1 * d.z, -SH_BEAM1 * d.x); }
// <sh, Y(d)>: the intensity the L1 field sends along d.
float shEvaluate(vec4 sh, vec3 d) {
  precise float a = sh.x * SH_Y00;
  precise float b = sh.y * (-SH_Y1 * d.y);
  precise float c = sh.z * (SH_Y1 * d.z);
  precise float e = sh.w * (-SH_Y1 * d.x);
  precise float r = ((a + b) + c) + e;
  return r;
}
// shEvaluate for a direction with zero components (a face direction): the zero terms are left out
// and the others added in shEvaluate's order (y, z, x), so the value is the same, with fewer
// operations once the direction is a constant.
float shEvaluateSparse(vec4 sh, vec3 d) {
  precise float r = sh.x * SH_Y00;
  if (d.y != 0.0) { precise float t = r + sh.y * (-SH_Y1 * d.y); r = t; }
  if (d.z != 0.0) { precise float t = r + sh.z * (SH_Y1 * d.z); r = t; }
  if (d.x != 0.0) { precise float t = r + sh.w * (-SH_Y1 * d.x); r = t; }
  return r;
}
// acc + f * lobe(o) for an axis direction o: only c00 and the axis' coefficient change.
vec4 shAddAxisLobe(vec4 acc, float f, ivec3 o) {
  precise float c0 = acc.x + f * SH_LOBE0;
  vec4 r = acc;
  r.x = c0;
  if (o.y != 0) { precise float t = acc.y + f * (-SH_LOBE1 * float(o.y)); r.y = t; }
  if (o.z != 0) { precise float t = acc.z + f * (SH_LOBE1 * float(o.z)); r.z = t; }
  if (o.x != 0) { precise float t = acc.w + f * (-SH_LOBE1 * float(o.x)); r.w = t; }
  return r;
}
// <sh, lobe(n)>: the field convolved with a clamped cosine around n.
float shDotLobe(vec4 sh, vec3 n) {
  precise float a = sh.x * SH_LOBE0;
  precise float b = sh.y * (-SH_LOBE1 * n.y);
  precise float c = sh.z * (SH_LOBE1 * n.z);
  precise float e = sh.w * (-SH_LOBE1 * n.x);
  precise float r = ((a + b) + c) + e;
  return r;
}
// Band-1 vector b with f(d) = Y00 c00 + Y1 b.d.
vec3 shBand1(vec4 sh) { return vec3(-sh.w, -sh.y, sh.z); }

// The six face neighbours, in the order +x, -x, +y, -y, +z, -z.
ivec3 lpvOffset(int i) {
  int axis = i >> 1;
  int s = (i & 1) == 0 ? 1 : -1;
  return ivec3(axis == 0 ? s : 0, axis == 1 ? s : 0, axis == 2 ? s : 0);
}
// Direction from neighbour i's centre to the centre of face j of the cell (j != i; j = i^1 is the
// far face, the other four are side faces).
vec3 lpvFaceDirection(int i, int j) {
  vec3 oi = vec3(lpvOffset(i)), oj = vec3(lpvOffset(j));
  if (j == (i ^ 1)) return -oi;
  precise vec3 d = -oi * LPV_SIDE_ALONG + oj * LPV_SIDE_ACROSS;
  return d;
}
float lpvFaceSolidAngle(int i, int j) { return j == (i ^ 1) ? LPV_SOLID_ANGLE_FAR : LPV_SOLID_ANGLE_SIDE; }

#endif
