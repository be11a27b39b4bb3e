// near-field: near-field indirect light from a binary voxel model (Thiedemann et al. 2011).
//
// Intro
//   One bounce of indirect light within a radius, with occlusion, from a binary voxel grid: the
//   scene's voxels are bits in a 2D texture of 128-bit columns, a 2D OR mip hierarchy of those
//   columns lets a ray skip empty space, and each pixel shoots a few cosine-distributed rays of
//   limited length through it. Where a ray hits a voxel, the hit is looked up in the light's
//   reflective shadow map: if the RSM sees that very surface, its reflected radiance is the light
//   arriving along the ray.
//
// Overview (the stages, in order)
//   1. voxelize        triangles -> conservative voxel fragment list (shared with vct-grid:
//                      voxelize-static, voxelize, triangle-axes)
//   2. binary-voxels   fragments -> RGBA32UI columns, one bit per slice (imageAtomicOr; shared)
//   3. bitmask-tables  OR[k], XOR[k] (129 entries) on the CPU; ray masks XOR[i]^XOR[j+1] on the GPU
//   4. hierarchy       2D OR mips, all 128 slices kept, one level per iteration
//      light       the scene's first light after the light.0.* parameters (shared, common/light_stage)
//   5. shadow-map      depth from the light and the light's parameters (shared)
//   6. rsm             position, normal, reflected radiance and flux seen from the light (shared)
//   7. gbuffer         position, normal, albedo from the camera (vct-grid's stage)
//   8. rays            one ray index per iteration: direction, offsets, traversal, RSM lookup, sum
//   9. filter          edge-aware a-trous passes over the indirect light, one per iteration, as many
//                      as the rays per pixel need (shared: common/atrous_filter_stage)
//  10. composite       direct + filtered indirect, tonemapped
//
// Details
//   - Bit order: slice k = bit 31 - (k & 31) of channel k >> 5 (MSB first), as GP3's OR table and
//     its voxel visualiser have it; slices run along the voxel volume's +z axis, which is the
//     voxelization axis (src/techniques/common/binary_voxels_stage.h).
//   - Estimator: directions are cosine distributed (pdf cos/pi) within the part of the hemisphere
//     that rays.spread keeps (pdf cos/(pi spread)), so the outgoing radiance of a Lambertian
//     receiver is L_o = (rho/pi) * (1/N) sum L~_i * cos / pdf = (rho * spread / N) * sum L~_i.
//     The thesis prints (rho/pi)/N sum L~_i [seed 000 line 869], a factor pi too small, and GP3
//     multiplies by a user "contrast" of 2 (5 in its Sibenik set) instead; neither is used here.
//     L~ is the RSM's albedo/pi * E * cos: the Lambertian radiance the hit surface reflects.
//   - Validity of an RSM sample: the hit projects into the map, the texel is covered, the
//     distance from the hit to the RSM's position is below epsilon = max(voxel diagonal,
//     distance-scale * texel footprint), at most 4 voxel diagonals (the footprint, measured per
//     texel from screen derivatives, is the paper's s/cos(alpha) * z/z_near), and the sender's
//     lit side faces the receiver. rsm.validity=plane (the default) replaces the distance by the
//     distance to the sender's plane (< a voxel diagonal): the paper's test rejects true hits where
//     the light grazes the sender (sponza's sun: 0.77 of the one-bounce light with it, 1.07 without). Each ray's outcome is a category (ray-category output and the
//     stage's counters), including "step budget spent", which the public code counts as a miss.
//   - Ray directions: the 16 pixels of a 4 x 4 tile take consecutive blocks of N points of one
//     Sobol (0,2)-sequence, shifted by a hashed offset per tile (Cranley-Patterson), so each pixel's
//     N directions and the tile's 16 N together are stratified (shaders/near_field/ray_common.glsl).
//   - Range: rays.radius defaults to 1.75 volume edges, beyond the volume's diagonal (sqrt 3), so a
//     ray runs until it meets a voxel or leaves the volume. The paper's radius (half the edge was
//     voxlab's default) left 0.47 of the Cornell box's one-bounce light and 0.69 of the spheres
//     room's; the rest arrives from farther. A coarse far-field lookup beyond a radius would need a
//     second, blurred representation of the lit scene; the binary walk's cost grows slowly with
//     length (mean steps per ray 13.6 at half the edge, 19.9 across the Cornell box's volume),
//     so walking the whole volume is cheaper
//     and exact.
//   - Ray set-up: origin = p + n * normal-offset + d * ray-offset / cos(theta) (voxel
//     diagonals, GP3's 0.8 and 0.6); the segment ends radius from p along d, and a ray whose
//     offset exceeds the radius is dropped (counted). Origins outside the volume are "no hit"
//     through a guard, never a fetch outside the textures.
//   - Traversal (shaders/near_field/traversal.glsl): starts at level min(3, top), descends on a
//     non-empty AND, steps to the exit face of the texel and ascends by one on an empty one;
//     exact face stepping instead of GP3's 0.25-texel offset, so it equals a brute-force DDA over
//     the grid except at corner ties (tested). Hits only at level 0; the hit slice is the first
//     set bit along the ray (findMSB toward +z, findLSB toward -z), and the hit point is the ray's
//     entry into that slice within the column (the thesis uses the column entry point).
//   - What the inspector shows: the grid, the hierarchy and the tables have the semantic
//     bitmask-columns (src/techniques/near_field/views/bitmask_columns.cpp): hovering or clicking a texel
//     names its set slices, and the inspector draws that column as a 128-slice stack with each
//     slice's depth interval and, above level 0, its four children one level down and their OR
//     (red where it differs from the column). probe.x / probe.y are a screen probe: a click on a
//     camera image re-runs the rays for that pixel, and the Probe tab shows the probe.ray walk
//     step by step (level, texel, slice range, ray mask, AND, descend / advance / hit, as bit
//     strips), checked by near-field-traversal (one level per step, hits only at level 0), and
//     the ray's set-up, hit and RSM lookup (probe-ray), and beside the walk the same segment
//     walked cell by cell by the CPU's brute-force DDA over the level-0 grid (probe-dda, checked
//     by near-field-dda: face neighbours in order, ending on the walk's hit). The walk is recorded
//     by the recorder program of the rays shader (common/probe_recorder.glsl), one invocation that walks the
//     probed ray again: recording behind a per-pixel flag made every pixel pay for its stores at
//     every step on llvmpipe (nearly half of the rays stage, docs/performance.md).
//   - Not reproduced: the texture-atlas voxelization (S1-S3 of the note: the fragment list is exact
//     and already there). Voxel path tracing (section 3.2.4) is the technique voxel-path-tracing
//     (voxel_path_tracing.cpp) on these stages.
//   - The filter is the edge-avoiding a-trous wavelet filter of Dammertz et al. 2010 with depth and
//     normal edge-stopping (no colour term: 8 rays leave noise as large as the edges it would keep),
//     shared with voxel-path-tracing; its passes follow rays.count (filter.samples rays under the
//     kernel: 3 passes for 8 rays). GP3's filter (radius 8, 2 iterations, distance limit 0.8) is
//     off by default there.
//   - Sky (sky.radiance, shaders/common/sky.glsl): a ray that ends its radius without a hit outside
//     the scene's bounds escapes and adds the sky as a valid hit adds L~; one that ends inside the
//     bounds is far field, which a near-field estimator leaves out, so it adds nothing (on the
//     lightless blocks near-field sees 0.77 of the reference's once-reflected sky).
//
// References
//   seed 000 (Gomes): section 2.2 (reflective shadow maps), 3.2 (near-field GI on a voxel model,
//   after Thiedemann et al. 2011), 4.4 (its implementation: bitmasks 4.4.1, voxel grid 4.4.4, mipmap
//   4.4.5, rays and intersection 4.4.6, RSM lookup), 4.6 table 5 (timings); Thiedemann, Henrich,
//   Grosch, Mueller, "Voxel-based Global Illumination", I3D 2011, and their GPU Pro 3 chapter;
//   Dachsbacher and Stamminger, "Reflective Shadow Maps", I3D 2005; Forest, Barthe, Paulin,
//   "Real-time hierarchical binary-scene voxelization", JGT 2009; Dammertz, Sewtz, Hanika, Lensch,
//   "Edge-Avoiding A-Trous Wavelet Transform for fast Global Illumination Filtering", HPG 2010.
#include "graph/technique.h"
#include "techniques/common/binary_voxels_stage.h"
#include "techniques/common/rsm_stage.h"
#include "techniques/common/gbuffer_stage.h"
#include "techniques/common/light_stage.h"
#include "techniques/common/shadow_map_stage.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/near_field/stages.h"
#include "techniques/vct_grid/stages.h"

namespace voxlab {

static std::unique_ptr<Technique> makeNearField() {
  auto t = std::make_unique<Technique>(
      "near-field", "Near-field GI on binary voxels",
      "Binary voxel columns, a 2D OR mip hierarchy, short cosine rays and a reflective shadow map lookup.");
  addVoxelizeStages(*t);
  t->add<BinaryVoxelsStage>();
  t->add<nearfield::BitmaskTablesStage>();
  t->add<nearfield::HierarchyStage>();
  t->add<LightStage>();
  t->add<ShadowMapStage>();
  t->add<RsmStage>();
  t->add<GBufferStage>();
  t->add<nearfield::RaysStage>();
  t->add<AtrousFilterStage>(nearfield::filterConfig("indirect-1", "rays.count"));
  t->add<CompositeStage>(nearfield::compositeTerms());
  t->setFinalOutput("composite", "final");
  return t;
}

VOXLAB_REGISTER_TECHNIQUE("near-field", "Near-field GI on binary voxels", makeNearField);

}  // namespace voxlab
