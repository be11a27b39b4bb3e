// The lrsm technique's decisions and CPU references (layered reflective shadow maps, Sugihara,
// Rauwendaal, Salvi, HPG 2014). Every choice the paper leaves open is fixed here, used by the
// stages and shaders with the same numbers, and tested in tests/unit/test_lrsm.cpp.
//
// Decisions (the paper does not state them; /work guide lrsm.md section 2 "Not given"):
//   storage        occlusion voxels: 1 byte per voxel (R8 UNORM, 0 or 1), as the paper allocates;
//                  isotropic mips are the mean of the 8 children, one compute pass per level.
//   layers         n = (a+1)(b+1): a = lrsm.depth-splits, b = lrsm.normal-splits; layer id =
//                  depthInterval * (b+1) + normalInterval.
//   boundaries     depth: a+1 equal intervals of [zNear, zFar], the depth range of the scene's
//                  bounds seen from the light; <n.l>: b+1 equal intervals of [0, 1].
//   light depth    directional: planar (distance along the light direction); spot: radial
//                  (distance from the light), so a sphere of radius r_c spans z_c +- r_c either way.
//   overlap        each texel is written to exactly one layer (the paper's section 5 wording); the
//                  overlap exists only at sampling: a layer's range is its interval grown by
//                  delta/2 at each inner boundary (delta = lrsm.overlap x interval width), none at
//                  zNear and zFar. Eq. 15's falloff k is smoothstep (or linear), both with
//                  k(t) + k(1-t) = 1, so the weights of the two layers sampled in an overlap sum to 1.
//   warp           z' = (z - zMin_l) / (zMax_l - zMin_l) over the layer's range (with its
//                  overlap), so z' in [0,1] for its texels; z_c and r_c are warped the same way
//                  before Eq. 12 (r' = r_c / (zMax_l - zMin_l)).
//   premultiplied  every layer texel holds alpha * value (alpha = texels of the layer in the 2x2
//                  block / 4): radiance rgb = A*R, a = alpha; normal xyz = alpha*n, w = alpha;
//                  depth (UNORM16) alpha*z'^k, k = 1..4 (alpha: the normal's .w). Box mips
//                  then keep sum over layers of A*R = the plain RSM's box mip (the sum identity).
//   variance floor sigma^2 >= lrsm.min-variance (warped units; default 1e-4, above the bound
//                  3 x (0.5/65535) / alpha = 9.2e-5 by which UNORM16 rounding of alpha z and alpha z^2
//                  can move E[z^2] - mu^2 at alpha = 1/4).
//   Eq. 12         Phi from erf (Abramowitz-Stegun 7.1.26, |error| < 1.5e-7) instead of a table.
//   two lobes      lrsm.two-lobes (default on): a layer's depths are read as two Gaussians matched to
//                  its first four moments where sigma^2 >= 0.01 (warped; blended in up to 0.03,
//                  below which UNORM16 rounding swamps the third and fourth central moments), each
//                  a surface of its own in the coverage estimator (mean point, horizon, V, Jacobian;
//                  the layer's normal and radiance shared): one Gaussian fitted to two surfaces
//                  (a box's top and the floor beyond its shadow) puts surface in the air between.
//   normal term    N = <n_mip/alpha . v_c> without renormalising n (Algorithm 1 divides by alpha only).
//   estimator      lrsm.estimator=coverage (default): what a sphere sample adds to Eq. 1 is
//                  T_i * sum_l A*R V <n.v> / <n.l>. Algorithm 1's sum A*R V N is already coverage
//                  times radiance (A V: the fraction of the sample's light-image footprint whose
//                  lit surface lies in its depth window); Eq. 3's Jacobian r^2 / <n.l> turns that
//                  light-image area into surface area and <n.v> projects it toward the receiver,
//                  so A V <n.v> / <n.l> is the fraction of the cone's cross-section the surface
//                  covers (summed over samples whose depth windows, half a step each side, tile
//                  the cone, an infinite plane counts once whatever its tilt). <n.l> is the
//                  layer's mean normal's, floored at 0.1 (LRSM_MIN_NDOTL); v points to the
//                  receiver from the layer's mean surface point (depth mu on the light ray
//                  through x_c), not from x_c. For a spot or point light the fraction is capped by
//                  the solid angle the footprint's surface can fill seen from the receiver,
//                  min(1, Omega z_s^2 t^2 / (pi r_c^2 d_s^2)) (Omega: the sphere's silhouette from
//                  the light; z_s the layer's mean depth; t, d_s: the sample's and that surface's
//                  distances from the receiver): a wide sphere whose footprint reaches the lamp's
//                  bright surroundings would otherwise lend them the whole cross-section. Eq. 1's alpha_i is the larger of the voxels'
//                  opacity and the lit surfaces' coverage, either facing (lrsm.lit-occlusion):
//                  a lit surface blocks what lies behind it, where a thin wall's isotropic mips
//                  let most through. lrsm.estimator=paper multiplies Algorithm 1's sum (window =
//                  the radius) by the voxels' alpha_i: coverage counted twice, 0.02-0.10 of
//                  the reference on the suite (docs/lrsm.md).
//   layers read    lrsm.layer-select=window (default): every layer whose texels' depth interval
//                  meets the sample's depth window, weight 1 (each texel lies in one layer, so
//                  this counts every texel in the window once); =overlap: Eq. 15's falloff over
//                  the layers whose range holds z_c, made for texels written to both layers of
//                  an overlap, which halves the light on a band around each depth boundary.
//   horizon        cone.horizon (default on): the receiver's plane bounds what its cones see.
//                  A radiance cone's occlusion lookup takes a finer mip where the coarse one's
//                  filter would reach the plane (a texel of edge s holding a surface voxel has
//                  its centre within s/2 + 1 voxel of the surface, the trilinear filter reaches
//                  one texel: s <= (h - voxel) / 1.5); layers whose mean surface point lies less
//                  than 2 voxels above the plane (LRSM_HORIZON_VOXELS) neither light nor block.
//   cones          6 diffuse cones of 60 degrees (full apex angle), one along the normal and five at
//                  60 degrees from it; weights pi * cos(tilt) / sum cos(tilt): each is proportional
//                  to the cone cap's exact cosine integral pi sin^2(half) cos(tilt), and they sum
//                  to pi, so E = sum w_k I_k and L_o = albedo/pi * E (white furnace exact). One
//                  specular cone of 10 degrees along the mirror direction; one shadow cone toward
//                  the light (cone.shadow-aperture, default 10 degrees so that it reaches across the
//                  volume within cone.max-steps). The direct light's visibility is the shadow map by
//                  default (composite.shadow): the shadow cone reads the isotropic mips of surface
//                  voxels, where a closed 20 cm slab is two one-voxel faces averaged with the empty
//                  voxels between them, and let about half of skylight-room's sun through its
//                  ceiling (direct light 16.8x the reference's). The specular cone is off by default
//                  (cone.specular): the paper traces it only for pixels with a specular component,
//                  and voxlab's materials are Lambertian.
//   samples        sphere radius r = t tan(half angle); step = cone.step x diameter (default 1:
//                  touching spheres, as Fig. 4 draws them; 0.5 measured 15 % darker, 1.7x slower); first sample at
//                  cone.start voxels; voxel mip = log2(diameter / voxel) + cone.lod-bias (voxel units;
//                  the shadow cone, Crassin's and not the paper's, uses cone.shadow-lod-bias, default
//                  -1: at 0 it read the boxes' one-voxel shells at coarse mips and saw through them,
//                  docs/fidelity.md);
//                  alpha corrected to the step: 1 - (1 - a)^(step / texel size at that mip).
//   interleave     cone.interleave (default on): each pixel of a 4 x 4 tile (Bayer order) starts its
//                  diffuse cones' samples at its own sixteenth of the first step, centred on
//                  cone.start, and the filter stage (the shared a-trous filter, 2 passes, 13 x 13
//                  traced pixels on the receiver's plane) averages the tile. With one start for every
//                  pixel the receivers of a flat face put their samples at the same heights above
//                  it, and the count of a surface whose depth window each sample meets jumps
//                  between neighbours the same way everywhere: swirls round the Cornell lamp (the
//                  ceiling's detail 0.072 against the reference's 0.033; 0.036 now), a dark patch on
//                  the tall box, and a roof over a sunlit floor at 1.45 of its exact light (1.09 now).
//   footprint      d_circle = diameter of the sphere projected into the light's image, in LRSM base
//                  texels; LRSM level = log2(d_circle) + lrsm.footprint-bias (default -1: the
//                  bilinear filter's support, two texels, equals the circle), fractional: the two
//                  neighbouring levels, each bilinear within the layer's tile, blended (an integer
//                  level switches along a receiver and draws rings).
//   layout         the n layers of one attribute lie side by side in one 2D texture (layer l covers
//                  x in [l W, (l+1) W)); a box mip of it is the per-layer box mip, since no 2x2
//                  block straddles two tiles while W is a power of two (semantic "lrsm-layers").
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace voxlab::lrsm {

inline constexpr int kMaxSplits = 3;
inline constexpr float kDefaultMinVariance = 1e-4f;
inline constexpr float kDiffuseAperture = 1.04719755f;   // 60 degrees, full apex angle
inline constexpr float kSpecularAperture = 0.17453293f;  // 10 degrees
inline constexpr int kDiffuseCones = 6;

// The static layer partition of one light.
struct LayerLayout {
  int depthSplits = 1;   // a
  int normalSplits = 1;  // b
  float zNear = 0.0f, zFar = 1.0f;
  float overlap = 0.25f;  // delta as a fraction of one depth interval

  int depthIntervals() const { return depthSplits + 1; }
  int normalIntervals() const { return normalSplits + 1; }
  int count() const { return depthIntervals() * normalIntervals(); }
  float intervalWidth() const { return (zFar - zNear) / float(depthIntervals()); }
  float delta() const { return overlap * intervalWidth(); }
  int depthIntervalOf(float z) const;
  int normalIntervalOf(float ndotl) const;
  // Layer id of an RSM texel at light depth z with <n.l> = ndotl.
  int classify(float z, float ndotl) const { return depthIntervalOf(z) * normalIntervals() + normalIntervalOf(ndotl); }
  // The sampling range [zMin_l, zMax_l] of depth interval d (grown by delta/2 at inner boundaries).
  void rangeOf(int d, float& zMin, float& zMax) const;
  // z warped into the range of depth interval d.
  float warp(int d, float z) const;
  // Eq. 15: the overlap falloff of depth interval d at sample depth z (0 outside its range).
  float falloff(int d, float z, bool smooth = true) const;
};

// k(t), clamped to [0,1]: smoothstep or linear; both satisfy k(t) + k(1 - t) = 1.
float falloffK(float t, bool smooth);

// Standard normal CDF by erf (the same approximation the shader uses) and Eq. 12.
float approxErf(float x);
float gaussianVisibility(float zc, float rc, float mu, float sigma2);
// Eq. 12 with std::erf, for the tests.
double gaussianVisibilityExact(double zc, double rc, double mu, double sigma2);

// A layer's depths as Gaussian lobes from its first four moments (E[z'^k], k = 1..4, warped),
// the formulas of shaders/lrsm/lrsm_common.glsl depthLobes: lobe 0 the single Gaussian (weight
// 1 - blend), lobes 1 and 2 two Gaussians of variance lambda sigma^2 matched to the mean, variance,
// skewness and kurtosis (weights blend q, blend (1 - q)); blend rises from 0 to 1 over sigma^2 in
// [kTwoLobeVariance, 3 kTwoLobeVariance]. count = 1 where only the single Gaussian is used.
inline constexpr float kTwoLobeVariance = 0.01f;  // LRSM_TWO_LOBE_VARIANCE
struct DepthLobes {
  int count = 1;
  float mean[3] = {0, 0, 0}, weight[3] = {1, 0, 0}, variance[3] = {1, 1, 1};
  float lambda = 1.0f;
};
DepthLobes depthLobes(const glm::vec4& moments, float minVariance);
// Eq. 12 summed over the lobes, weighted.
float lobeVisibility(const DepthLobes& lobes, float zc, float rc);

struct DiffuseCone {
  glm::vec3 direction;  // tangent space, z = normal
  float weight;         // sum over the cones = pi
};
std::vector<DiffuseCone> diffuseCones();
// Exact integral of cos(theta to the normal) over a cone cap of half angle 'half' whose axis is
// 'tilt' from the normal (cap above the horizon: tilt + half <= pi/2).
double capCosineIntegral(double half, double tilt);

// Bytes of the paper's layout (Table 1 / Table 2): occlusion res^3 x 1 B x 8/7; RSM 16 B x 4/3
// per texel; LRSM (rsm/2)^2 x 24 B x layers x 4/3.
struct PaperMemory {
  double occlusion, rsm, lrsm;
  double total() const { return occlusion + rsm + lrsm; }
};
PaperMemory paperMemory(int voxelResolution, int rsmResolution, int layers);

// "" when n layers of (rsm / 2)^2 texels fit side by side in one texture of at most maxTextureSize
// texels per side; else the one-line error the layers stage throws before allocating anything.
std::string atlasSizeError(int rsmResolution, int layers, int maxTextureSize);

// CPU reference of the layer build (one 2x2 block per base texel), for the tests: from the RSM's
// light depth, <n.l>, validity and radiance, the premultiplied base of every layer.
struct LayerBase {
  int width = 0;  // per layer; the atlas is width * layers x width
  int layers = 0;
  std::vector<glm::vec4> radiance, normal, depth;  // atlas order: (y * width * layers + l * width + x)
  std::vector<uint8_t> layerId;                    // per RSM texel
};
LayerBase buildLayersCpu(const LayerLayout& layout, int rsmSize, const std::vector<float>& depth,
                         const std::vector<float>& ndotl, const std::vector<glm::vec3>& normal,
                         const std::vector<glm::vec3>& radiance, const std::vector<uint8_t>& valid);

}  // namespace voxlab::lrsm
