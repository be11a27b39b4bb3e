// svo: voxel cone tracing on a sparse voxel octree, with ambient occlusion.
//
// Intro
//   The prefiltered voxels of vct-grid, stored sparsely: a node pool of 2x2x2 node tiles linked by
//   child pointers, built top down one level per pass from the voxel fragment list, and a brick
//   pool of 3x3x3 texels per node so that hardware trilinear filtering works inside a node. Leaves
//   hold the fragments' direct light (HDR by default, as vct-grid's voxels: RGBA8 bricks with a
//   scale each), inner
//   nodes the box filter of their children and, by default, six directional values (anisotropic
//   mips, Crassin et al. 2011, with vct-grid's fronts rule: a direction sees a voxel's light only
//   where it sees its surfaces' fronts, and the voxels' solid opacity is kept apart for ambient
//   occlusion and shadows): each node above the voxels has six more bricks, one per direction, and
//   one of solid opacity (RGBA8); a cone sample descends from the root to the level of its diameter and
//   blends two levels (quadrilinear), reading the directional bricks that face the cone and
//   combining them as vct-grid's cone tracer does. The cone model is vct-grid's; only where the
//   voxels live differs. Empty space costs no nodes below the level where it becomes empty.
//
// Overview (the stages, in order)
//   1. voxelize        shared (techniques/common: voxelize-static, voxelize, triangle-axes):
//                      triangles -> voxel fragment list
//   2. shadow-map      shared: depth from the light, the light's uniform buffer
//   3. svo-build       one level per iteration: flag (per fragment, atomicOr) -> dilate (optional,
//                      the 26 neighbours) -> count -> size the node pool from the count ->
//                      allocate (atomicAdd per tagged node) + init the children. Iteration 0 is
//                      svo-init (root, counters); iteration D only flags the leaves.
//      svo-neighbours  the six same-level face neighbours of every node (through the closest common
//                      ancestor), symmetric by construction; the bricks gather by position instead
//   4. svo-leaves      per fragment: shadow-mapped Lambert + emission with vct-grid's inject code
//                      (common/fragment_light.glsl: the shadow map read inject.shadow-offset
//                      voxels off the voxel centre along the fragment's normal, so a voxel whose
//                      centre lies behind its surface is not shadowed by it), exact fixed-point
//                      sums per leaf, then mean and opacity 1; the OR of the fragments' facing
//                      codes per leaf (common/facing.glsl, as vct-grid's inject)
//   5. svo-mipmap      one level per iteration, D-1 .. 0: parent = mean of its 8 children; with
//                      mipmap.mode=anisotropic (default) also its six directional values, the
//                      children composited front to back along each axis, then averaged
//                      (common/anisotropic_mip.glsl); with mipmap.fronts (default) a voxel shows
//                      each direction only its fronts (facingLeaf, common/facing.glsl) and the
//                      solid opacity per direction is reduced beside them, as vct-grid's
//                      mipmap_anisotropic; the "svo-dense" view resamples each level (isotropic)
//                      into a mip of a 3D texture
//   6. svo-bricks      one 3x3x3 brick per tagged node, borders gathered from the same-level nodes
//                      (svo.layout=tile: one per subdivided node, at its children's corners); with
//                      anisotropic mips six more per tagged node above the voxels, in a second pool
//                      (svo-directional-bricks), made the same way from the directional values,
//                      and with mipmap.fronts one of solid opacity along x, y, z in a third,
//                      RGBA8 (svo-opacity-bricks, as vct-grid's solid-opacity volume)
//      svo-pick        the node under a click on svo-structure (volume probe pick.x/y/z/level):
//                      box, children, neighbour links, the brick's 27 texels
//   7. gbuffer         shared
//   8. svo-cone-trace  vct-grid's cones through the octree (the shared cone set-up,
//                      common/cone_setup.*, with vct-grid's defaults); above the voxels the three
//                      directional bricks facing the cone, weighted dir^2, the two levels blended
//                      per direction and combined by optical depth (seenFronts,
//                      common/anisotropic_mip.glsl, vct-grid's too); AO and the shadow cone from
//                      the solid opacity; probe records (samples, descents)
//   9. composite       vct-grid's composite, or the AO image as the final one (svo.shading=ao)
//
// Details
//   - Levels: 0 = root (the whole volume), D = log2(voxel.resolution) = one voxel; D + 1 levels.
//     Node word 0 = [31] tag, [30] non-empty, [29:0] first child (0 = none), child index
//     x + 2y + 4z; every node also stores its cell and level, so no pass needs a traversal to
//     know where a node is (shaders/svo/svo_shared.h, all masks in one header).
//   - Layout N of the technical note (Basgier): every tagged node has a node-centred brick whose
//     texel t in {0,1,2}^3 sits at node.min + t * size / 2; borders are the mean of the centre
//     values of the 2/4/8 same-level cells sharing the point (gathered by position: exact, unlike
//     the separable transfer, source error P3), clamped at the volume edge like vct-grid's
//     CLAMP_TO_EDGE. With the box mip filter every octree level then equals vct-grid's mip D - l
//     everywhere inside the existing nodes; with svo.dilate=1 (optional, off by default: it costs 2.6x the leaves at 128^3) the 26 neighbours of every
//     non-empty node exist too, so an absent node is exactly empty and svo = vct-grid everywhere.
//     Without dilation an absent fine node falls back to the coarse level alone (P2).
//   - Pools are sized from counts, never guessed: each build level counts its tagged nodes before
//     the next level is allocated (the pool grows to exactly 1 + 8 * tiles), the brick pool holds
//     the sum of tagged nodes + the zero brick. Every allocating pass checks capacity and sets an
//     overflow flag; the stage then fails with one line naming the pool and the size it needs.
//     svo.node-pool-fraction and svo.brick-pool-fraction < 1 undersize a pool on purpose: guard
//     words after the node pool, and the brick pool's spare slots past its capacity, staying empty
//     show that nothing was written past its end (tests/unit/test_svo.cpp, SvoPools.*).
//   - Brick numbers: 1 + a tagged node's rank among the tagged nodes in pool order (brick 0 is
//     the zero brick), the same on every run. Above the voxels that rank is the number of the
//     tile svo-build gave the node's children, so the brick is 1 + (first child - 1) / 8; the
//     tagged voxels follow all tiles in the order of svo-build's last scan (svo-groups), so
//     svo-bricks needs no counting pass of its own.
//   - Quadrilinear: levelStar = D - max(log2(d / voxel) + bias, 0); fine = min(D, floor + 1),
//     weight of fine = levelStar - (fine - 1). This is GL's LINEAR_MIPMAP_LINEAR with lod =
//     D - levelStar, continuous across integer levels (Gomes' listing 4.25 inverts it: P1).
//   - Leaf radiance uses exact integer sums (steps of 1/4096, as vct-grid's) instead of the RGBA8
//     CAS moving average (P8); the result is independent of fragment order and thread count. Each
//     fragment's radiance is clamped to what the bricks hold (voxel.format, vct-grid's parameter):
//     64 with voxel.format=rgba16f (the default), 1 with rgba8. Clamped to 1, the sun patch of
//     skylight-room and the voxels by the corridor's lamp lose most of their light (indirect energy
//     0.42 and 0.40 of the reference with vct-grid's fronts rule).
//   - AO: from the diffuse cones by default (the same cones as vct-grid, so the two AO images can be
//     compared), or Basgier's constellations (ao.cones): 5 cones of 90 deg and 8 of 60 deg as
//     published, 3 cones of 100 deg (the seed leaves the aperture open: our choice, with the ring
//     layout of vct-grid for all directions, which the seed does not give either), equal weights;
//     falloff f(r) = 1 / (1 + lambda r), r in voxels, lambda = ao.falloff (default 0). ao.jitter
//     (off) turns every pixel's cone frame about the normal by a fixed hash of the pixel (the same
//     image every run; the seed gives no jitter pattern): banding becomes noise, the mean stays.
//   - Anisotropic bricks (mipmap.mode=anisotropic, the default; Layout N only): a node above the
//     voxels has six directional values, built from its children as vct-grid builds its
//     directional mips (from the voxels' values for level D - 1, else from the children's own
//     directional values; absent children count 0), and six bricks of them in
//     svo-directional-bricks, numbered as its isotropic brick (1 + its tile), part d of the pool
//     stacked along z, so the sign of the cone's direction is an offset (no divergent branch on
//     llvmpipe). The voxels stay isotropic: between level D - 1 and D a sample blends the
//     directional value with the leaf, as vct-grid fades its voxels into directional level 1.
//   - The fronts rule (mipmap.fronts, the default, vct-grid's): a leaf's facing code says, per
//     travel direction, how much of its surfaces' fronts a cone sees; the directional values hold
//     only that (premultiplied radiance and coverage), and one more record per node the solid
//     opacity (the voxels as cubes) along x, y, z, the same either way. A cone blends each direction's two
//     levels, then combines the three by optical depth (common/facing.glsl, seenFronts,
//     the code vct-grid's sampler calls); AO and the shadow cone accumulate the solid opacity.
//     Crassin's classic rule (every voxel seen from all sides) let the sun-lit top of
//     skylight-room's roof shine into the room (indirect energy 1.95 of the reference) and gave
//     the corridor's walls seen edge-on half their opacity; with the rule and HDR leaves svo is in
//     the band on every interior scene (docs/fidelity.md). A sample reads the solid opacity only
//     where it is used (up to ao.range, and on the shadow cone, which reads no fronts). With
//     dilation svo's indirect light and AO equal vct-grid's (max 0.020 and 0.0034 at 64^3, test
//     SvoConeTrace.FrontsIndirectAndOcclusionEqualVctGridWithDilation; with mipmap.fronts=false
//     and RGBA8 on both, max 0.0033: AnisotropicIndirectEqualsVctGridWithDilation). Memory: the
//     directional pool is 6 bricks per inner node, the opacity pool 2 (docs/performance.md).
//     mipmap.mode=isotropic keeps the box chain, exactly vct-grid's isotropic mips.
//   - HDR bricks (voxel.format=rgba16f, the default; Layout N): RGBA8 texels holding radiance
//     divided by a scale per brick and part, the largest radiance channel of its 27 texels
//     (svo-brick-scales; shared-exponent blocks); opacity unscaled. A sample filters within one
//     brick only, so the scaled texels filter exactly; the error is 8 bits of the brick's largest
//     value (indirect light max 0.020 off vct-grid's half floats at 64^3 with dilation, 0.0062
//     with half-float bricks; suite energies equal to two decimals). Why not half floats: llvmpipe
//     filters RGBA8 on a faster path; a 512x512 Cornell run took about 4.0 s of CPU with half-float
//     bricks, 4.3 s with half-float opacity bricks too, 3.5-4.0 s now (2.7-3.0 s before the fronts
//     rule and HDR; docs/performance.md). Layout T keeps half floats: its Gaussian pass filters
//     across bricks.
//   - Voxel halo (svo.voxel-halo, on): a sample whose fine level is the voxels and whose voxel has
//     no brick (empty, or no node: Layout N has bricks on non-empty nodes only) reads the dense
//     grid's trilinear blend of the eight voxels around it, found in the octree (from the deepest
//     node of the descent, through the closest common ancestor); without it such a voxel reads 0
//     and a cone that starts in it misses the surface next to it: stair bands along the short
//     box's base on the Cornell box (0.055 off vct-grid's final image, 0.016 with the halo, both
//     with the classic rule and RGBA8 voxels). It
//     costs CPU time: a 512x512 run --final-only on one thread 2.9 s instead of 2.0 s. The soft-shadow
//     cone skips it (its image 0.991 SSIM to the halo's, the final image unchanged; 0.35-0.55 s of
//     CPU less on one thread). Above the voxels the same gap remains (P2):
//     svo.dilate=true closes it everywhere.
//   - Layout T (svo.layout=tile, Crassin/Gomes): one brick per subdivided node (tagged, above the
//     voxels), texel t at its children's corner 2 cell + t holding the mean of the 8 child-level
//     cells around that corner (clamped to the volume like Layout N's borders); a sample of level l
//     reads the bricks of level l - 1, so the descent ends one level higher, leaves have no brick
//     and level 0 (the root's value) is not stored: samples coarser than level 1 read level 1. The
//     finest level is the dense grid filtered by [1 2 1] / 4 per axis (the note's fact 2), so the AO
//     is darker (mean 0.083 from Layout N's on the Cornell box at 64^3). Memory on Sponza at 256^3:
//     127,450 bricks instead of 662,065; the traced octree is 0.21 of vct-grid's mip chain (both in half floats, before the scaled RGBA8 bricks)
//     (docs/performance.md).
//   - Neighbour links (S3) are their own stage and output; the bricks' borders do not follow them
//     but gather by position (the same descent), so the links are for inspection and tests.
//   - svo.filter=gaussian (with svo.layout=tile): the bricks above level D - 1 are Crassin/Gomes'
//     1/8-1/16-1/32-1/64 kernel of the level below's bricks (vertex values read back from the
//     RGBA8 pool, level by level from D - 2 up); the finest bricks stay the corner means. With the
//     node layout the kernel collapses to decimation (the note) and is not applied.
//   - The probed pixel's cone samples and descents are recorded by a second program of the same
//     shader (the recorder, common/probe_recorder.glsl: one invocation that traces that pixel again): llvmpipe runs a
//     branch that depends on the invocation masked in all of them, so a per-pixel "record" flag
//     made every pixel pay for the recording (a brick sample per descent level): 3x the cone
//     trace's time (docs/performance.md, svo).
//   - llvmpipe runs both sides of every branch, even where all lanes agree (docs/performance.md),
//     so what a dispatch does not need is left out of its program: the cone trace marches in loops
//     by phase (lod 0: the voxels alone; the fade into the voxels; above them) and before and after
//     ao.range, each loop holding only its lookups (vct-grid's march does the same); all cones but
//     the soft-shadow one share one loop, and that cone is a define; svo-bricks fills the tiles of
//     voxels and the tiles above in two programs, and svo-mipmap's level above the voxels is its own
//     program.
//   - Not built (yet): the CAS leaf mode.
//
// References
//   seed 000 (Gomes) sections 3.1.1-3.1.3 and 4.2.2 (listings 4.16-4.25); seed 002 (Basgier)
//   chapters 3-6; Crassin, Neyret, Sainz, Green, Eisemann, "Interactive Indirect Illumination Using
//   Voxel Cone Tracing", 2011; the technical note ../shared/guide/techniques/svo.md (invariants
//   I1-I16, source errors P1-P24).
#include "graph/technique.h"
#include "gpu/shader_library.h"
#include "techniques/common/gbuffer_stage.h"
#include "techniques/common/light_stage.h"
#include "techniques/common/shadow_map_stage.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/svo/stages.h"
#include "techniques/vct_grid/stages.h"

namespace voxlab {
namespace svo {

// The composite with vct-grid's terms, plus svo.shading=ao: the final image is the ambient occlusion.
class GiOrAoCompositeStage : public CompositeStage {
 public:
  GiOrAoCompositeStage() : CompositeStage(terms()) {}
  void declare(StageBuilder& b) const override {
    CompositeStage::declare(b);
    b.param(ParamDesc::choice("svo.shading", {"gi", "ao"}, 0,
                              "gi: direct + indirect light; ao: the final image is the ambient occlusion (grey)"));
    b.read("ambient-occlusion");
  }
  void execute(StageContext& ctx) override {
    CompositeStage::execute(ctx);
    if (ctx.params.getChoice("svo.shading") != "ao") return;
    GLuint program = ctx.shaders.program({"svo/ao_final.comp.glsl"});
    glUseProgram(program);
    glBindTextureUnit(0, ctx.board.texture("ambient-occlusion").id());
    glBindTextureUnit(1, ctx.board.texture("position").id());
    glBindImageTexture(0, ctx.board.texture("final").id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA8);
    dispatchCompute({ctx.view.width, ctx.view.height, 1}, {8, 8, 1});
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
  }

 private:
  static CompositeTerms terms() {
    CompositeTerms t = vct::compositeTerms();
    t.summary = "Add direct light, indirect diffuse and specular and tonemap (svo.shading=gi), or show the ambient "
                "occlusion (svo.shading=ao).";
    return t;
  }
};

}  // namespace svo

static std::unique_ptr<Technique> makeSvo() {
  auto t = std::make_unique<Technique>(
      "svo", "Voxel cone tracing on a sparse voxel octree",
      "Build an octree level by level from the voxel fragments, light and filter it bottom up, then trace "
      "cones (GI and ambient occlusion) that descend it per sample.");
  addVoxelizeStages(*t);
  t->add<LightStage>();
  t->add<ShadowMapStage>();
  t->add<svo::BuildStage>();
  t->add<svo::NeighboursStage>();
  t->add<svo::LeavesStage>();
  t->add<svo::MipmapStage>();
  t->add<svo::BricksStage>();
  t->add<svo::PickStage>();
  t->add<GBufferStage>();
  t->add<svo::ConeTraceStage>();
  t->add<svo::GiOrAoCompositeStage>();
  t->setFinalOutput("composite", "final");
  return t;
}

VOXLAB_REGISTER_TECHNIQUE("svo", "Voxel cone tracing on a sparse voxel octree", makeSvo);

}  // namespace voxlab
