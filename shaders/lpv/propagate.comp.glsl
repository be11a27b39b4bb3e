#version 450
// One propagation step (seed 000 section 4.3.3, Listings 4.32/4.33; K&D 2010), one invocation
// per cell: gather from the 6 face neighbours, 5 faces each (the shared face is skipped). For
// neighbour i and face j of this cell the neighbour's intensity towards the face centre,
// max(0, <SH, Y(d_ij)>), times the face's solid angle, its transmission and the weight scale is a
// flux that re-enters as a clamped-cosine lobe leaving through face j. Neighbours outside the grid
// are skipped (never read). The CPU twin is src/techniques/lpv/reference.cpp: same order.
// u_probeMode = 1: one invocation recomputes the picked cell with per-neighbour contributions.
#include "common/sh.glsl"
#include "lpv/encoding.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(std430, binding = LPV_BINDING_VOXELS) readonly buffer Voxels { LpvVoxel voxels[]; };
layout(std430, binding = LPV_BINDING_PROBE) writeonly buffer Probe { LpvProbe probe; };
// The state lives in buffers (llvmpipe loads and stores them far faster than images); the stage
// copies each step's result into the output volumes. Section s of a state holds cells s * res^3...:
// 0-2 light r, g, b (what the lookup reads), 3-5 wavefront r, g, b.
layout(std430, binding = LPV_BINDING_STATE_IN) readonly buffer StateIn { vec4 stateIn[]; };
layout(std430, binding = LPV_BINDING_STATE_OUT) writeonly buffer StateOut { vec4 stateOut[]; };
uniform int u_step;
uniform int u_thesisScheme;        // 1: propagate everything so far; 0: only the last wavefront
uniform float u_weightScale;       // 1/pi (flux-consistent) or fluxAmplifier/(4 pi) (thesis)
uniform int u_clampFaces;
uniform int u_occlusion;           // 0 two-sided, 1 thesis, 2 none
uniform float u_occlusionAmplifier;
uniform int u_firstStepUnoccluded;
uniform int u_probeMode;
uniform ivec3 u_probeCell;
uniform int u_cascade;

// Whether the source cell blocks at all in this step, and the stored normal it blocks with: the
// one nearest the travel direction (two-sided: nearest up to sign), empty channels skipped.
bool blocker(LpvVoxel v, vec3 travel, out vec3 best) {
  best = vec3(0.0);
  if (u_occlusion == 2 || !decodeOccupied(v.colorOcclusion)) return false;
  if (u_step == 0 && u_firstStepUnoccluded == 1) return false;
  float bestDot = -1e30;
  for (int c = 0; c < 4; ++c) {
    uint m = v.normals[c];
    if (m == 0u) continue;
    vec3 n = decodeNormalMask(m);
    precise float t = (n.x * travel.x + n.y * travel.y) + n.z * travel.z;
    if (u_occlusion == 0 && t < 0.0) { n = -n; t = -t; }
    if (t > bestDot) { bestDot = t; best = n; }
  }
  return true;
}
// Transmission along d: 1 - clamp(A <lobe(n), Y(d)>).
float transmission(vec3 n, vec3 d) {
  precise float blocked = u_occlusionAmplifier * shEvaluate(shLobe(n), d);
  return 1.0 - min(max(blocked, 0.0), 1.0);
}

int cells() { return u_gridRes * u_gridRes * u_gridRes; }
vec4 sourceAt(int ch, ivec3 n) { return stateIn[(u_thesisScheme == 1 ? ch : 3 + ch) * cells() + cellIndex(n)]; }

// The three colour channels as named members: no array indexed in a loop, so llvmpipe keeps them
// in registers.
struct ShRgb { vec4 r, g, b; };

vec4 faceChannel(vec4 acc, vec4 src, vec3 d, float omega, float occ, ivec3 oj) {
  float e = shEvaluateSparse(src, d);
  if (u_clampFaces == 1) e = max(e, 0.0);
  precise float f = ((e * omega) * occ) * u_weightScale;
  return shAddAxisLobe(acc, f, oj);
}

// Face j of this cell, lit from neighbour i (src: the neighbour's SH per channel). Called with
// literal i and j (the FACES lists below), so after inlining the direction, solid angle and lobe
// axis are constants and the sparse evaluations lose their zero terms and branches: the same
// operations in the same order as the loop of the CPU reference (bit-identical).
void addFace(ShRgb src, int i, int j, bool blocks, vec3 blockNormal, inout ShRgb acc, inout float sumT) {
  vec3 d = lpvFaceDirection(i, j);
  float omega = lpvFaceSolidAngle(i, j);
  float occ = blocks ? transmission(blockNormal, d) : 1.0;
  sumT += occ;
  ivec3 oj = lpvOffset(j);
  acc.r = faceChannel(acc.r, src.r, d, omega, occ, oj);
  acc.g = faceChannel(acc.g, src.g, d, omega, occ, oj);
  acc.b = faceChannel(acc.b, src.b, d, omega, occ, oj);
}

// The five faces of neighbour i other than the shared one, in increasing j (the reference's order).
#define FACES(I, J0, J1, J2, J3, J4)                              \
  addFace(src, I, J0, blocks, blockNormal, acc, sumT);            \
  addFace(src, I, J1, blocks, blockNormal, acc, sumT);            \
  addFace(src, I, J2, blocks, blockNormal, acc, sumT);            \
  addFace(src, I, J3, blocks, blockNormal, acc, sumT);            \
  addFace(src, I, J4, blocks, blockNormal, acc, sumT)

void gatherNeighbour(ivec3 cell, int i, inout ShRgb acc, out float meanTransmission) {
  meanTransmission = 1.0;
  ivec3 n = cell + lpvOffset(i);
  if (!cellInside(n)) return;
  ShRgb src = ShRgb(sourceAt(0, n), sourceAt(1, n), sourceAt(2, n));
  // A neighbour without light adds exactly nothing: skip it (most cells in early steps). The skip
  // is a loop that runs at most once, not an if: llvmpipe runs both sides of an if for all the
  // lanes of a SIMD row, but leaves a loop as soon as none of its lanes is active, so a row of
  // cells whose neighbour is dark skips the face arithmetic and the occlusion entirely.
  const bool lit = !(src.r == vec4(0.0) && src.g == vec4(0.0) && src.b == vec4(0.0));
  for (int once = 0; lit && once < 1; ++once) {
    vec3 blockNormal;
    bool blocks = blocker(voxels[cellIndex(n)], -vec3(lpvOffset(i)), blockNormal);
    float sumT = 0.0;
    if (i == 0) { FACES(0, 1, 2, 3, 4, 5); }
    else if (i == 1) { FACES(1, 0, 2, 3, 4, 5); }
    else if (i == 2) { FACES(2, 0, 1, 3, 4, 5); }
    else if (i == 3) { FACES(3, 0, 1, 2, 4, 5); }
    else if (i == 4) { FACES(4, 0, 1, 2, 3, 5); }
    else { FACES(5, 0, 1, 2, 3, 4); }
    meanTransmission = sumT / 5.0;
  }
}

void main() {
  ivec3 c = u_probeMode == 1 ? u_probeCell : ivec3(gl_GlobalInvocationID);
  if (u_probeMode == 1 && gl_LocalInvocationIndex != 0u) return;
  if (!cellInside(c)) return;
  ShRgb acc = ShRgb(vec4(0.0), vec4(0.0), vec4(0.0));
  vec4 fromNeighbour[6];
  if (u_probeMode == 1) {
    for (int i = 0; i < 6; ++i) {
      float t;
      ShRgb own = ShRgb(vec4(0.0), vec4(0.0), vec4(0.0));
      gatherNeighbour(c, i, own, t);
      fromNeighbour[i] = vec4(own.r.x, own.g.x, own.b.x, t);
    }
  }
  // Literal neighbour indices (see addFace); the same order as the reference's loop.
  float t;
  gatherNeighbour(c, 0, acc, t);
  gatherNeighbour(c, 1, acc, t);
  gatherNeighbour(c, 2, acc, t);
  gatherNeighbour(c, 3, acc, t);
  gatherNeighbour(c, 4, acc, t);
  gatherNeighbour(c, 5, acc, t);
  const int cell = cellIndex(c), stride = cells();
  precise vec4 totalR = stateIn[cell] + acc.r;
  precise vec4 totalG = stateIn[stride + cell] + acc.g;
  precise vec4 totalB = stateIn[2 * stride + cell] + acc.b;
  if (u_probeMode == 0) {
    stateOut[cell] = totalR;
    stateOut[stride + cell] = totalG;
    stateOut[2 * stride + cell] = totalB;
    stateOut[3 * stride + cell] = acc.r;
    stateOut[4 * stride + cell] = acc.g;
    stateOut[5 * stride + cell] = acc.b;
    return;
  }
  vec4 total[3] = vec4[3](totalR, totalG, totalB);
  vec4 wave[3] = vec4[3](acc.r, acc.g, acc.b);
  LpvVoxel v = voxels[cellIndex(c)];
  probe.cell = ivec4(c, u_cascade);
  for (int ch = 0; ch < 3; ++ch) {
    probe.total[ch] = total[ch];
    probe.wavefront[ch] = wave[ch];
  }
  probe.voxel = uvec4(v.colorOcclusion, v.fragmentCount, uint(u_step + 1), 0u);
  probe.normals = v.normals;
  for (int i = 0; i < 6; ++i) probe.fromNeighbour[i] = fromNeighbour[i];
}
