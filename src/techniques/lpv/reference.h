// The CPU reference of lpv: binning voxel fragments into an LPV voxel grid, a point VPL, the
// propagation steps and the irradiance lookup, in the same fp32 maths as the shaders (sh.h is the
// twin of shaders/common/sh.glsl). The exact tests compare the GPU stages with these functions;
// the invariant tests of the technical note (guide/techniques/lpv.md section 4) run on them.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "common/shared.h"
#include "lpv/lpv_shared.h"
#include "techniques/lpv/sh.h"

namespace voxlab::lpv {

// SH per colour channel of every cell, index (z * res + y) * res + x.
struct ShField {
  int res = 0;
  std::vector<std::array<SH, 3>> cells;
  explicit ShField(int r = 0) : res(r), cells(size_t(r) * r * r, {SH(0.0f), SH(0.0f), SH(0.0f)}) {}
  size_t index(glm::ivec3 c) const { return (size_t(c.z) * res + c.y) * res + c.x; }
  bool inside(glm::ivec3 c) const { return glm::all(glm::greaterThanEqual(c, glm::ivec3(0))) && glm::all(glm::lessThan(c, glm::ivec3(res))); }
  std::array<SH, 3>& at(glm::ivec3 c) { return cells[index(c)]; }
  const std::array<SH, 3>& at(glm::ivec3 c) const { return cells[index(c)]; }
  glm::dvec3 flux() const;  // sum of c00 * 2 sqrt(pi) per channel
};

enum class Occlusion { TwoSided, Thesis, None, Front };
enum class Scheme { Wavefront, Thesis };
// The lobe a face's flux re-enters as: along the face's axis (K&D) or along the direction the light
// crossed the face (from the neighbour's centre to the face's centre), as a clamped-cosine lobe
// (travel) or as a narrow beam (shBeam, keeps the whole direction).
enum class Reprojection { FaceAxis, Travel, Beam };

struct PropagationSettings {
  Scheme scheme = Scheme::Wavefront;
  float weightScale = float(1.0 / kPi);  // flux-consistent 1/pi; thesis fluxAmplifier / (4 pi)
  bool clampFaces = true;                // max(0, .) of each face evaluation
  bool clampConserves = false;           // the clamped faces of a neighbour carry its unclamped flux
  Occlusion occlusion = Occlusion::TwoSided;
  float occlusionAmplifier = 1.0f;
  bool firstStepUnoccluded = true;
  Reprojection reprojection = Reprojection::FaceAxis;
};

// Transmission of the face evaluation along d of light leaving a cell whose voxel is 'v'
// towards the neighbour at -offset (travel direction 'travel'), at 'step'.
float faceTransmission(const gpu::LpvVoxel* v, const glm::vec3& travel, const glm::vec3& d,
                       const PropagationSettings& s, int step);

// One step: gathers into every cell from its 6 neighbours (5 faces each) of 'source'.
// wave = gathered light, total = totalIn + gathered. 'voxels' may be empty (no occlusion).
void propagateStep(const ShField& source, const ShField& totalIn, const std::vector<gpu::LpvVoxel>& voxels,
                   const PropagationSettings& s, int step, ShField& wave, ShField& total);

struct PropagationResult {
  ShField total, wave;
  std::vector<glm::dvec3> waveFlux, totalFlux;  // index 0: injected, k+1: after step k
};
PropagationResult propagate(const ShField& injected, const std::vector<gpu::LpvVoxel>& voxels,
                            const PropagationSettings& s, int steps);

// Gathered contribution of neighbour i to 'cell' in one step (the probe's per-neighbour record).
std::array<SH, 3> gatherFrom(const ShField& source, const std::vector<gpu::LpvVoxel>& voxels, glm::ivec3 cell,
                             int i, const PropagationSettings& s, int step);

// The five face evaluations of neighbour i for 'cell' (the probe record's faceIntensity/faceFlux):
// faces j in increasing order, the shared face skipped; all zero when the neighbour lies outside
// the grid or holds no light (the shader skips it). gatherFrom is the sum of flux * lobe(axis of j)
// over them in this order.
struct FaceTerm {
  int face = 0;                 // j
  glm::vec3 intensity{0.0f};    // per channel: <SH, Y(d)>, clamped at 0 by s.clampFaces
  float solidAngle = 0.0f;      // sr
  float transmission = 0.0f;
  glm::vec3 flux{0.0f};         // ((intensity * solid angle) * transmission) * weight scale
};
std::array<FaceTerm, 5> faceTerms(const ShField& source, const std::vector<gpu::LpvVoxel>& voxels, glm::ivec3 cell,
                                  int i, const PropagationSettings& s, int step);

// Bins voxel fragments (voxel coordinates packed 10:10:10, albedo RGBA8, normal snorm8) of a
// fragment voxel space (origin, voxel size, voxels per axis) into a grid at 'gridOrigin' with
// 'cellSize'; the area word counts each fragment's share of its voxel in 'areaUnits' per voxel^2.
struct FragmentRecord { uint32_t position, albedo, normal, emission; };
std::vector<gpu::LpvVoxel> binFragments(const std::vector<FragmentRecord>& fragments, glm::vec3 fragOrigin,
                                        float fragVoxel, int fragRes, glm::vec3 gridOrigin, float cellSize,
                                        int res, float areaUnits);

// --- Injection (shaders/lpv/inject.comp.glsl, inject_fragments.comp.glsl) ----------------------
// What inject reads besides the voxels: the light block and the shadow map's depths (texel (x, y)
// at y * width + x, as captured).
struct ShadowedLight {
  voxlab::gpu::GpuLight light;
  int width = 0, height = 0;
  std::vector<float> depth;
};
// Visibility of p (normal n) by the shadow map, as shaders/common/lights.glsl: 3x3 nearest taps with
// the light's normal offset. 'marginal' (may be null) is set when a tap's texel coordinate lies
// within 1e-4 texel of a texel edge or its depth within 1e-6 of the test's threshold: there the
// GPU's float rounding of the same expressions may decide a tap the other way.
float shadowVisibility(const ShadowedLight& l, glm::vec3 p, glm::vec3 n, bool* marginal);
glm::vec3 lightIrradiance(const voxlab::gpu::GpuLight& l, glm::vec3 p);
glm::vec3 directionToLight(const voxlab::gpu::GpuLight& l, glm::vec3 p);

// Injected VPLs of one cascade in double precision, and per cell the largest change of any of
// its coefficients that marginal shadow taps could make (the flux of the marginal fragments or
// cells at full visibility).
struct Injected {
  std::vector<std::array<glm::dvec4, 3>> sh;
  std::vector<double> marginal;
  size_t marginalCells = 0;
  std::vector<uint32_t> fragments;  // per fragment: the lit fragments summed into each cell
};
// inject.lighting=per-cell: each occupied cell lit once through its most light-facing normal.
Injected injectPerCell(const std::vector<gpu::LpvVoxel>& voxels, const gpu::LpvGrid& grid, const ShadowedLight& l,
                       float fragmentArea, float areaUnits);
// inject.lighting=per-fragment: every fragment lit at its voxel, summed into the cell its voxel
// centre lands in after moving 'shift' cells along its normal (inject.vpl-shift; exact sums: the
// GPU's fixed-point rounding is the caller's to bound).
Injected injectPerFragment(const std::vector<FragmentRecord>& fragments, glm::vec3 fragOrigin, float fragVoxel,
                           int fragRes, const gpu::LpvGrid& grid, const ShadowedLight& l, float areaUnits,
                           float shift);

// Trilinear SH at a point given in cell units (cell centres at i + 0.5), clamped to the edge texels.
std::array<SH, 3> sampleTrilinear(const ShField& f, glm::vec3 cellPos);

}  // namespace voxlab::lpv
