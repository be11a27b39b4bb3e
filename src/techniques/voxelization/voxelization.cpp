// voxelization: three ways to turn triangles into voxels, each checked against a CPU reference.
//
// Intro
//   Every voxel technique starts by finding the voxels a surface touches. A *conservative* surface
//   voxelization keeps every voxel whose box a triangle overlaps, even by a sliver; anything less
//   leaves holes that light leaks through. This technique runs one of four methods and shows, voxel
//   by voxel, how it differs from the exact answer computed on the CPU.
//
// Overview (the stages, in order)
//   1. classify   per triangle: dominant axis, area projected along it (voxels^2), and the pass
//                 that voxelizes it (small -> triangle-parallel compute, large -> raster)
//   1b. triangle-view  one chosen triangle (inspect.triangle) along its dominant axis: the pixels
//                 plain rasterization covers, those conservative rasterization adds, the grown
//                 triangle and grown bounding box (drawn on the CPU with the raster pass's rules)
//   2. voxelize   triangles -> voxel fragment list (10:10:10 positions), by voxelize.method:
//                   fragment-parallel  rasterize along the dominant axis, triangles grown by half
//                                      a pixel, exact triangle/box test for the <= 3 voxels of each
//                                      fragment's column (the vct-grid voxelizer)
//                   plain              the same pass without growth or box test: one voxel per
//                                      covered pixel centre (holes in thin and small geometry)
//                   triangle-parallel  one compute invocation per triangle loops over its voxel
//                                      box column by column with Schwarz & Seidel's plane and 2D
//                                      edge-function tests in the xy, yz and zx projections
//                   hybrid             triangles below voxelize.hybrid-cutoff voxels^2 go to the
//                                      compute pass, the others to the conservative raster pass
//   3. occupancy  fragments per voxel (image atomics); duplicates = fragments - occupied voxels
//   4. compare    the CPU reference set and a difference volume (1 missed, 2 added)
//
// Details
//   - The fragment list packs voxel coordinates into 10 bits per axis, so a grid is at most
//     1024^3; voxel.resolution stops at 512 and the stages refuse anything above 1024.
//   - Both conservative methods decide each candidate voxel with the plane and 9 edge functions
//     of common/triangle_cells.glsl (set up once per triangle, in double), which inside the
//     triangle's bounding box of cells equal the CPU reference's 13-axis separating axis test,
//     half-open cells included: the voxel sets are the reference's. Every fragment of either is one (triangle, voxel) pair: a
//     voxel lies in exactly one pixel column of a triangle's projection, so duplicates (fragments
//     minus occupied voxels) count voxels shared by several triangles, not double work.
//   - The compute pass samples albedo and emission from the material's textures at the voxel
//     centre's projection onto the triangle (one dispatch per draw range, so one material each)
//     and writes a face normal oriented like the vertex normals; positions are what is compared.
//     The passes are shared with vct-grid (techniques/common/triangle_voxelizer.h).
//   - alphaMode MASK triangles keep a voxel only where their alpha coverage is opaque near it,
//     by one rule in every pass and in the CPU reference (scene/alpha_coverage.h).
//   - Time: a triangle-parallel invocation loops over its projected box, so on a GPU one huge
//     triangle serialises thousands of columns while other lanes idle; rasterization spreads them
//     over pixels. That is the case the hybrid method exists for. The compute pass splits a box into
//     chunks of 8192 columns (one invocation each), because llvmpipe ends an invocation's loops
//     after 65535 iterations; on llvmpipe it is then the faster pass everywhere, so the default
//     cutoff sends every triangle to it (docs/performance.md, "Voxelization sweep").
//
// References
//   seed 000 (Gomes) section 2.1; seed 002 (Basgier) chapter 3: triangle-parallel voxelization,
//   the hybrid by triangle size and the 10:10:10 voxel fragment list; Schwarz & Seidel, "Fast
//   Parallel Surface and Solid Voxelization on GPUs", 2010; Rauwendaal & Bailey, "Hybrid
//   Computational Voxelization Using the Graphics Pipeline", 2013; Akenine-Moller, "Fast 3D
//   Triangle-Box Overlap Testing", 2001.
#include "graph/technique.h"
#include "techniques/voxelization/stages.h"

namespace voxlab {

static std::unique_ptr<Technique> makeVoxelization() {
  auto t = std::make_unique<Technique>(
      "voxelization", "Voxelization three ways",
      "Turn triangles into voxels by conservative raster, plain raster, a compute pass per triangle or a "
      "hybrid by triangle size, and compare every voxel with an exact CPU reference.");
  t->add<vox::ClassifyStage>();
  t->add<vox::TriangleViewStage>();
  t->add<vox::VoxelizeStage>();
  t->add<vox::OccupancyStage>();
  t->add<vox::CompareStage>();
  t->setFinalOutput("compare", "difference");
  return t;
}

VOXLAB_REGISTER_TECHNIQUE("voxelization", "Voxelization three ways", makeVoxelization);

}  // namespace voxlab
