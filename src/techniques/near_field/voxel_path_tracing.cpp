// voxel-path-tracing: diffuse paths of several bounces on near-field's binary voxels.
//
// Intro
//   The binary voxel hierarchy answers "where does this ray first meet the scene?" cheaply, so it
//   can carry whole paths, not just one short ray: from each pixel a path bounces diffusely through
//   the voxels, and wherever the light's reflective shadow map sees a path vertex lit, that
//   vertex's reflected radiance flows back along the path, attenuated by the albedos it met.
//
// Overview (the stages, in order)
//   1. voxelize, binary-voxels, bitmask-tables, hierarchy   as in near-field
//   2. voxel-attributes   an albedo and a normal per voxel (for vertices the RSM does not see)
//   3. shadow-map, rsm, gbuffer                              as in near-field
//   4. paths              one bounce of one path per iteration (paths.count x paths.bounces)
//   5. filter, composite                                     as in near-field
//
// Details
//   - Seed 000 section 3.2.4 describes the method only in outline: per bounce, hit positions,
//     direct radiance from the RSM where the hit is lit, normal and BRDF from the RSM or else the
//     voxel texture, then radiance propagated backwards. Its propagation formula is not given; the
//     one used here, accumulated forward, is L = sum_k W_k L~_k with W_k the product of the albedos
//     of the earlier vertices (cosine-distributed bounces of Lambertian surfaces), which equals the
//     backward recursion L_k = L~_k + rho_k L_{k+1} path by path.
//   - The RSM holds reflected radiance, not albedo, so a vertex's albedo always comes from the
//     voxel grid (atomic max of its fragments' packed albedos: one of them, not an average).
//   - No radius: a bounce's ray runs to the volume's edge. With paths.bounces = 1 the estimator is
//     near-field's with an unlimited radius (tests/unit/test_near_field.cpp compares them).
//   - Direct light at the pixel itself is composite's, as in near-field; emission is not carried.
//   - What it is compared with: paths of K = paths.bounces bounces carry light reflected 2..K+1
//     times (r in the reference's counting), so `indirect` and `indirect-filtered` declare the
//     reference mode "indirect-{paths.bounces}" (indirect-K, resolved against the run's parameters;
//     OutputDesc::referenceMode), not the all-bounce "indirect": a K-bounce estimate is not charged
//     for the bounces it does not trace. `combined` is compared with `full`, as every technique's.
//   - Sky (sky.radiance, shaders/common/sky.glsl): a bounce whose ray crosses the volume without a
//     hit ends the path in the sky: it adds L times the albedos of the path's vertices so far (the
//     sky reflected once per vertex).
//
// References
//   seed 000 (Gomes) section 3.2.4 (voxel path tracing, after Thiedemann et al. 2011); the
//   near-field references in near_field.cpp.
#include "graph/technique.h"
#include "techniques/common/binary_voxels_stage.h"
#include "techniques/common/gbuffer_stage.h"
#include "techniques/common/rsm_stage.h"
#include "techniques/common/light_stage.h"
#include "techniques/common/shadow_map_stage.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/near_field/stages.h"

namespace voxlab {

static std::unique_ptr<Technique> makeVoxelPathTracing() {
  auto t = std::make_unique<Technique>(
      "voxel-path-tracing", "Voxel path tracing on binary voxels",
      "Diffuse paths of several bounces through the binary voxel hierarchy, lit where the RSM sees their vertices.");
  addVoxelizeStages(*t);
  t->add<BinaryVoxelsStage>();
  t->add<nearfield::VoxelAttributesStage>();
  t->add<nearfield::BitmaskTablesStage>();
  t->add<nearfield::HierarchyStage>();
  t->add<LightStage>();
  t->add<ShadowMapStage>();
  t->add<RsmStage>();
  t->add<GBufferStage>();
  t->add<nearfield::PathsStage>();
  t->add<AtrousFilterStage>(nearfield::filterConfig("indirect-{paths.bounces}", "paths.count"));
  t->add<CompositeStage>(nearfield::compositeTerms());
  t->setFinalOutput("composite", "final");
  return t;
}

VOXLAB_REGISTER_TECHNIQUE("voxel-path-tracing", "Voxel path tracing on binary voxels", makeVoxelPathTracing);

}  // namespace voxlab
