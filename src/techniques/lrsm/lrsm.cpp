// lrsm: layered reflective shadow maps for voxel-based indirect light (Sugihara, Rauwendaal,
// Salvi, HPG 2014).
//
// Intro
//   Voxel cone tracing with the voxel data split in two. Occlusion is a binary voxel grid (1 byte
//   per voxel, no colour) with isotropic 3D mips: it gives each sphere sample of a cone its
//   opacity alpha_i. The light a sample sends does not come from voxels: it is read from the
//   light's reflective shadow map, split into layers by static depth and <n.l> partitions, each
//   layer box-mipped with its coverage, mean normal and the first two moments of its (warped)
//   depth. A sample projected into the light's image takes, from each layer whose depth range
//   holds it, the pre-filtered reflected radiance times a Gaussian estimate of how much of that
//   surface lies inside the sphere (Eq. 12) times a back-face term. One bounce, diffuse and
//   glossy, with far less memory than a radiance voxel grid.
//
// Overview (the stages, in order)
//   1. voxelize          triangles -> conservative voxel fragment list (shared: voxelize-static,
//                        voxelize, triangle-axes)
//   2. occlusion-voxels  fragments -> R8 3D texture, 1 byte per voxel (plain stores)
//   3. occlusion-mips    isotropic mips, mean of 8 children; one level per iteration
//   4. shadow-map        depth from the light and the light's parameters (shared)
//   5. rsm               position, normal, reflected radiance albedo/pi * E <n.l> (shared)
//   6. layers            one thread per 2x2 RSM block: layer id per texel, merged premultiplied
//                        texels, warped z and z^2 (LRSM base at RSM/2 per axis)
//   7. lrsm-mips         box mips of every layer and the sum of coverage; one level per iteration
//   8. gbuffer           position, normal, albedo from the camera (shared)
//   9. cone-gather       6 x 60 deg diffuse, 1 x 10 deg specular and 1 shadow cone per pixel:
//                        Eq. 1 with, per sample, the lit surface's coverage x radiance from the
//                        layers (Algorithm 1's terms and Eq. 3's Jacobian) and alpha the larger
//                        of the occlusion mips' and the lit coverage
//  10. filter            the shared edge-aware a-trous filter (2 passes) over the gathered light:
//                        it averages the 4 x 4 tile of step phases that cone.interleave spreads
//  11. composite         direct (shadow map; the shadow cone as a variant) + indirect diffuse, tonemapped
//
// Details
//   - Every decision the paper leaves open is listed, with its constant, in lrsm.h (layers,
//     boundaries, light depth, overlap and falloff k, warp of z_c and r_c, premultiplied storage,
//     variance floor, Eq. 12 by erf, the estimator, the layers read, the receiver's horizon,
//     cone weights, step and alpha correction, footprint to level); docs/lrsm.md says why and
//     what each measured.
//   - Sum identity: texels go to exactly one layer and are stored premultiplied, so summed over
//     the layers, LRSM level m equals the plain RSM's 2x2 box mip at level m + 1 (tested).
//   - Equation 12 uses z_c and r_c warped into the layer's range, the units mu and sigma^2 are in.
//   - The atlas: a layer of an attribute is a tile of one 2D texture (layers side by side), so
//     the mips of all layers are one dispatch per level and capture reads them like any image;
//     the lrsm-layer-* visualisers (src/techniques/lrsm/views/lrsm_layers.cpp) show tiles, mu, sigma.
//   - Probe: for the probed pixel, every sphere sample (cone-samples) and, per sample and layer,
//     the whole of Algorithm 1 (gather-records: in range, f, N, mu, sigma^2, V, A*R, contribution),
//     and per cone its I and weight (cone-results). They are written by a second program of the
//     gather (the recorder, common/probe_recorder.glsl: one invocation that gathers the probed pixel again): behind a
//     per-pixel flag, llvmpipe made every pixel pay for the records' stores (about 15 %).
//   - The gather pays only for the layers a sample reads: it loops over the depth intervals from
//     the first to the last its window meets (llvmpipe runs a loop's body for every lane until
//     none is left in it, and both sides of every branch), reads a layer's radiance once before
//     its lobes, and runs the two-lobe fit's bisection only where a layer holds two surfaces.
//   - Memory: the voxel grid, RSM and LRSM as the paper lays them out are in the cone-gather
//     statistics (paper_layout_*_mb); what voxlab allocates is what `voxlab bench` lists per
//     resource (the RSM here is RGBA32F position + RGBA16F normal/radiance + flux, not mipped).
//   - Not reproduced: sparse storage of the voxel grid; per-frame temporal clamping of the LRSM
//     mip (SRS14 section 7); several lights (one LRSM per light).
//
// References
//   seed 001 (Sugihara, Rauwendaal, Salvi, "Layered Reflective Shadow Maps for Voxel-based
//   Indirect Illumination", HPG 2014): section 3.1 (Eq. 1), 3.2 (binary voxels, G-buffer),
//   Eqs. 2-15, section 4.3 (layers), section 5 with Algorithm 1, section 6 Tables 1-3, section 7;
//   seed 000 (Gomes) section 2.2 (RSM) and 3.3 (LRSM summary); Lauritzen and McCool, layered
//   variance shadow maps (2008); Donnelly and Lauritzen, variance shadow maps (2006); Crassin
//   et al., cone-traced soft shadows (2011).
#include "graph/technique.h"
#include "techniques/common/atrous_filter_stage.h"
#include "techniques/common/gbuffer_stage.h"
#include "techniques/common/rsm_stage.h"
#include "techniques/common/light_stage.h"
#include "techniques/common/shadow_map_stage.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/lrsm/stages.h"

namespace voxlab {

static std::unique_ptr<Technique> makeLrsm() {
  auto t = std::make_unique<Technique>(
      "lrsm", "Layered reflective shadow maps",
      "Binary occlusion voxels with isotropic mips; a per-light layered RSM with depth moments; cone sphere samples "
      "take alpha from the voxels and radiance from the layers (Gaussian depth visibility).");
  addVoxelizeStages(*t);
  t->add<lrsm::OcclusionVoxelsStage>();
  t->add<lrsm::OcclusionMipsStage>();
  t->add<LightStage>();
  t->add<ShadowMapStage>();
  t->add<RsmStage>();
  t->add<lrsm::LayersStage>();
  t->add<lrsm::LrsmMipsStage>();
  t->add<GBufferStage>();
  t->add<lrsm::ConeGatherStage>();
  t->add<AtrousFilterStage>(lrsm::filterConfig());
  t->add<CompositeStage>(lrsm::compositeTerms());
  t->setFinalOutput("composite", "final");
  return t;
}

VOXLAB_REGISTER_TECHNIQUE("lrsm", "Layered reflective shadow maps", makeLrsm);

}  // namespace voxlab
