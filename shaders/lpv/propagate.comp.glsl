#version 450
// One propagation step (seed 000 section 4.3.3, Listings 4.32/4.33; K&D 2010), one invocation
// per column of cells along x, cell after cell. Each cell gathers from its 6 face neighbours, 5
// faces each (the shared face is skipped). For neighbour i and face j of this cell the
// neighbour's intensity towards the face centre, max(0, <SH, Y(d_ij)>), times the face's solid
// angle, its transmission and the weight scale is a flux that re-enters as a clamped-cosine lobe
// leaving through face j. Neighbours outside the grid are skipped (never read). The CPU twin is
// src/techniques/lpv/reference.cpp: same order. Built twice: as is for every column, and with LPV_PROBE defined as the program the stage runs as
// one invocation for the picked cell, which records the 30 face evaluations behind its gathered
// light (LpvProbe). The recording lives in its own program because llvmpipe runs a branch for all
// lanes of a SIMD row, so recording code behind a uniform would cost every cell.
#include "common/sh.glsl"
#include "lpv/encoding.glsl"
// Work groups of 8 x 4 columns (y, z); llvmpipe runs them as SIMD rows of 8 invocations (256-bit
// vectors), 8 columns side by side in y, which walk x in step. A column sums its cells' energy in
// registers as it goes, so the step's energy record needs no extra pass and no barrier. Against
// one invocation per cell (8 x 2 x 4 cells per work group, a work-group sum through shared memory
// and a barrier): the stage's 8 steps took 41-58 against 77-104 ms (docs/performance.md, lpv).
// 1024 invocations for 32^3 cells are few for a GPU, but a step there is microseconds either way.
// The stage dispatches with the same shape (kPropagateColumns).
layout(local_size_x = 8, local_size_y = 4, local_size_z = 1) in;
layout(std430, binding = LPV_BINDING_VOXELS) readonly buffer Voxels { LpvVoxel voxels[]; };
uniform ivec3 u_boxLo, u_boxHi;
#ifdef LPV_PROBE
layout(std430, binding = LPV_BINDING_PROBE) writeonly buffer Probe { LpvProbe probe; };
uniform ivec3 u_probeCell;
uniform int u_cascade;
#endif
// The state lives in buffers (llvmpipe loads and stores them far faster than images); the stage
// copies each step's result into the output volumes. Section s of a state holds cells s * res^3...:
// 0-2 light r, g, b (what the lookup reads), 3-5 wavefront r, g, b.
layout(std430, binding = LPV_BINDING_STATE_IN) readonly buffer StateIn { vec4 stateIn[]; };
layout(std430, binding = LPV_BINDING_STATE_OUT) writeonly buffer StateOut { vec4 stateOut[]; };
uniform int u_step;
uniform float u_weightScale;       // 1/pi (flux-consistent) or fluxAmplifier/(4 pi) (thesis)
uniform float u_occlusionAmplifier;
// The propagation's choices, fixed per program (the stage's defines): llvmpipe runs both sides of a
// branch on a uniform, so as uniforms every cell also paid for the modes not chosen.
const int kThesisScheme = LPV_THESIS_SCHEME;                 // 1: propagate everything so far; 0: only the last wavefront
const int kClampFaces = LPV_CLAMP_FACES;                     // 1: max(0, .) on each face's evaluation
const int kClampConserves = LPV_CLAMP_CONSERVES;             // 1: the clamped faces of a neighbour carry its unclamped flux
const int kOcclusion = LPV_OCCLUSION;                        // 0 two-sided, 1 thesis, 2 none, 3 front
const int kFirstStepUnoccluded = LPV_FIRST_STEP_UNOCCLUDED;  // 1: step 0 ignores the voxels
const int kReprojection = LPV_REPROJECTION;                  // 0: lobe along the face's axis (K&D); 1: along the direction the light crossed it; 2: a beam along it

// Whether the voxels block at all in this step (the same for every cell).
bool occlusionOn() { return kOcclusion != 2 && !(u_step == 0 && kFirstStepUnoccluded == 1); }
// The stored normal an occupied source cell blocks with: the one nearest the travel direction
// (two-sided: nearest up to sign), empty channels skipped (none stored: the zero vector).
vec3 blockNormal(uvec4 normals, vec3 travel) {
  vec3 best = vec3(0.0);
  float bestDot = -1e30;
  for (int c = 0; c < 4; ++c) {
    uint m = normals[c];
    if (m == 0u) continue;
    vec3 n = decodeNormalMask(m);
    precise float t = (n.x * travel.x + n.y * travel.y) + n.z * travel.z;
    if ((kOcclusion == 0 && t < 0.0) || kOcclusion == 3) { n = -n; t = -t; }
    if (t > bestDot) { bestDot = t; best = n; }
  }
  // front: no stored surface faces the light (it leaves the fronts of all of them): nothing blocks.
  if (kOcclusion == 3 && !(bestDot > 0.0)) best = vec3(0.0);
  return best;
}
// Transmission along d: 1 - clamp(A <lobe(n), Y(d)>).
float transmission(vec3 n, vec3 d) {
  if (kOcclusion == 3 && n == vec3(0.0)) return 1.0;  // front: nothing faces the light
  precise float blocked = u_occlusionAmplifier * shEvaluate(shLobe(n), d);
  return 1.0 - min(max(blocked, 0.0), 1.0);
}

int cells() { return u_gridRes * u_gridRes * u_gridRes; }
vec4 sourceAt(int ch, int index) { return stateIn[(kThesisScheme == 1 ? ch : 3 + ch) * cells() + index]; }

// The three colour channels as named members: no array indexed in a loop, so llvmpipe keeps them
// in registers.
struct ShRgb { vec4 r, g, b; };

// One channel of one face: e = the neighbour's intensity towards the face, f = the flux through it.
// The flux re-enters as a clamped-cosine lobe along the face's axis oj (K&D: a VPL at the cell's
// centre shining through face j), or with lpv.reprojection=travel along d, the direction it
// crossed the face in (from the neighbour's centre to the face's centre).
vec4 faceChannel(vec4 acc, vec4 src, vec3 d, float omega, float occ, float scale, ivec3 oj, out float e, out float f) {
  e = shEvaluateSparse(src, d);
  if (kClampFaces == 1) e = max(e, 0.0);
  precise float flux = (((e * omega) * occ) * u_weightScale) * scale;
  f = flux;
  if (kReprojection == 1) {
    precise vec4 r = acc + flux * shLobe(d);
    return r;
  }
  if (kReprojection == 2) {
    precise vec4 r = acc + flux * shBeam(d);
    return r;
  }
  return shAddAxisLobe(acc, flux, oj);
}

// Face j of this cell (the k-th of neighbour i's five), lit from neighbour i (src: its SH per
// channel) through transmission occ. Called with literal i, j and k (the NEIGHBOUR lists below), so
// after inlining the direction, solid angle and lobe axis are constants and the sparse evaluations
// lose their zero terms and branches: the same operations in the same order as the loop of the CPU
// reference (bit-identical).
void addFace(ShRgb src, int i, int j, int k, float occ, vec3 scale, inout ShRgb acc) {
  vec3 d = lpvFaceDirection(i, j);
  float omega = lpvFaceSolidAngle(i, j);
  ivec3 oj = lpvOffset(j);
  vec3 e, f;
  acc.r = faceChannel(acc.r, src.r, d, omega, occ, scale.r, oj, e.r, f.r);
  acc.g = faceChannel(acc.g, src.g, d, omega, occ, scale.g, oj, e.g, f.g);
  acc.b = faceChannel(acc.b, src.b, d, omega, occ, scale.b, oj, e.b, f.b);
#ifdef LPV_PROBE
  probe.faceIntensity[5 * i + k] = vec4(e, omega);
  probe.faceFlux[5 * i + k] = vec4(f, occ);
#endif
}

// lpv.clamp-conserves: the factor on a source cell's clamped face fluxes (one channel) that makes
// the 30 faces it lights (5 in each of its 6 neighbours) carry the flux of the unclamped 30,
// sum omega e (0 where that is not positive), so the clamp keeps intensities non-negative without
// adding flux. The same for every receiver of the source.
float conserveScale(vec4 src) {
  precise float signedFlux = 0.0, clampedFlux = 0.0;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      if (j == i) continue;
      float e = shEvaluate(src, lpvFaceDirection(i, j));
      float omega = lpvFaceSolidAngle(i, j);
      precise float a = signedFlux + e * omega;
      precise float b = clampedFlux + max(e, 0.0) * omega;
      signedFlux = a;
      clampedFlux = b;
    }
  return clampedFlux > 0.0 ? max(signedFlux, 0.0) / clampedFlux : 0.0;
}
vec3 conserveScales(ShRgb src) {
  if (kClampConserves == 0 || kClampFaces == 0) return vec3(1.0);
  return vec3(conserveScale(src.r), conserveScale(src.g), conserveScale(src.b));
}

// Neighbour I's five faces J0 < ... < J4 (the shared face left out; the reference's order). The
// five transmissions stay 1 unless the neighbour's voxel blocks; they are computed in a loop that
// runs at most once, which llvmpipe leaves at once for a SIMD row without a blocking lane (most
// rows: the voxels are a thin shell), where an if would compute them for every lane. Multiplying
// by a transmission of exactly 1 changes nothing, so the result is the reference's either way.
#define NEIGHBOUR(I, J0, J1, J2, J3, J4)                                        \
  {                                                                             \
    float t0 = 1.0, t1 = 1.0, t2 = 1.0, t3 = 1.0, t4 = 1.0;                     \
    for (int o = 0; blocks && o < 1; ++o) {                                     \
      vec3 bn = blockNormal(voxels[index].normals, -vec3(lpvOffset(I)));        \
      t0 = transmission(bn, lpvFaceDirection(I, J0));                           \
      t1 = transmission(bn, lpvFaceDirection(I, J1));                           \
      t2 = transmission(bn, lpvFaceDirection(I, J2));                           \
      t3 = transmission(bn, lpvFaceDirection(I, J3));                           \
      t4 = transmission(bn, lpvFaceDirection(I, J4));                           \
    }                                                                           \
    const vec3 scale = conserveScales(src);                                     \
    addFace(src, I, J0, 0, t0, scale, acc);                                     \
    addFace(src, I, J1, 1, t1, scale, acc);                                     \
    addFace(src, I, J2, 2, t2, scale, acc);                                     \
    addFace(src, I, J3, 3, t3, scale, acc);                                     \
    addFace(src, I, J4, 4, t4, scale, acc);                                     \
    meanTransmission = ((((t0 + t1) + t2) + t3) + t4) / 5.0;                    \
  }

void gatherNeighbour(ivec3 cell, int i, inout ShRgb acc, out float meanTransmission) {
  meanTransmission = 1.0;
  ivec3 n = cell + lpvOffset(i);
  if (!cellInside(n)) return;
  const int index = cellIndex(n);
  ShRgb src = ShRgb(sourceAt(0, index), sourceAt(1, index), sourceAt(2, index));
  // A neighbour without light adds exactly nothing: skip it (most cells in early steps). The skip
  // is a loop that runs at most once, not an if: llvmpipe runs both sides of an if for all the
  // lanes of a SIMD row, but leaves a loop as soon as none of its lanes is active, so a row of
  // cells whose neighbour is dark skips the face arithmetic and the occlusion entirely.
  const bool lit = !(src.r == vec4(0.0) && src.g == vec4(0.0) && src.b == vec4(0.0));
  for (int once = 0; lit && once < 1; ++once) {
    const bool blocks = occlusionOn() && decodeOccupied(voxels[index].colorOcclusion);
    if (i == 0) NEIGHBOUR(0, 1, 2, 3, 4, 5)
    else if (i == 1) NEIGHBOUR(1, 0, 2, 3, 4, 5)
    else if (i == 2) NEIGHBOUR(2, 0, 1, 3, 4, 5)
    else if (i == 3) NEIGHBOUR(3, 0, 1, 2, 4, 5)
    else if (i == 4) NEIGHBOUR(4, 0, 1, 2, 3, 5)
    else NEIGHBOUR(5, 0, 1, 2, 3, 4)
  }
}

// The cell's step: gather from the six neighbours (literal indices, see addFace; the reference's
// order), add to what the lookup read before. Returns the wavefront in acc.
void propagateCell(ivec3 c, out ShRgb acc, out ShRgb total) {
  acc = ShRgb(vec4(0.0), vec4(0.0), vec4(0.0));
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
  total = ShRgb(totalR, totalG, totalB);
}

#ifdef LPV_PROBE
void main() {
  ivec3 c = u_probeCell;
  if (gl_LocalInvocationIndex != 0u) return;
  if (!cellInside(c)) return;
  float t;
  for (int f = 0; f < 30; ++f) probe.faceIntensity[f] = probe.faceFlux[f] = vec4(0.0);
  for (int i = 0; i < 6; ++i) {
    ShRgb own = ShRgb(vec4(0.0), vec4(0.0), vec4(0.0));
    gatherNeighbour(c, i, own, t);
    probe.fromNeighbour[i] = vec4(own.r.x, own.g.x, own.b.x, t);
  }
  ShRgb acc, total;
  propagateCell(c, acc, total);
  const int cell = cellIndex(c);
  probe.cell = ivec4(c, u_cascade);
  probe.total[0] = total.r;
  probe.total[1] = total.g;
  probe.total[2] = total.b;
  probe.wavefront[0] = acc.r;
  probe.wavefront[1] = acc.g;
  probe.wavefront[2] = acc.b;
  probe.voxel = uvec4(voxels[cell].colorOcclusion, voxels[cell].fragmentCount, uint(u_step + 1), 0u);
  probe.normals = voxels[cell].normals;
  probe.weight = vec4(u_weightScale, 0.0, 0.0, 0.0);
}
#else
layout(std430, binding = LPV_BINDING_ENERGY_PARTIALS) writeonly buffer EnergyPartials { vec4 energyPartials[]; };

// The step's energy record, summed where the values are: each column adds its cells' c00 (light
// and wavefront, per channel) in x order and writes one partial pair; the stage adds the partials in
// column order (deterministic, whatever the thread count).
void main() {
  // The dispatch covers the columns of the box of cells that can hold light after this step (the
  // stage's u_boxLo..u_boxHi, within the grid); the other cells stay 0 in both states. Columns past
  // the box write zero partials.
  ivec2 yz = u_boxLo.yz + ivec2(gl_GlobalInvocationID.xy);
  precise vec3 light = vec3(0.0), wave = vec3(0.0);
  if (all(lessThanEqual(yz, u_boxHi.yz))) {
    for (int x = u_boxLo.x; x <= u_boxHi.x; ++x) {
      ivec3 c = ivec3(x, yz);
      ShRgb acc, total;
      propagateCell(c, acc, total);
      const int cell = cellIndex(c), stride = cells();
      stateOut[cell] = total.r;
      stateOut[stride + cell] = total.g;
      stateOut[2 * stride + cell] = total.b;
      stateOut[3 * stride + cell] = acc.r;
      stateOut[4 * stride + cell] = acc.g;
      stateOut[5 * stride + cell] = acc.b;
      light += vec3(total.r.x, total.g.x, total.b.x);
      wave += vec3(acc.r.x, acc.g.x, acc.b.x);
    }
  }
  const uint column = gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * gl_WorkGroupSize.x) + gl_GlobalInvocationID.x;
  energyPartials[2u * column] = vec4(light, 0.0);
  energyPartials[2u * column + 1u] = vec4(wave, 0.0);
}
#endif
