// vct-grid: voxel cone tracing on a dense 3D texture.
//
// Intro
//   Global illumination by cone tracing (Crassin et al. 2011), in the simplest form: the scene is
//   voxelized into a dense grid, the grid is lit by the direct light, prefiltered into mip levels,
//   and every pixel gathers indirect light by marching a few wide cones through the mip levels.
//
// Overview (the stages, in order)
//   1. voxelize-static  the triangles no animation moves -> their voxel fragment list, once
//      voxelize       that list + the moving triangles' fragments -> the voxel fragment list
//                     (dominant axis, conservative; only this re-runs when an animated node moves)
//      triangle-axes  the triangles coloured by projection axis, from the camera (shared,
//                     common/voxelize_stage: the three voxelization stages)
//      light       the scene's first light after the light.0.* parameters (shared, common/light_stage)
//   2. shadow-map     depth from the light; the light's parameters as a uniform buffer
//   3. inject         Lambert direct light + emission per fragment, averaged per voxel (exact
//                     fixed-point sums with integer atomics; or the RGBA8 compare-and-swap average)
//   4. occlusion-fix  alpha = 1 in every non-empty voxel
//   5. mipmap         own compute pass per level: average of the 8 children (isotropic), and the
//                     six directional volumes (anisotropic, the default) the cones read; each
//                     level visits only the texels with a voxel fragment under them
//   6. bounce         bounces >= 2: each voxel fragment gathers the previous bounce's grid with a
//                     few diffuse cones, adds albedo x that to the injected radiance, re-mips
//                     (bounce#k, one iteration per bounce; nothing at the default bounces=1)
//   7. gbuffer        position, normal, albedo, emission, depth from the camera
//   8. cone-trace     diffuse cones (+AO), one specular cone, one soft-shadow cone per pixel
//   9. composite      direct + indirect diffuse + specular, tonemapped; each term an output
//
// Details
//   - Units: metres and the radiometric units of src/scene/light_model.h. The grids store outgoing
//     radiance as RGBA8 clamped to [0,1] by default; voxel.format=rgba16f keeps up to 64 (the
//     Cornell blocks' tops under the spot reach 4.6: what the clamp costs is in docs/fidelity.md).
//   - Diffuse cone weights sum to 1 (common/cone_layout.h), so under uniform incoming radiance L the
//     indirect diffuse term is exactly albedo * L: the white-furnace test in tests/ checks it.
//     (The 0.707-style weights in seed 000 and the blog's unweighted sum do not sum to 1.)
//   - Steps are half the sample diameter with opacity correction a' = 1 - (1 - a)^(step/diameter).
//   - Cones start cone.start-offset voxels off the surface (default 1.75, about a voxel diagonal).
//   - Defaults (chosen for fidelity, docs/fidelity.md): 6 cones of 45 degrees (at 60 the ring's outer cones
//     graze the surface and gather it), up to 1.75 volume edges, anisotropic mips, the voxels'
//     shadow test half a voxel along the fragment normal: 1.04 / 1.07 of the path tracer's
//     one-bounce energy on the Cornell box / Sponza.
//   - The voxelization geometry shader takes the plane normal from the triangle's positions (seed
//     003's listing subtracts a normal from a position there: a typo we do not reproduce).
//
// References
//   seed 000 (Gomes) section 2.1 (voxelization), 4.2.1 (VCT on a full grid); seed 003 (blog: the
//   minimal dense-grid VCT with 6 diffuse cones and 1 specular cone); Crassin, Neyret, Sainz,
//   Green, Eisemann, "Interactive Indirect Illumination Using Voxel Cone Tracing", 2011.
#include "graph/technique.h"
#include "techniques/common/gbuffer_stage.h"
#include "techniques/common/light_stage.h"
#include "techniques/common/shadow_map_stage.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/vct_grid/stages.h"

namespace voxlab {

static std::unique_ptr<Technique> makeVctGrid() {
  auto t = std::make_unique<Technique>(
      "vct-grid", "Voxel cone tracing on a dense grid",
      "Voxelize, inject direct light, prefilter into mips, then gather indirect light with cones.");
  addVoxelizeStages(*t);
  t->add<LightStage>();
  t->add<ShadowMapStage>();
  t->add<vct::InjectStage>();
  t->add<vct::OcclusionFixStage>();
  t->add<vct::MipmapStage>();
  t->add<vct::BounceStage>();
  t->add<GBufferStage>();
  t->add<vct::ConeTraceStage>();
  t->add<CompositeStage>(vct::compositeTerms());
  t->setFinalOutput("composite", "final");
  return t;
}

VOXLAB_REGISTER_TECHNIQUE("vct-grid", "Voxel cone tracing on a dense grid", makeVctGrid);

}  // namespace voxlab
