// clipmap: voxel cone tracing on a 3D clipmap (VXGI-style), updated incrementally as the camera moves.
//
// Intro
//   A stack of L clip levels of N^3 cells each, level k with voxels of s_0 2^k, all centred on the
//   camera: detail falls off with distance at a fixed memory cost. The levels are anchored to a
//   lattice fixed in the world and addressed toroidally (cell c lives at texel c & (N-1)), so when
//   the camera moves only the slabs of newly exposed cells are cleared and re-voxelized; no data
//   moves. Cones read, per sample, the finest level whose region holds the sample's footprint.
//
// Overview (the stages, in order)
//      light       the scene's first light after the light.0.* parameters (shared, common/light_stage)
//   1. shadow-map  depth from the light (shared)
//   2. anchor      per level o_k = 2 floor(a_k / s_{k+1}) - N/2 around the anchor a_k (the camera plus
//                  the path's moves, plus clipmap.look-ahead N s_k along the view direction);
//                  per move the planner's disjoint slabs and counts
//   3. update      iterative, one camera move per iteration (update#0 = the full build): level by
//                  level, clear the accumulators of the cells to voxelize, voxelize + inject them
//                  (shadow-mapped Lambert, fixed-point atomics), resolve into the atlas (RGBA16F
//                  by default), refilter the covered block from the finer level (isotropic mean;
//                  six faces by the under operator), fill the cells the camera's space does not
//                  reach (clipmap.fill-unreached); then refresh the guard texels (timed per level
//                  and phase)
//   4. mips        the coarsest level unrolled into logical order, every face mipped down to 4^3;
//                  every level unrolled for display (clip-logical)
//   5. covered-compare  (clipmap.compare-covered) covered cells voxelized directly beside their
//                  filtered content, and the difference (the source of popping)
//   6. gbuffer     position, normal, albedo, emission, depth from the camera at the end of the path
//                  (the shared stage, given the moved view)
//   7. cone-trace  diffuse cones (+AO) and a specular cone across levels; level-used image; probe
//   8. composite   direct + indirect diffuse + specular, tonemapped (vct-grid's composite shader)
//
// Details
//   - Lattice and snapping: cell c of level k covers [c, c+1) s_k in metres; origins are even, so
//     level k's region lies inside level k+1's and the covered block of level k+1 is exactly
//     [o_k / 2, o_k / 2 + N/2). Integer work is int64 on the CPU (clipmap_math.h: floorDiv, modPos;
//     C++ '/' and '%' truncate toward zero, the classic negative-coordinate bug).
//   - Incremental == from scratch, by design: a cell's voxels come from a (triangle, cell) test in
//     triangle-local double coordinates of the world lattice (independent of origin and box), its
//     light is summed in fixed point with integer atomics (independent of order), the resolve is
//     an integer mean, and a level's content is defined (clip levels Direct_k outside the covered
//     block, F(level k-1) inside), so the plan rebuilds exactly the cells whose definition
//     changed: exposed slabs (N^3 - prod(N - |d_i|) cells), cells that left the covered block
//     (coverage changes most implementations miss) and the covered block itself.
//   - Which triangles a pass visits does not change a texel either (sums are order-free, and a
//     triangle the shader would turn away adds nothing): the stage keeps the scene's triangles in
//     Morton order per draw range, cut into runs of 512 with bounds, and dispatches only those
//     whose bounds can reach a box of the pass (mayReach: runs first, then each triangle), so a
//     move pays for the slabs' triangles, not a pass over the scene.
//   - The fixed-point sums have clipmap.fixed-point-bits b fraction bits (default 14): a cell holds
//     light adding up to 2^(32-b) before a sum overflows; every addition that wraps a sum is
//     counted and reported (accumulator_overflows and one warning line), never silent.
//   - The cone model is vct-grid's (clipmap.faces=anisotropic, the default): each of a cell's six
//     directional faces shows a cone travelling that way only the fronts of the surfaces it sees
//     (common/facing.glsl: the mean light of the fragments whose fronts it sees, covering their
//     largest front weight), coarser cells composite their children front to back per direction
//     (common/anisotropic_mip.glsl), and a sample blends the three faces facing the cone by their
//     optical depths (seenFronts), at level 0 too (vct-grid reads its isotropic level 0 there: an
//     isotropic cell shows a cone the light of the surface it leaves, and the floor beside the two
//     rooms' camera lit itself). A coarse cell voxelized directly can hold both faces of a slab (a
//     sun-lit roof's top and its underside): each side sees only its own. With level 0's region
//     over vct-grid's volume, levels 0-3 equal its mips texel for texel, isotropic and six faces,
//     and the cones take the same samples (tests/unit/test_clipmap_dense.cpp).
//   - Where a sample reads a level coarser than its cone asks for (the finer levels do not reach
//     it: far from the camera), a wall is one coarse cell whose trilinear opacity peaks up to half
//     a cell in front of it, and a cone crossing it between samples leaked through; the tracer
//     also reads each directional face clipmap.front-hold cells (0.5) back along the cone and
//     keeps the more opaque, so a front the cone reached stays opaque behind it.
//   - The march runs in three loops by the level the cone's width asks for (near: clip levels,
//     raised and holding fronts; crossing the coarsest level; far: its mips alone), so a sample
//     runs only its phase's reads: llvmpipe runs both sides of every branch, and one loop holding
//     every level's reads cost about 25 % more (docs/performance.md).
//   - Cells no path of empty cells from the camera reaches (behind the walls of a closed room,
//     inside closed objects) are filled, opaque, with the light of the wall next to them as the
//     camera's space sees it (clipmap.fill-unreached, unreached_cells.h, fill.comp.glsl). Empty,
//     they let a cone whose footprint reaches past a wall go on as if the wall were not there: in
//     a closed corridor the cone along the end wall's normal ran its length seeing the walls
//     edge-on (opacity 0.03) and the others left through the walls they graze. Level 0 is searched
//     from the camera's cell, each coarser level from the faces through which its finer level's
//     reached cells leave a covered cell (a corridor inside one coarse cell does not open the space
//     around it). The layer next to a wall stays empty, and a coarser cell holding a surface is
//     filtered from the surface alone, so a cone leaving the wall does not read its own light
//     below its horizon. Searched on the CPU after each level's filter, redone on
//     every move (a held filled cell is empty to the search), so a path still equals a build from
//     scratch.
//   - Guard texels on every side of every block make trilinear filtering across the physical seam
//     correct; a level serves a sample only when its footprint lies inside the level's region.
//   - clipmap.voxel-size defaults to a power-of-two fraction of the scene's extent (the same
//     lattice for the same scene in any unit); set to a power of two of metres, p / s_k is exact
//     in float (the exactness tests do).
//   - The path parameters move the camera: the clip levels' anchor along the path, and the G-buffer,
//     cone tracing and composite from its end (pathEndView; the shared G-buffer stage is given the
//     moved view, so no shared code knows about the path). The clip levels and the images of a run
//     from P with K moves of D equal, bit for bit, those of a run started at P + K D
//     (tests/unit/test_clipmap.cpp).
//   - In the viewer, a camera move re-runs update#0 incrementally from the held origins (the
//     stage keeps them with a key of layout, scene, light and atlas; any change rebuilds fully).
//
// References
//   ../shared/guide/techniques/clipmap.md; seed 004 (HanetakaChou's VXGI notes) sections 2-1-2 to
//   2-1-4 (toroidal addressing, logical and physical clipmap structure) and 2-3-2 (the under
//   operator); seed 000 (Gomes) section 3.5; Panteleev, "Practical Real-Time Voxel-Based Global
//   Illumination for Current GPUs", GTC 2014; Tanner, Migdal, Jones, "The Clipmap", 1998.
#include "graph/technique.h"
#include "techniques/clipmap/stages.h"
#include "techniques/common/light_stage.h"
#include "techniques/common/shadow_map_stage.h"

namespace voxlab {

static std::unique_ptr<Technique> makeClipmap() {
  auto t = std::make_unique<Technique>(
      "clipmap", "Voxel cone tracing on a 3D clipmap",
      "Clip levels around the camera, toroidally addressed and updated by slabs as it moves; cones read the "
      "finest level that holds each sample.");
  t->add<LightStage>();
  t->add<ShadowMapStage>();
  t->add<clipmap::AnchorStage>();
  t->add<clipmap::UpdateStage>();
  t->add<clipmap::MipsStage>();
  t->add<clipmap::CoveredCompareStage>();
  t->add<clipmap::PathGBufferStage>();
  t->add<clipmap::ConeTraceStage>();
  t->add<CompositeStage>(clipmap::compositeTerms());
  t->setFinalOutput("composite", "final");
  return t;
}

VOXLAB_REGISTER_TECHNIQUE("clipmap", "Voxel cone tracing on a 3D clipmap", makeClipmap);

}  // namespace voxlab
