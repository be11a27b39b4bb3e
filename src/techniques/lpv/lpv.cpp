// lpv: light propagation volumes with voxel VPLs (Doghramachi's variant, as seed 000 implements it).
//
// Intro
//   The indirect light of a scene is kept as low-order spherical harmonics (L1: 4 coefficients per
//   colour channel) in two coarse nested lattices (cascades, 32^3 each). The lit voxels of the
//   scene become virtual point lights (VPLs) whose clamped-cosine lobes are injected into the
//   lattice; the light then spreads by a fixed number of local gather steps to the 6 face
//   neighbours of each cell, blocked by the voxels themselves, and every visible surface reads its
//   indirect irradiance from the lattice. Kaplanyan & Dachsbacher 2010 give the physical reading
//   that the defaults here follow; the thesis' variants are parameters a lesson can switch to.
//
// Overview (the stages, in order)
//   1. voxelize    triangles -> voxel fragment list (the shared stages of src/techniques/common:
//                  voxelize-static once, voxelize per frame of moving triangles, triangle-axes)
//      light       the scene's first light after the light.0.* parameters (shared, common/light_stage)
//   2. shadow-map  depth from the light (shared)
//   3. place       fine and coarse grid boxes: the coarse one on the scene, the fine one ahead of the
//                  camera inside the scene (or both on the scene, or both ahead of the camera),
//                  snapped to a multiple of their cell size
//   4. bin         the fragments binned into each cascade: colour/contrast/occupancy and four
//                  tetrahedron-channel normals by atomicMax (Listings 4.27-4.29), fragment counts,
//                  the surface each cell holds (the fragments of one voxel share its area)
//   5. inject      each voxel fragment lit with its own normal and shadow test, summed per cell into
//                  a VPL in L1 SH (inject.lighting=per-cell: each cell once, through its best normal)
//   6. propagate   one gather step per iteration in both cascades (propagate#k), the energy per step,
//                  the picked cell's record, the occlusion per cell and direction
//   7. reflection  a finer colour grid over the fine cascade's box lit by its L0 light (Listing
//                  4.34), then one mip level per iteration (reflection@L, mean of 8 children)
//   8. gbuffer     position, normal, albedo from the camera (vct-grid's stage, reused as is)
//   9. gi          trilinear SH lookup per cascade, cosine convolution, cascade blend; one glossy
//                  cone through the reflection grid's mips
//  10. composite   direct + indirect diffuse (+ composite.glossy x glossy), tonemapped
//   inject.vpl-shift (0.5, K&D's half cell) moves each fragment's VPL along its normal before it is
//   binned (per cell: the cell's VPL, by a 27-cell gather, so no atomics are needed); see Details.
//   inject.source=point-vpl puts one VPL in the picked cell, or inject.vpl-distance cells behind it
//   (0 by default; lesson 05's facing-plates step uses 2, LpvLookup.FacingPlatesDecideTheSign's
//   receivers), so the probe record can show what a receiver in front of an emitter reads.
//   propagate runs each step over the box of cells within k + 1 of injected light (light moves
//   one cell per step; the rest stays 0), one invocation per column of cells along x, which also
//   sums the column's energy for the step's record (docs/performance.md, lpv); the probe record
//   comes from the same shader built with LPV_PROBE, one invocation, with the 30 face evaluations
//   behind the picked cell's gathered light.
//
// Details (every constant and default; the technical note is guide/techniques/lpv.md)
//   - SH storage (c00, c1-1, c10, c11), Condon-Shortley signs, intensity indexed by the direction of
//     travel: shaders/common/sh.glsl, its C++ twin sh.h. A VPL on a surface of normal n is lobe(+n).
//   - Cells: cell i of a cascade covers origin + [i, i+1) s; the origin is the snapped centre
//     floor(C / s) s minus res/2 cells, so cell boundaries lie on multiples of s: a camera move of
//     less than a cell leaves every grid bit-identical, a move of one cell shifts it by one cell.
//   - Fine cell = lpv.fine-extent (1.5) x the scene's largest extent / res; coarse cell =
//     lpv.cascade-ratio (2, the thesis' "8 times the volume") x fine, so the coarse grid's edge is
//     3 times the scene's largest extent. lpv.centre=view by default: the coarse grid on the scene's
//     centre (it holds the whole scene), the fine grid on the point GPU Pro 4 puts it (camera +
//     forward x half its extent) moved into the scene's bounds, so the fine grid covers the part of
//     the scene ahead of the camera and the coarse one serves the rest (on the Cornell box at camera 0
//     the blocks are fine, the back wall and ceiling blend into coarse). scene (both on the scene's
//     centre; the former default) leaves the coarse grid unused whenever the scene fits in the fine
//     one; camera (both ahead of the camera, GPU Pro 4) puts a camera outside the scene's fine grid
//     in empty space. Against the reference path tracer at 22 steps, view against scene: indirect
//     energy 0.60 vs 0.56 of the reference on the Cornell box, 1.04 vs 0.78 in skylight-room, equal
//     elsewhere (VPLs unshifted).
//   - Injection (physical, K&D): flux Phi = albedo * E * A, intensity (Phi / pi) lobe(n). A is the
//     surface a fragment stands for: its voxel's surface voxel^2 / |n|_1 (a conservative
//     voxelization cuts |n|_1 voxels per voxel^2 of a plane) shared by the fragments of that voxel
//     (one per triangle touching it; the bin stage counts them). Counting a whole voxel^2 per
//     fragment, as before, made Sponza's lit surface 7.8 times too large (706k fragments in 98k
//     voxels at 128^3; indirect light 73.9x the reference) while the Cornell box's large triangles
//     hid it; tests/unit/test_lpv.cpp, InjectedFluxIsTheReflectedFluxOfTheSurface, cuts a floor
//     into 4608 triangles and tilts one 30 degrees. The thesis omits A and scales by an unexplained
//     lightMultiplier instead.
//     inject.lighting=per-fragment (default) lights every voxel fragment at its own voxel (its own
//     normal; the shadow map tested |n|_1 half voxels along the normal, where the voxel centre can
//     lie behind the surface) and sums the fragments' lobes per cell in fixed point (integer
//     atomics, order independent; the unit gives the fullest cell 2^30 steps). per-cell (the
//     thesis) lights each occupied cell once through its most light-facing normal with one shadow
//     test half a cell along it, so a cell holding sunlit and shaded surface, or several
//     orientations, counts all of it as lit at the best cosine. Against the reference path tracer
//     (docs/fidelity.md) per fragment is closer on both scenes: Sponza (1.74 m cells) indirect
//     0.91x the reference's energy, RMSE 0.0108, against 1.85x and 0.0161 per cell; Cornell box
//     (2.6 cm cells) RMSE 0.0832 against 0.0873 (energy 0.40 and 0.42; 8 steps, VPLs unshifted). It costs a pass over the
//     fragments (docs/performance.md).
//   - VPL shift (inject.vpl-shift, 0.5; K&D, GPU Pro 2 "Temporally Coherent LPVs": a VPL whose
//     normal points away from its cell's centre belongs to the next cell; the thesis: 0). A fragment
//     sits at its voxel's centre, up to half a voxel on either side of its surface, and cell
//     boundaries lie on multiples of the cell size, as many walls do: binned there unshifted, up to
//     half of a wall's VPLs land in the cell behind it, whose voxels block their light from the
//     second step on (skylight-room's walls read 0.1-0.2 of the reference). Per fragment each
//     fragment moves before it is binned; per cell the cell's VPL moves along its normal from the
//     cell centre (a whole cell for an axis-aligned normal). Against the reference at 256 x 256,
//     indirect energy (SSIM) from 0 to 0.5: cornell-box 0.60 -> 0.81 (0.57 -> 0.58), Sponza 0.94 ->
//     1.13, skylight-room 1.04 -> 1.58 (0.55 -> 0.62), two-rooms 1.03 -> 1.03, corridor 0.72 -> 0.99
//     (0.75 -> 0.83), spheres-room 1.06 -> 1.11. skylight-room's 1.04 was walls at 0.1-0.2 and a
//     floor at 2.5-5 times the reference; shifted, the floor around its sunlit patch lights itself
//     (4-8.5 times the reference, walls 0.3-0.6): K&D note that the shift "does not guarantee"
//     avoiding self-illumination, and L1 propagation keeps light near its VPLs (Reprojection, below;
//     lesson 05, step 15). The floor next to the Cornell box's red wall gets redder (bleeding ratio
//     1.70 against the reference's 1.20; 1.29 unshifted): the wall's VPLs are now in the room.
//   - Propagation weights: lpv.weighting=flux-consistent (default) re-emits the flux F = Omega I(d)
//     through face j as (F / pi) lobe(o_j), so without the face clamp the total flux is conserved
//     exactly (30 solid angles sum to 4 pi). thesis = Omega / (4 pi) x lpv.flux-amplifier (GPU Pro
//     4: 1.75) with the lobe not divided by pi: flux-consistent x amplifier / 4 = 0.4375.
//     The thesis' "fluxAmplifier" thus stands for the 4 pi vs pi normalisation, the missing surface
//     area at injection, the missing radiance conversion at lookup and the iteration scheme.
//   - Face solid angles 4 asin(0.1) = 0.4006697 (far) and (2 pi / 3 - far) / 4 = 0.4234314 (side);
//     the 0.4234413544 of several public implementations is a typo (a test pins the value).
//   - lpv.scheme=wavefront (default, K&D): w_{k+1} = P w_k and the lookup reads sum_k w_k, so every
//     path length is counted once. thesis: x_{k+1} = x_k + P x_k = (I + P)^{k+1} x_0, which counts a
//     path of j cells C(K, j) times and grows geometrically (the tests show both).
//   - lpv.clamp-faces (on): max(0, .) on each face evaluation, as every source does; it drops
//     negative back lobes and so adds flux (+13.8 % on the first step of an axis lobe, none once the
//     field is broad). Off gives the linear operator, which conserves flux per step exactly.
//     lpv.clamp-conserves (off) keeps the clamp and scales a source cell's clamped face fluxes, per
//     channel, so its 30 faces carry the flux of the unclamped 30 (ConservingClampKeepsTheFluxOfEveryStep):
//     non-negative and flux-conserving. It evaluates the 30 faces once per receiver (about 5 times the
//     propagation's cost on llvmpipe), so it is a measuring tool: with it the suite shows how much of
//     the default's light the clamp adds (Details, Reprojection).
//   - Occlusion from the source cell's voxel (the thesis' scheme, no separate geometry volume):
//     transmission 1 - clamp(A (0.25 + 0.5 n.d)) with the stored normal nearest the travel
//     direction; lpv.occlusion=two-sided (default) also flips normals facing away, so a wall blocks
//     light from both sides (the thesis blocks only light travelling along the normal, which lets
//     light hitting a one-sided wall's front through, pitfall 4 of the note). Empty normal channels
//     are skipped, not decoded to the zero vector. A = lpv.occlusion-amplifier 1 (GPU Pro 4): 25 %
//     passes head on. The first step is unoccluded (GPU Pro 4, the NVIDIA sample, K&D ports) so a
//     VPL's own voxel does not block its own light. front blocks only light arriving at a stored
//     surface's front (the normal most opposed to the travel direction; nothing if none faces
//     it), never the light a surface sends: a measuring tool for how much of a room's light its
//     own surfaces block. Against the reference at 256 x 256 (indirect energy): cornell-box 0.81 ->
//     1.31, Sponza 1.23, skylight-room 2.36, two-rooms 2.39, corridor 1.76, spheres-room 2.05
//     (unshifted VPLs: 0.60 -> 1.26, 1.03, 2.41, 2.39, 1.51, 2.10):
//     two-sided blocking takes half of the Cornell box's light as it leaves the surfaces that send
//     it (light spread sideways into a wall's or the floor's cells), and without it the surfaces'
//     own light, smeared sideways by L1, lights them (self-illumination) everywhere else.
//   - Steps (lpv.steps = 0, "scene", by default): ceil(lpv.resolution / lpv.fine-extent) = 22 at the
//     defaults, the steps the light's frontier needs to cross the scene's largest extent in the fine
//     cascade (the frontier moves one cell per step; the fine cell is fine-extent x that extent /
//     resolution, so the count depends on the grid alone, and the coarse cascade, which holds the whole scene, crosses it in
//     half as many). A fixed 8 (K&D-style implementations; GPU Pro 4 uses 10) carried light 21 cm on
//     the 56 cm Cornell box: its ceiling stayed black and its indirect energy was 0.39 of the
//     reference (0.60 at 22 steps with VPLs unshifted, 0.81 shifted; unshifted skylight-room
//     0.50 -> 1.04, two-rooms 0.83 -> 1.03, corridor 0.69 -> 0.73,
//     spheres-room 0.81 -> 1.06, Sponza 0.91 -> 0.94, with lpv.centre=view). Only the frontier moves
//     a cell per step, though; the rest is the propagation's own bias, not range (next item): the
//     Cornell box's ceiling, 21 fine cells from the lit floor, reads 1-3 % of the reference while the
//     floor by the walls reads 2-5 times it (light kept near its VPLs; unshifted 0.1 % and 2-7 times);
//     more steps barely change that (64 steps, unshifted: Cornell box 0.72, at 128 x 128). No
//     amplifier makes up for it.
//   - Reprojection (lpv.reprojection=face-axis, K&D): a face's flux re-enters as a lobe along the
//     face's axis, so the side faces turn light across the way it came. A step keeps the flux but
//     only 0.3686 of the band-1 vector (the direction of travel; tests/unit/test_lpv.cpp,
//     ReprojectionKeepsPartOfTheDirectionOfTravel), and light does a random walk: a point VPL's
//     wavefront keeps a mean height of 0.70 cells from step 2 on and after 22 steps has 1.8 % of its
//     flux beyond 8 cells (LightSpreadsAsARandomWalk). In a room light that must cross L cells
//     arrives as about 1 / L of a straight path's and after of the order of L^2 steps, which is why
//     small closed rooms, many fine cells across, come out dark far from their lit surfaces (Cornell
//     box 0.81 of the reference's indirect light; lesson 05, step 11). travel re-enters it along the
//     direction it crossed the face in (neighbour centre to face centre), which keeps 2/3 of the
//     direction (sum of omega d d^T over the 30 faces = 4 pi / 3 I): against the reference at 256 x
//     256, indirect energy (SSIM) cornell-box 0.81 -> 0.97 (0.58 -> 0.67), Sponza 1.13 -> 1.22,
//     skylight-room 1.58 -> 2.15, two-rooms 1.03 -> 1.28, corridor 0.99 -> 1.05 (0.83 -> 0.91),
//     spheres-room 1.11 -> 1.25: a directional L1 field has large negative back lobes, and the face
//     clamp adds what it drops. With lpv.clamp-faces off as well: 0.87 (0.69), 1.14, 1.75 (0.64),
//     1.12 (0.70), 1.01 (0.90), 1.08 (0.85): five of the six interior scenes in [0.8, 1.25] like the
//     default, SSIM higher on all six, skylight-room further out; not the default (an unpublished
//     reprojection, and without the clamp the field can go negative). With VPLs unshifted travel
//     read 0.70, 0.82, 1.44, 1.28, 0.77, 1.10 (without the clamp 0.62, 0.78, 0.87, 1.13, 0.74, 0.97).
//     Measured and not kept (128 x 128, VPLs unshifted): cells twice as large (lpv.fine-extent=3)
//     give the ceiling 12 % but skylight-room
//     2.1 (the floor lights itself over larger cells); reading the larger of the two cascades' light
//     (the coarse one where the fine one has received none) gives the Cornell box 0.73 and
//     skylight-room 2.3 (the coarse grid's self-illumination and leaks).
//     beam re-enters the flux as the L1 projection of a narrow beam along d (pi Y(d): the lobe's c00,
//     1.5 times its band 1), so a step keeps all of the direction. Against the reference at 256 x 256
//     (indirect energy, SSIM), with the plain clamp: cornell-box 1.75 (0.67), Sponza 1.34, skylight-room
//     4.70 (0.29), two-rooms 2.00, corridor 1.48 (0.79), spheres-room 1.69 (VPLs unshifted: 1.27
//     (0.77), 0.83, 3.18 (0.38), 2.00, 1.09 (0.91), 1.41; the rest of this item is unshifted); the ceiling is lit, but the
//     clamp now adds most of the light and what travels along a floor lights it (an L1 lobe sends a
//     quarter of its peak intensity sideways and reads a quarter of grazing light back). Without the
//     clamp: 0.78, 0.68, 0.73, 0.99, 0.91, 0.70, with black blotches where the field goes negative.
//     With lpv.clamp-conserves: 0.55 (0.76), 0.66, 1.19 (0.63), 1.05 (0.71), 0.71 (0.86), 0.80 (0.84).
//     With lpv.occlusion-amplifier=1.3333 (head-on light fully blocked) and the plain clamp: 1.12
//     (0.79), 0.67, 2.50, 1.69, 0.95 (0.94), 1.22: the setting that brings the Cornell box and the
//     corridor into [0.8, 1.25] (lesson 05, step 11), at the other rooms' cost.
//     The face-axis default with lpv.clamp-conserves: 0.53, 0.87, 0.92, 0.92, 0.66, 0.93. So a
//     flux-conserving propagation, whatever its reprojection, reads at most about 0.9 of the reference
//     on every interior scene, and 0.53-0.55 on the Cornell box; the default's 1.04 in skylight-room and
//     1.03 in two-rooms included light the clamp adds (+13 %), its leaks and its self-illumination.
//     None is the default: with VPLs unshifted none of these put more than four of the six interior
//     scenes within [0.8, 1.25] of the reference; the shifted default puts five (skylight-room, 1.58,
//     is out: its floor lights itself around the sunlit patch; lesson 05, step 15).
//   - Lookup: incident radiance L = gi.radiance-scale x I / s^2 (a cell face of area s^2 radiating
//     intensity I; K&D's text uses (s/2)^2, i.e. scale 4; the scale is calibrated once against the
//     reference path tracer, tests/unit/test_lpv.cpp, and recorded in docs/fidelity.md), E =
//     max(0, <L, lobe(-n)>) (gi.lookup-sign=minus-n: light arriving at the surface travels along
//     -n). The thesis listings convolve with lobe(+n): surfaces then see light leaving them, their own
//     VPL included; the facing-plates test decides the sign. Surfaces read the grid gi.lookup-offset
//     (0.5) cells along their normal, against self-illumination.
//   - Cascade blend: coarse weight 0 up to 4 fine cells (gi.blend-width) inside the fine grid's
//     edge, 1 from half a cell inside it (trilinear reads stay inside), by the max norm from the
//     fine grid's snapped centre (the grid is a box; the thesis' Euclidean 12..16 cells uses only
//     the inscribed ball of the fine grid). The blend goes by position alone: on the
//     Cornell box the front of the ceiling is read from the fine grid, which holds 1/80 of the
//     coarse grid's light there.
//   - Storage: RGBA32F (the thesis uses RGBA16F, 10-bit mantissa): the GPU matches the CPU
//     reference propagation, and the energy records are meaningful. 32^3 x 16 B = 512 KiB per volume;
//     per cascade 3 channels x (VPL, light, wavefront) = 4.5 MiB of volumes, 6 MiB of propagation
//     state in two buffers (llvmpipe loads and stores buffers about twice as fast as images), and
//     1 MiB of LPV voxel records; the bin stage's fragments-per-voxel count is voxel.resolution^3
//     x 4 B (8 MiB at the default 128^3).
//   - Reflection grid: reflection.resolution 64 by default (the thesis: 256^3, 128 MiB for level 0
//     in RGBA16F, too large for llvmpipe runs), RGBA16F, the colour word of Listing 4.27 per voxel,
//     radiance albedo / pi x the fine cascade's L0 irradiance (direction ignored, as the thesis),
//     sampled at the voxel centre (Listing 4.34's z + 0.0 is a 2D-array port error). The glossy
//     cone uses the mip level whose voxel equals its diameter (the thesis' log2(d / 0.25) is two
//     levels finer) and starts one voxel off the surface; composite.glossy is 0 and gi.glossy off because the scenes
//     and the reference path tracer are Lambertian.
//   - No sky (sky.radiance, docs/architecture.md "Sky"): the diffuse light is the propagated VPL
//     flux, read from the cell a point is in, and no ray leaves the grid; a sky would have to enter
//     as flux through the grid's faces, and L1 propagation (above) carries little of it more than a
//     few cells into the interior. Only the glossy cone (off by default) leaves the reflection grid; a
//     sky there alone would light reflections but not the diffuse light, so lpv has none.
//   - Bad input: parameters are range-checked before any GPU work (lpv.resolution 8..64, a power of
//     two: at most 2 x (9 volumes of 4 MiB + 48 MiB of state); reflection.resolution 16..256); fragments outside a grid are counted in the bin stage's
//     statistics (fragments_outside_fine/coarse) and dropped.
//
// References
//   seed 000 (Gomes, 000_3aa83555395ffea9.txt): section 2.2 (RSMs and K&D's LPV, lines 465-480);
//   section 3.4 (the technique, lines 933-1048: 3.4.1 voxelization and grid placement, 3.4.2
//   injection, 3.4.3 propagation, 3.4.4 reflection grid, 3.4.5 GI rendering); section 4.3 (the
//   implementation, lines 2231-2908, Listings 4.26-4.37); section 4.6 Table 4 (performance).
//   Kaplanyan & Dachsbacher, "Cascaded Light Propagation Volumes for Real-Time Indirect
//   Illumination", I3D 2010. Doghramachi, "Rasterized Voxel-based Dynamic Global Illumination",
//   GPU Pro 4. The technical note ../shared/guide/techniques/lpv.md (invariants 1-13, pitfalls).
#include "graph/technique.h"
#include "techniques/common/gbuffer_stage.h"
#include "techniques/common/light_stage.h"
#include "techniques/common/shadow_map_stage.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/lpv/stages.h"
#include "techniques/vct_grid/stages.h"

namespace voxlab {

static std::unique_ptr<Technique> makeLpv() {
  auto t = std::make_unique<Technique>(
      "lpv", "Light propagation volumes with voxel VPLs",
      "Lit voxels become VPLs in L1 SH grids; light spreads cell by cell, blocked by the voxels; surfaces read it back.");
  addVoxelizeStages(*t);
  t->add<LightStage>();
  t->add<ShadowMapStage>();
  t->add<lpv::PlaceStage>();
  t->add<lpv::BinStage>();
  t->add<lpv::InjectStage>();
  t->add<lpv::PropagateStage>();
  t->add<lpv::ReflectionStage>();
  t->add<GBufferStage>();
  t->add<lpv::GiStage>();
  t->add<CompositeStage>(lpv::compositeTerms());
  t->setFinalOutput("composite", "final");
  return t;
}

VOXLAB_REGISTER_TECHNIQUE("lpv", "Light propagation volumes with voxel VPLs", makeLpv);

}  // namespace voxlab
