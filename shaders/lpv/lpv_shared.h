// Layouts and binding points of the lpv technique, included by C++ (src/techniques/lpv) and GLSL
// (shaders/lpv) alike so the two sides cannot disagree. std430: the uvec4 of LpvVoxel is 16-byte
// aligned, so the record is 32 bytes (the thesis' {uint; uvec4} is 32 bytes in std430 too, not 20).
#ifndef VOXLAB_LPV_SHARED_H
#define VOXLAB_LPV_SHARED_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace voxlab::lpv::gpu {
using vec4 = glm::vec4;
using ivec4 = glm::ivec4;
using uvec4 = glm::uvec4;
using uint = uint32_t;
#endif

#define LPV_BINDING_VOXELS 10      // SSBO: LpvVoxel[res^3] of the cascade being processed
#define LPV_BINDING_SCRATCH 11     // SSBO: a pass's small counter (bin: fragments outside; inject: largest coefficient)
#define LPV_BINDING_PROBE 12       // SSBO: LpvProbe (one record)
#define LPV_BINDING_GRIDS 13       // SSBO: LpvGrid[2] (fine, coarse)
#define LPV_BINDING_STATE_IN 14    // SSBO: vec4[6][res^3] propagation state read (light r,g,b, wavefront r,g,b)
#define LPV_BINDING_STATE_OUT 15   // SSBO: the same, written
#define LPV_BINDING_VOXEL_FRAGMENTS 16  // SSBO: uint[voxel.resolution^3], fragments per voxel of the fragment list
#define LPV_BINDING_ENERGY_PARTIALS 17  // SSBO: vec4[2 per column] c00 sums (light, wavefront) of a propagation step

// One cell of an LPV voxel grid (Listings 4.27-4.29 of seed 000, plus a fragment count).
struct LpvVoxel {
  uint colorOcclusion;  // bits 0-7 B, 8-15 G, 16-23 R (linear albedo, 8 bit), 24-30 contrast*127, 31 occupied
  uint fragmentCount;   // voxel fragments binned into the cell (surface area = count * fragment voxel^2)
  uint cell;            // the cell's own coordinates packed 10:10:10 (for point views)
  uint area;            // surface area in the cell, in u_areaUnits per fragment voxel^2 (see fragmentAreaUnits)
  uvec4 normals;        // one normal mask per tetrahedron channel (0 = empty): dot field 27-31, x 18-26, y 9-17, z 0-8
};

// One cell of the propagate stage's occlusion view: the transmission of light leaving the cell
// head on through its far face, 1 - clamp(A (0.25 + 0.5 n.d)) with the stored normal the
// propagation picks for that direction (from step 1 on; step 0 is unoccluded by default).
struct LpvOcclusion {
  uint cell;            // the cell's coordinates packed 10:10:10
  uint occupied;        // 1: the cell's voxel is occupied (only occupied cells block)
  uint pad0;
  uint pad1;
  vec4 plus;            // xyz: transmission of light travelling along +x, +y, +z; w: the least of the six
  vec4 minus;           // xyz: along -x, -y, -z; w: the mean of the six
};

// Placement of one cascade: cell i covers origin + [i, i+1) * cellSize.
struct LpvGrid {
  vec4 originCell;      // xyz: world minimum corner (a multiple of the cell size), w: cell size (m)
  vec4 centreRes;       // xyz: unsnapped centre the grid follows, w: cells per axis
};

// Per propagation step and cascade: flux of the wavefront and of what the lookup uses (sum over
// cells of c00 * 2 sqrt(pi) per colour channel).
struct LpvEnergy {
  vec4 wavefront;       // rgb: flux that moved in this step (step 0: the injected VPLs), a: step
  vec4 total;           // rgb: flux of the grid the lookup reads after this step, a: cascade
};

// A world box of the gi stage's "cascade-boxes" record (fine, coarse, blend shell start and end).
struct LpvBox {
  vec4 lo;              // xyz: minimum corner (m), w: 0 fine, 1 coarse, 2 shell start (coarse weight 0), 3 shell end (1)
  vec4 hi;              // xyz: maximum corner (m), w: cell size of the cascade it belongs to (m)
};

// The picked cell (probe.cell-x/y/z, probe.cascade) after the current step.
struct LpvProbe {
  ivec4 cell;           // xyz: cell, w: cascade
  vec4 total[3];        // SH (c00, c1-1, c10, c11) per colour channel (r, g, b) the lookup reads
  vec4 wavefront[3];    // SH per channel of the wavefront after the step
  uvec4 voxel;          // x: colorOcclusion, y: fragmentCount, z: step, w: 0
  uvec4 normals;        // the four normal masks
  vec4 fromNeighbour[6];  // rgb: c00 gained from neighbour +x,-x,+y,-y,+z,-z in this step; a: its mean face transmission
  // The 30 face evaluations behind fromNeighbour, [5 * i + k]: neighbour i, its k-th face j of this
  // cell in increasing j with the shared face (j = i) skipped. A dark or outside neighbour's are 0.
  vec4 faceIntensity[30]; // rgb: the neighbour's intensity towards face j's centre (W/sr; clamped at 0 by
                          // lpv.clamp-faces), a: the face's solid angle seen from the neighbour (sr)
  vec4 faceFlux[30];      // rgb: flux through face j = ((intensity * solid angle) * transmission) * weight (W),
                          // which re-enters as flux * lobe(axis of j): c00 += flux * sqrt(pi) / 2; a: transmission
  vec4 weight;            // x: the weight scale (1/pi, or lpv.flux-amplifier / 4 pi), yzw: 0
};

#ifdef __cplusplus
}  // namespace voxlab::lpv::gpu
#endif
#endif  // VOXLAB_LPV_SHARED_H
