#include "techniques/near_field/stages.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

#include "common/shared.h"
#include "core/error.h"
#include "gpu/shader_library.h"
#include "graph/scene_inputs.h"
#include "near_field/near_field_shared.h"
#include "techniques/common/binary_voxels_stage.h"
#include "techniques/common/light_stage.h"
#include "techniques/common/probe_recorder.h"
#include "techniques/common/sky.h"
#include "techniques/common/traced_image.h"
#include "techniques/common/voxel_space.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/near_field/bitmask.h"
#include "techniques/near_field/near_field.h"
#include "techniques/near_field/surface_query.h"

namespace voxlab::nearfield {

// rays.radius's default, in volume edges: above the volume's diagonal, sqrt 3.
constexpr float kWholeVolumeRadius = 1.75f;

int maxLevelOf(int res) {
  int l = 0;
  while ((1 << l) < res) ++l;
  return l;
}

BinaryGridGeometry BinaryGridGeometry::of(const Scene& scene, int res) {
  BinaryGridGeometry g;
  VoxelSpace space = VoxelSpace::fromScene(scene, res);
  g.origin = space.origin;
  g.edge = space.edge();
  g.resolution = res;
  g.columnSize = g.edge / float(res);
  g.sliceDepth = g.edge / float(kBinarySlices);
  g.voxelDiagonal = std::sqrt(2.0f * g.columnSize * g.columnSize + g.sliceDepth * g.sliceDepth);
  return g;
}

// Parameters of a walk from a surface and its RSM lookup, shared by rays and paths.
static void declareWalkParams(StageBuilder& b) {
  b.param(ParamDesc::integer("rays.steps", 64, 1, 1024,
                             "traversal step budget per ray (texels visited); running out is counted, not a miss",
                             "steps"));
  b.param(ParamDesc::integer("rays.start-level", 3, 0, 9, "hierarchy level a walk starts at (clamped to the top)"));
  b.param(ParamDesc::real("rays.normal-offset", 0.8, 0.0, 4.0, "ray origin offset along the normal", "voxel diagonals"));
  b.param(ParamDesc::real("rays.ray-offset", 0.6, 0.0, 4.0,
                          "ray origin offset along the ray, divided by cos(theta)", "voxel diagonals"));
  b.param(ParamDesc::real("rsm.distance-scale", 1.0, 0.0, 8.0,
                          "RSM validity: a hit is the RSM's surface when closer than max(voxel diagonal, scale * texel footprint), at most 4 diagonals"));
  b.param(ParamDesc::boolean("rsm.normal-check", true, "RSM validity: the sender must face the receiver"));
  b.param(ParamDesc::choice("rsm.validity", {"distance", "plane"}, 1,
                            "distance: |hit - RSM position| < epsilon (the paper); plane (the default): the hit lies "
                            "within a voxel diagonal of the RSM surface's plane (keeps the true hits the paper's test "
                            "rejects where light grazes the sender: sponza's sun)"));
}

// Uniforms of ray_common.glsl and traversal.glsl from those parameters.
static void setWalkUniforms(GLuint program, const ParamSet& params, const BinaryGridGeometry& geo) {
  setUniform(program, "u_budget", params.getInt("rays.steps"));
  setUniform(program, "u_normalCheck", params.getBool("rsm.normal-check") ? 1 : 0);
  setUniform(program, "u_planeTest", params.getChoice("rsm.validity") == "plane" ? 1 : 0);
  setUniform(program, "u_normalOffset", params.getFloat("rays.normal-offset"));
  setUniform(program, "u_rayOffset", params.getFloat("rays.ray-offset"));
  setUniform(program, "u_voxelDiagonal", geo.voxelDiagonal);
  setUniform(program, "u_epsilonScale", params.getFloat("rsm.distance-scale"));
  setUniform(program, "u_volumeOrigin", geo.origin);
  setUniform(program, "u_volumeEdge", geo.edge);
  setUniform(program, "u_gridRes", geo.resolution);
  setUniform(program, "u_maxLevel", maxLevelOf(geo.resolution));
  setUniform(program, "u_startLevel", params.getInt("rays.start-level"));
}

// Refuses, before anything is allocated, traced images beyond 1 GiB in all (one line naming the
// size and what would fit).
static void checkTracedBytes(const char* stage, int tw, int th, int bytesPerTexel) {
  const double mib = double(tw) * th * bytesPerTexel / (1024.0 * 1024.0);
  if (mib > 1024.0)
    throw Error(std::string(stage) + ": " + std::to_string(tw) + "x" + std::to_string(th) + " traced pixels need " +
                std::to_string(int(mib)) + " MiB of images, more than 1024 MiB; use rays.resolution=half or a smaller --size");
}

// The bitmask tables: OR (128 x 1), XOR (129 x 1), the ray masks (128 x 128) and their popcount.
static TextureDesc orTableDesc() { return imageDesc(kBinarySlices, 1, GL_RGBA32UI); }
static TextureDesc xorTableDesc() { return imageDesc(kBinarySlices + 1, 1, GL_RGBA32UI); }
static TextureDesc rayMasksDesc() { return imageDesc(kBinarySlices, kBinarySlices, GL_RGBA32UI); }
static TextureDesc rayMaskPopcountDesc() { return imageDesc(kBinarySlices, kBinarySlices, GL_R32UI); }

// The 2D OR hierarchy (RGBA32UI) and its popcount (R32UI): res x res with all mip levels.
static TextureDesc hierarchyDesc(int res, GLenum format) {
  TextureDesc d = imageDesc(res, res, format);
  d.levels = maxLevelOf(res) + 1;
  d.minFilter = GL_NEAREST_MIPMAP_NEAREST;  // integer textures need NEAREST filters to be complete
  return d;
}

// Voxel albedo / normal: RGBA8, res^3.
static TextureDesc voxelAttributeDesc(int res) {
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = GL_RGBA8;
  d.size = {res, res, res};
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}

constexpr int kRayCounters = 16 + 256;  // [0] step records, [1 + category], [16 + steps] histogram
// Cells the probe's brute-force DDA keeps (a segment crosses at most res + res + 128 cells: 1152 at
// 512 columns; the rest are counted as dropped).
constexpr size_t kMaxDdaCells = 2048;

// --- Bitmask tables ------------------------------------------------------------------------------

void BitmaskTablesStage::declare(StageBuilder& b) const {
  auto& orT = b.output("or-table", OutputKind::Image2D, kBitmaskColumns,
                       "128 x 1 RGBA32UI: texel k has only slice k set (MSB first in channel k >> 5)");
  orT.alongside = true;
  orT.tier = CaptureTier::Exact;
  auto& xorT = b.output("xor-table", OutputKind::Image2D, kBitmaskColumns,
                        "129 x 1 RGBA32UI: texel k has slices k..127 set; texel 128 is all zero");
  xorT.alongside = true;
  xorT.tier = CaptureTier::Exact;
  auto& rays = b.output("ray-masks", OutputKind::Image2D, kBitmaskColumns,
                        "128 x 128 RGBA32UI: texel (i, j) = XOR[i] ^ XOR[j+1], the slices i..j (used only for i <= j)");
  rays.tier = CaptureTier::Exact;
  auto& pc = b.output("ray-mask-popcount", OutputKind::Image2D, Semantic::Scalar,
                      "set slices per ray mask: j - i + 1 above the diagonal; below it the unused i > j half");
  pc.alongside = true;
  pc.tier = CaptureTier::Exact;
  b.texture("or-table", [](const ParamSet&, const ViewState&) { return orTableDesc(); });
  b.texture("xor-table", [](const ParamSet&, const ViewState&) { return xorTableDesc(); });
  b.texture("ray-masks", [](const ParamSet&, const ViewState&) { return rayMasksDesc(); });
  b.texture("ray-mask-popcount", [](const ParamSet&, const ViewState&) { return rayMaskPopcountDesc(); });
}

void BitmaskTablesStage::execute(StageContext& ctx) {
  Texture& orTex = ctx.board.ensureTexture("or-table", orTableDesc());
  Texture& xorTex = ctx.board.ensureTexture("xor-table", xorTableDesc());
  Texture& rayTex = ctx.board.ensureTexture("ray-masks", rayMasksDesc());
  Texture& pcTex = ctx.board.ensureTexture("ray-mask-popcount", rayMaskPopcountDesc());
  auto orT = orTable();
  auto xorT = xorTable();
  glTextureSubImage2D(orTex.id(), 0, 0, 0, kBinarySlices, 1, GL_RGBA_INTEGER, GL_UNSIGNED_INT, orT.data());
  glTextureSubImage2D(xorTex.id(), 0, 0, 0, kBinarySlices + 1, 1, GL_RGBA_INTEGER, GL_UNSIGNED_INT, xorT.data());
  GLuint program = ctx.shaders.program({"near_field/ray_masks.comp.glsl"});
  glUseProgram(program);
  glBindImageTexture(0, xorTex.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32UI);
  glBindImageTexture(1, rayTex.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32UI);
  glBindImageTexture(2, pcTex.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32UI);
  dispatchCompute({kBinarySlices, kBinarySlices, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  ctx.stats["table_bytes"] = double(orTex.byteSize() + xorTex.byteSize() + rayTex.byteSize());
}

// --- Hierarchy -----------------------------------------------------------------------------------

void HierarchyStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.read("binary-voxels");
  b.read("binary-popcount");
  auto& h = b.output("bitmask-hierarchy", OutputKind::Image2D, kBitmaskColumns,
                     "RGBA32UI columns per level: level l+1 texel = OR of its 2x2 children at level l (all 128 slices)");
  h.tier = CaptureTier::Exact;
  auto& pc = b.output("hierarchy-popcount", OutputKind::Image2D, Semantic::Scalar,
                      "set slices per column at every level (never decreases from a level to the next)");
  pc.alongside = true;
  pc.tier = CaptureTier::Exact;
  b.texture("bitmask-hierarchy", [](const ParamSet& p, const ViewState&) {
    return hierarchyDesc(p.getInt("voxel.resolution"), GL_RGBA32UI);
  });
  b.texture("hierarchy-popcount", [](const ParamSet& p, const ViewState&) {
    return hierarchyDesc(p.getInt("voxel.resolution"), GL_R32UI);
  });
}

int HierarchyStage::iterations(const ParamSet& params) const {
  return std::max(maxLevelOf(params.getInt("voxel.resolution")), 1);
}

void HierarchyStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  const int maxLevel = maxLevelOf(res);
  Texture& h = ctx.board.ensureTexture("bitmask-hierarchy", hierarchyDesc(res, GL_RGBA32UI));
  Texture& pc = ctx.board.ensureTexture("hierarchy-popcount", hierarchyDesc(res, GL_R32UI));
  ctx.board.place("bitmask-hierarchy", VoxelSpace::fromScene(ctx.scene, res).box());  // slices in metres in its views
  if (ctx.iteration == 0) {
    const uint32_t zero[4] = {0, 0, 0, 0};
    for (int l = 1; l <= maxLevel; ++l) {
      glClearTexImage(h.id(), l, GL_RGBA_INTEGER, GL_UNSIGNED_INT, zero);
      glClearTexImage(pc.id(), l, GL_RED_INTEGER, GL_UNSIGNED_INT, zero);
    }
    glCopyImageSubData(ctx.board.texture("binary-voxels").id(), GL_TEXTURE_2D, 0, 0, 0, 0, h.id(), GL_TEXTURE_2D, 0,
                       0, 0, 0, res, res, 1);
    glCopyImageSubData(ctx.board.texture("binary-popcount").id(), GL_TEXTURE_2D, 0, 0, 0, 0, pc.id(), GL_TEXTURE_2D,
                       0, 0, 0, 0, res, res, 1);
  }
  const int fine = ctx.iteration;
  if (fine < maxLevel) {
    const int coarseRes = res >> (fine + 1);
    GLuint program = ctx.shaders.program({"near_field/mipmap.comp.glsl"});
    setUniform(program, "u_coarseRes", coarseRes);
    glUseProgram(program);
    glBindImageTexture(0, h.id(), fine, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32UI);
    glBindImageTexture(1, h.id(), fine + 1, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32UI);
    glBindImageTexture(2, pc.id(), fine + 1, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32UI);
    dispatchCompute({coarseRes, coarseRes, 1}, {8, 8, 1});
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
  }
  ctx.stats["levels"] = maxLevel + 1;
  ctx.stats["hierarchy_bytes"] = double(h.byteSize());
}

// --- Rays ----------------------------------------------------------------------------------------

void RaysStage::declare(StageBuilder& b) const {
  b.read(kSceneGeometryInput);  // its CPU checks walk the scene's triangles
  b.param(voxelResolutionParam());
  b.param(kTracedRays.resolutionParam());
  b.param(ParamDesc::integer("rays.count", 8, 1, 256, "rays per pixel, one per iteration", "rays"));
  // The default reaches past the volume's diagonal (sqrt 3 = 1.732 edges): every ray runs until it
  // meets a voxel or leaves the volume, so no light inside the volume is left out as "far field".
  b.param(ParamDesc::real("rays.radius", kWholeVolumeRadius, 0.01, 2.0,
                          "longest ray (near-field radius), as a fraction of the voxel volume's edge; the default, "
                          "1.75, exceeds the volume's diagonal (sqrt 3): every ray crosses the whole volume"));
  declareWalkParams(b);
  b.param(ParamDesc::real("rays.spread", 1.0, 0.05, 1.0,
                          "fraction of the cosine-weighted hemisphere sampled (1 = all); the estimator is scaled by it"));
  b.param(ParamDesc::boolean("rays.pixel-shift", true, "per-pixel directions: the pixels of a 4 x 4 tile take consecutive blocks of one Sobol "
                             "(0,2)-sequence, shifted by a hashed offset per tile; off: every pixel the same Hammersley set"));
  b.param(ParamDesc::real("probe.x", 0.5, 0.0, 1.0, "horizontal position of the probed pixel (0 left, 1 right)"));
  b.param(ParamDesc::real("probe.y", 0.5, 0.0, 1.0, "vertical position of the probed pixel (0 top, 1 bottom)"));
  b.param(ParamDesc::integer("probe.ray", 0, 0, 255, "ray index whose traversal the probe records"));
  b.probe(ProbeDesc::screen("probe.x", "probe.y"));  // a click on a camera image picks the recorded pixel
  declareSky(b);  // rays that leave the volume within the radius
  b.readView();
  b.read("bitmask-hierarchy");
  b.read("ray-masks");
  b.read("position");
  b.read("normal");
  b.read("albedo");
  b.read("rsm-position");
  b.read("rsm-normal");
  b.read("rsm-radiance");
  b.read("light");
  b.read(kSceneLightsInput);  // the light's type: programs are built for it (lightKindDefines)
  b.write("rays.counters");
  b.output("indirect", OutputKind::Image2D, Semantic::RadianceHDR,
           "near-field indirect radiance so far: (albedo / N) * sum of valid hits' reflected radiance (at rays.resolution)")
      .referenceMode = "indirect-1";
  // Its own semantic: a colour per category, a legend and the category's name under the cursor
  // (src/techniques/near_field/views/ray_category.cpp).
  auto& cat = b.output("ray-category", OutputKind::Image2D, kRayCategory,
                       "the last ray's outcome: 0 valid, 1 no hit, 2 not in the RSM, 3 too far from the RSM's surface, "
                       "4 wrong facing, 5 step budget spent, 6 dropped (offset > radius), 7 no receiver");
  cat.alongside = true;
  cat.tier = CaptureTier::Exact;
  auto& steps = b.output("ray-steps", OutputKind::Image2D, Semantic::Scalar, "traversal steps per pixel, summed over the rays so far");
  steps.alongside = true;
  steps.tier = CaptureTier::Exact;
  b.output("hit-position", OutputKind::Image2D, Semantic::Scalar, "the last ray's hit point (world xyz), w = 1 where it hit").alongside = true;
  BufferLayout sl;
  sl.stride = sizeof(gpu::TraversalStep);
  const char* u32Names[] = {"step", "level", "texel-x", "texel-y", "first-slice", "last-slice", "action", "hit-slice",
                            "ray-mask-r", "ray-mask-g", "ray-mask-b", "ray-mask-a",
                            "and-r", "and-g", "and-b", "and-a"};
  for (int i = 0; i < 16; ++i) sl.fields.push_back({u32Names[i], FieldType::U32, uint32_t(4 * i), FieldRole::Other});
  sl.fields.push_back({"t-enter", FieldType::F32, 64, FieldRole::Other});
  sl.fields.push_back({"t-exit", FieldType::F32, 68, FieldRole::Other});
  sl.fields.push_back({"t-end", FieldType::F32, 72, FieldRole::Other});
  sl.countResource = "rays.counters";
  sl.countOffset = 0;
  auto& st = b.output("traversal-steps", OutputKind::Buffer, kTraversalSteps,
                      "every step of the probed pixel's probe.ray walk: level, texel, slice range, ray mask, AND, "
                      "action (8 descend, 9 advance, 0 hit)");
  st.alongside = true;
  st.layout = sl;
  st.tier = CaptureTier::Exact;
  st.probeRecord = true;  // checked and drawn by src/techniques/near_field/views/bitmask_columns.cpp
  BufferLayout pl;
  pl.stride = sizeof(gpu::ProbeRay);
  pl.fields = {{"receiver", FieldType::Vec4, 0, FieldRole::Position},
               {"direction", FieldType::Vec4, 16, FieldRole::Other},
               {"origin", FieldType::Vec4, 32, FieldRole::Other},
               {"hit-point", FieldType::Vec4, 48, FieldRole::Other},
               {"hit-x", FieldType::U32, 64, FieldRole::Other},
               {"hit-y", FieldType::U32, 68, FieldRole::Other},
               {"hit-slice", FieldType::U32, 72, FieldRole::Other},
               {"termination", FieldType::U32, 76, FieldRole::Other},
               {"rsm-sample", FieldType::Vec4, 80, FieldRole::Other},
               {"rsm-radiance", FieldType::Vec4, 96, FieldRole::Color},
               {"steps", FieldType::Vec4, 112, FieldRole::Other},
               {"surface", FieldType::Vec4, 128, FieldRole::Other},
               {"surface-gap", FieldType::Vec4, 144, FieldRole::Other},
               {"rsm-position", FieldType::Vec4, 160, FieldRole::Other},
               {"rsm-normal", FieldType::Vec4, 176, FieldRole::Other}};
  BufferLayout dl;
  dl.stride = 32;
  dl.fields = {{"cell", FieldType::Vec3, 0, FieldRole::Other},
               {"t-enter", FieldType::F32, 12, FieldRole::Other},
               {"set", FieldType::U32, 16, FieldRole::Other},
               {"walk-hit", FieldType::U32, 20, FieldRole::Other}};
  dl.countResource = "probe-dda.count";
  auto& dda = b.output("probe-dda", OutputKind::Buffer, kProbeDda,
                       "the probed ray's segment walked cell by cell by a brute-force 3D DDA on the CPU over the same "
                       "binary grid (x, y, slice; t entering it; 1 where set: the last is the DDA's hit; walk-hit 1 where "
                       "the hierarchical walk hit that cell), beside the hierarchical walk");
  dda.alongside = true;
  dda.layout = dl;
  dda.tier = CaptureTier::Exact;
  dda.probeRecord = true;
  b.write("probe-dda.count");
  b.buffer("probe-dda", [](const ParamSet&, const ViewState&) { return size_t(32) * kMaxDdaCells; });
  b.buffer("probe-dda.count", [](const ParamSet&, const ViewState&) { return size_t(4); });
  b.read("binary-voxels");
  auto& pr = b.output("probe-ray", OutputKind::Buffer, kProbeRay,
           "the probed ray: receiver, direction (w cos), origin (w radius left), hit point (w distance), hit voxel, "
           "termination (0 hit, 1 left, 2 budget, 3 outside, 4 dropped), RSM texel/distance/epsilon, L~ (w category), "
           "steps, the true surface point on the same ray (w t; exact ray/triangle query on the CPU) and its distance "
           "from the hit voxel in voxels (x largest axis, y Euclidean, z along the ray in voxel diagonals, w triangle), "
           "the RSM texel's position (w footprint) and normal (w: 1 normal test on, + 2 plane validity)");
  pr.alongside = true;
  pr.layout = pl;
  pr.probeRecord = true;
  kTracedRays.declareImage(b, "indirect", GL_RGBA32F);
  kTracedRays.declareImage(b, "ray-category", GL_R32UI);
  kTracedRays.declareImage(b, "ray-steps", GL_R32UI);
  kTracedRays.declareImage(b, "hit-position", GL_RGBA32F);
  b.buffer("traversal-steps", [](const ParamSet&, const ViewState&) {
    return sizeof(gpu::TraversalStep) * NF_MAX_TRAVERSAL_STEPS;
  });
  b.buffer("probe-ray", [](const ParamSet&, const ViewState&) { return sizeof(gpu::ProbeRay); });
  b.buffer("rays.counters", [](const ParamSet&, const ViewState&) { return size_t(kRayCounters) * 4; });
}

int RaysStage::iterations(const ParamSet& params) const { return params.getInt("rays.count"); }

void RaysStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  const int rayCount = ctx.params.getInt("rays.count");
  const BinaryGridGeometry geo = BinaryGridGeometry::of(ctx.scene, res);
  const int s = kTracedRays.scale(ctx.params);
  const glm::ivec2 traced = kTracedRays.size(ctx.params, ctx.view);
  const int tw = traced.x, th = traced.y;
  checkTracedBytes("rays", tw, th, 16 + 4 + 4 + 16);
  Texture& indirect = ctx.board.ensureTexture("indirect", imageDesc(tw, th, GL_RGBA32F));
  Texture& category = ctx.board.ensureTexture("ray-category", imageDesc(tw, th, GL_R32UI));
  Texture& steps = ctx.board.ensureTexture("ray-steps", imageDesc(tw, th, GL_R32UI));
  Texture& hits = ctx.board.ensureTexture("hit-position", imageDesc(tw, th, GL_RGBA32F));
  Buffer& records = ctx.board.ensureBuffer("traversal-steps", sizeof(gpu::TraversalStep) * NF_MAX_TRAVERSAL_STEPS);
  Buffer& probe = ctx.board.ensureBuffer("probe-ray", sizeof(gpu::ProbeRay));
  constexpr int kCounters = kRayCounters;
  Buffer& counters = ctx.board.ensureBuffer("rays.counters", kCounters * 4);
  if (ctx.iteration == 0) {
    const float none[4] = {0, 0, 0, 0};
    const uint32_t zero[4] = {0, 0, 0, 0};
    glClearTexImage(indirect.id(), 0, GL_RGBA, GL_FLOAT, none);
    glClearTexImage(hits.id(), 0, GL_RGBA, GL_FLOAT, none);
    glClearTexImage(steps.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, zero);
    std::vector<uint32_t> z(kCounters, 0);
    counters.upload(z.data(), z.size() * 4);
    gpu::ProbeRay empty{};
    probe.upload(&empty, sizeof(empty));
  }
  int probeX = std::min(int(ctx.params.getFloat("probe.x") * tw), tw - 1);
  int probeY = std::min(int((1.0f - ctx.params.getFloat("probe.y")) * th), th - 1);

  // The tracer, every pixel with nothing recorded, and the recorder, which walks the probed pixel's
  // probed ray again and records its steps (probe_recorder.h).
  const auto [tracer, recorder] = tracerAndRecorder(ctx.shaders, {"near_field/rays.comp.glsl"}, lightKindDefines(ctx.scene));
  for (GLuint program : {tracer, recorder}) {
    setUniform(program, "u_rayIndex", ctx.iteration);
    setUniform(program, "u_rayCount", rayCount);
    setUniform(program, "u_traceScale", s);
    setWalkUniforms(program, ctx.params, geo);
    setUniform(program, "u_shift", ctx.params.getBool("rays.pixel-shift") ? 1 : 0);
    setUniform(program, "u_radius", ctx.params.getFloat("rays.radius") * geo.edge);
    setUniform(program, "u_spread", ctx.params.getFloat("rays.spread"));
    setUniform(program, "u_probeRay", ctx.params.getInt("probe.ray"));
    glProgramUniform2i(program, glGetUniformLocation(program, "u_probePixel"), probeX, probeY);
    setSkyUniforms(program, ctx.params, ctx.scene);
  }
  glBindTextureUnit(1, ctx.board.texture("position").id());
  glBindTextureUnit(2, ctx.board.texture("normal").id());
  glBindTextureUnit(3, ctx.board.texture("albedo").id());
  glBindTextureUnit(4, ctx.board.texture("bitmask-hierarchy").id());
  glBindTextureUnit(5, ctx.board.texture("ray-masks").id());
  glBindTextureUnit(6, ctx.board.texture("rsm-position").id());
  glBindTextureUnit(7, ctx.board.texture("rsm-normal").id());
  glBindTextureUnit(8, ctx.board.texture("rsm-radiance").id());
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, NF_BINDING_TRAVERSAL_STEPS, records.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, NF_BINDING_PROBE_RAY, probe.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, NF_BINDING_RAY_COUNTERS, counters.id());
  glBindImageTexture(0, indirect.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  glBindImageTexture(1, category.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32UI);
  glBindImageTexture(2, steps.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
  glBindImageTexture(3, hits.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glUseProgram(tracer);
  dispatchCompute({tw, th, 1}, {8, 8, 1});
  const bool probedRay = ctx.iteration == ctx.params.getInt("probe.ray");
  if (probedRay) dispatchRecorder(recorder, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);

  if (ctx.iteration == rayCount - 1) {
    std::vector<uint32_t> c(kCounters);
    auto bytes = counters.download(kCounters * 4);
    std::memcpy(c.data(), bytes.data(), bytes.size());
    const char* names[NF_CATEGORIES] = {"valid", "no_hit", "not_in_rsm", "too_far", "wrong_facing", "budget_spent",
                                        "dropped", "no_receiver"};
    double rays = 0;
    for (int k = 0; k < NF_CATEGORIES; ++k) {
      ctx.stats[std::string("rays_") + names[k]] = c[1 + k];
      rays += c[1 + k];
    }
    double stepSum = 0, seen = 0;
    int p99 = 0;
    for (int k = 0; k < 256; ++k) stepSum += double(k) * c[16 + k];
    for (int k = 0; k < 256; ++k) {
      seen += c[16 + k];
      if (seen >= 0.99 * rays) { p99 = k; break; }
    }
    ctx.stats["rays_traced"] = rays;
    ctx.stats["steps_per_ray_mean"] = rays > 0 ? stepSum / rays : 0;
    ctx.stats["steps_per_ray_p99"] = p99;  // 255 = 255 or more
    ctx.stats["probe_step_records"] = c[0];
    ctx.stats["probe_step_records_dropped"] = c[0] > NF_MAX_TRAVERSAL_STEPS ? c[0] - NF_MAX_TRAVERSAL_STEPS : 0;
    ctx.stats["voxel_diagonal_m"] = geo.voxelDiagonal;
    ctx.stats["radius_m"] = ctx.params.getFloat("rays.radius") * geo.edge;
  }
  ctx.stats["probe_x"] = probeX;
  ctx.stats["probe_y_from_top"] = th - 1 - probeY;
  if (ctx.iteration == 0) {
    const uint32_t zero = 0;
    ctx.board.ensureBuffer("probe-dda.count", 4).upload(&zero, 4);
    ctx.board.ensureBuffer("probe-dda", 32 * kMaxDdaCells);
  }
  if (probedRay) {
    recordProbeDda(ctx, geo, probe);
    recordProbeSurface(ctx, geo, probe);
  }
}

// The probed ray's segment walked by the CPU's brute-force DDA over the level-0 grid, so the
// student sees the voxels the hierarchy skipped beside the walk's steps (and its hit beside the
// DDA's: the same voxel, or both miss, except at corner ties; NearFieldTraversal.* tests that on
// many segments).
void RaysStage::recordProbeDda(StageContext& ctx, const BinaryGridGeometry& geo, Buffer& probe) {
  gpu::ProbeRay p;
  std::memcpy(&p, probe.download(sizeof(p)).data(), sizeof(p));
  struct Rec {
    float cell[3], tEnter;
    uint32_t set, walkHit, pad[2];
  };
  std::vector<Rec> recs;
  uint32_t dropped = 0;
  const bool started = p.receiver.w > 0.5f && p.result.w != NF_END_OUTSIDE && p.result.w != NF_END_DROPPED;
  if (started) {
    const int res = geo.resolution;
    const std::vector<BitColumn> grid = readBitColumns(ctx.board.texture("binary-voxels").id(), 0, res, res);
    const glm::vec3 o = (glm::vec3(p.origin) - geo.origin) / geo.edge;
    const glm::vec3 e = (glm::vec3(p.origin) + glm::vec3(p.direction) * p.origin.w - geo.origin) / geo.edge;
    std::vector<DdaCell> cells;
    bruteForceDda(grid, res, o, e, &cells);
    for (const DdaCell& c : cells) {
      if (recs.size() >= kMaxDdaCells) { ++dropped; continue; }
      const bool set = hasSlice(grid[size_t(c.cell.y) * res + c.cell.x], c.cell.z);
      const bool walkHit = p.result.w == NF_END_HIT && glm::uvec3(c.cell) == glm::uvec3(p.result);
      recs.push_back({{float(c.cell.x), float(c.cell.y), float(c.cell.z)}, c.tEnter, set ? 1u : 0u, walkHit ? 1u : 0u, {0, 0}});
    }
  }
  if (!recs.empty()) ctx.board.buffer("probe-dda").upload(recs.data(), recs.size() * sizeof(Rec));
  const uint32_t count = uint32_t(recs.size());
  ctx.board.buffer("probe-dda.count").upload(&count, 4);
  ctx.stats["probe_dda_cells"] = count;
  ctx.stats["probe_dda_cells_dropped"] = dropped;
}

// The true surface along the probed ray (the same origin, direction and radius as the walk) beside
// the voxel the walk stopped in: conservative voxels make the voxel containing that point set, so
// the walk stops there or earlier (NearFieldProbe.* measures how much earlier over many rays).
void RaysStage::recordProbeSurface(StageContext& ctx, const BinaryGridGeometry& geo, Buffer& probe) {
  gpu::ProbeRay p;
  std::memcpy(&p, probe.download(sizeof(p)).data(), sizeof(p));
  p.surface = glm::vec4(0.0f, 0.0f, 0.0f, -1.0f);
  p.surfaceGap = glm::vec4(-1.0f);
  const bool started = p.receiver.w > 0.5f && p.result.w != NF_END_OUTSIDE && p.result.w != NF_END_DROPPED;
  if (started) {
    const glm::vec3 o(p.origin), d(p.direction);
    const SurfaceHit s = firstSurfaceAlong(ctx.scene, o, d, p.origin.w);
    if (s.hit) {
      p.surface = glm::vec4(o + d * s.t, s.t);
      p.surfaceGap.w = float(s.triangle);
      if (p.result.w == NF_END_HIT) {
        const VoxelGap g = gapToVoxel(geo, glm::ivec3(glm::uvec3(p.result)), glm::vec3(p.surface));
        p.surfaceGap.x = g.chebyshev;
        p.surfaceGap.y = g.euclidean;
        p.surfaceGap.z = (s.t - p.hitPoint.w) / geo.voxelDiagonal;
      }
    }
  }
  probe.upload(&p, sizeof(p));
  ctx.stats["probe_surface_t_m"] = p.surface.w;
  ctx.stats["probe_surface_gap_voxels"] = p.surfaceGap.x;
}

// --- Voxel path tracing ---------------------------------------------------------------------------

void VoxelAttributesStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.read("fragments");
  b.read("fragments.count");
  b.output("voxel-albedo", OutputKind::Volume3D, Semantic::Color,
           "albedo per voxel (RGBA8, a = 1 where occupied): the largest packed value of its fragments");
  b.output("voxel-normal", OutputKind::Volume3D, Semantic::Color,
           "normal per voxel, stored as n * 0.5 + 0.5 (RGBA8, a = 1 where occupied)");
  for (const char* name : {"voxel-albedo", "voxel-normal"})
    b.texture(name, [](const ParamSet& p, const ViewState&) { return voxelAttributeDesc(p.getInt("voxel.resolution")); });
}

void VoxelAttributesStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  const TextureDesc d = voxelAttributeDesc(res);
  Texture& albedo = ctx.board.ensureTexture("voxel-albedo", d);
  Texture& normal = ctx.board.ensureTexture("voxel-normal", d);
  const uint32_t zero = 0;
  glClearTexImage(albedo.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, &zero);
  glClearTexImage(normal.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, &zero);
  // r32ui views for the atomics (RGBA8 and R32UI share the 32-bit view class).
  GLuint views[2];
  glGenTextures(2, views);
  glTextureView(views[0], GL_TEXTURE_3D, albedo.id(), GL_R32UI, 0, 1, 0, 1);
  glTextureView(views[1], GL_TEXTURE_3D, normal.id(), GL_R32UI, 0, 1, 0, 1);
  // Labelled like every other GL object (src/gpu/resources.h), so a debug message names them.
  glObjectLabel(GL_TEXTURE, views[0], -1, "voxel-albedo.r32ui-view");
  glObjectLabel(GL_TEXTURE, views[1], -1, "voxel-normal.r32ui-view");
  const uint32_t fragments = voxelFragmentCount(ctx.board);
  GLuint program = ctx.shaders.program({"near_field/voxel_attributes.comp.glsl"});
  setUniform(program, "u_fragmentCount", fragments);
  setUniform(program, "u_resolution", res);
  glUseProgram(program);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, ctx.board.buffer("fragments").id());
  glBindImageTexture(0, views[0], 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
  glBindImageTexture(1, views[1], 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
  if (fragments > 0) dispatchCompute({int(fragments), 1, 1}, {64, 1, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  glDeleteTextures(2, views);
  ctx.stats["fragments_read"] = fragments;
}

void PathsStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(kTracedRays.resolutionParam());
  b.param(ParamDesc::integer("paths.count", 4, 1, 64, "paths per traced pixel", "paths"));
  b.param(ParamDesc::integer("paths.bounces", 2, 1, 8,
                             "diffuse bounces per path (1 = one indirect bounce, as near-field without a radius)"));
  declareWalkParams(b);
  declareSky(b);  // paths that leave the volume
  b.readView();
  b.read("bitmask-hierarchy");
  b.read("ray-masks");
  b.read("voxel-albedo");
  b.read("voxel-normal");
  b.read("position");
  b.read("normal");
  b.read("albedo");
  b.read("rsm-position");
  b.read("rsm-normal");
  b.read("rsm-radiance");
  b.read("light");
  b.read(kSceneLightsInput);  // the light's type: programs are built for it (lightKindDefines)
  b.write("paths.normal");
  b.write("paths.weight");
  b.output("indirect", OutputKind::Image2D, Semantic::RadianceHDR,
           "indirect radiance of paths.bounces diffuse bounces so far: (1/P) sum over paths of sum_k W_k L~_k")
      .referenceMode = "indirect-{paths.bounces}";  // K bounces: the reference's r in {2, ..., K+1}
  b.output("path-vertex", OutputKind::Image2D, Semantic::Scalar,
           "the current path vertex per pixel (world xyz), w = 1 while the path is alive").alongside = true;
  for (const char* name : {"indirect", "path-vertex", "paths.normal", "paths.weight"})
    kTracedRays.declareImage(b, name, GL_RGBA32F);
}

int PathsStage::iterations(const ParamSet& params) const {
  return params.getInt("paths.count") * params.getInt("paths.bounces");
}

void PathsStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  const int paths = ctx.params.getInt("paths.count"), bounces = ctx.params.getInt("paths.bounces");
  const BinaryGridGeometry geo = BinaryGridGeometry::of(ctx.scene, res);
  const int s = kTracedRays.scale(ctx.params);
  const glm::ivec2 traced = kTracedRays.size(ctx.params, ctx.view);
  const int tw = traced.x, th = traced.y;
  checkTracedBytes("paths", tw, th, 4 * 16);
  Texture& indirect = ctx.board.ensureTexture("indirect", imageDesc(tw, th, GL_RGBA32F));
  Texture& vertex = ctx.board.ensureTexture("path-vertex", imageDesc(tw, th, GL_RGBA32F));
  Texture& normal = ctx.board.ensureTexture("paths.normal", imageDesc(tw, th, GL_RGBA32F));
  Texture& weight = ctx.board.ensureTexture("paths.weight", imageDesc(tw, th, GL_RGBA32F));
  if (ctx.iteration == 0) {
    const float none[4] = {0, 0, 0, 0};
    glClearTexImage(indirect.id(), 0, GL_RGBA, GL_FLOAT, none);
  }
  GLuint program = ctx.shaders.program({"near_field/paths.comp.glsl"}, lightKindDefines(ctx.scene));
  setWalkUniforms(program, ctx.params, geo);
  setUniform(program, "u_path", ctx.iteration / bounces);
  setUniform(program, "u_pathCount", paths);
  setUniform(program, "u_bounce", ctx.iteration % bounces);
  setUniform(program, "u_traceScale", s);
  // A bounce's ray may cross the whole volume (its diagonal); the walk clips it to the volume.
  setUniform(program, "u_maxLength", std::sqrt(3.0f) * geo.edge);
  setSkyUniforms(program, ctx.params, ctx.scene);
  glUseProgram(program);
  glBindTextureUnit(1, ctx.board.texture("position").id());
  glBindTextureUnit(2, ctx.board.texture("normal").id());
  glBindTextureUnit(3, ctx.board.texture("albedo").id());
  glBindTextureUnit(4, ctx.board.texture("bitmask-hierarchy").id());
  glBindTextureUnit(5, ctx.board.texture("ray-masks").id());
  glBindTextureUnit(6, ctx.board.texture("rsm-position").id());
  glBindTextureUnit(7, ctx.board.texture("rsm-normal").id());
  glBindTextureUnit(8, ctx.board.texture("rsm-radiance").id());
  glBindTextureUnit(9, ctx.board.texture("voxel-albedo").id());
  glBindTextureUnit(10, ctx.board.texture("voxel-normal").id());
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  glBindImageTexture(0, indirect.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  glBindImageTexture(1, vertex.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  glBindImageTexture(2, normal.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  glBindImageTexture(3, weight.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  dispatchCompute({tw, th, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  ctx.stats["paths_per_pixel"] = paths;
  ctx.stats["bounces"] = bounces;
}

// --- Filter ------------------------------------------------------------------------------------

AtrousFilterConfig filterConfig(const char* referenceMode, const char* raysParam) {
  AtrousFilterConfig c;
  c.referenceMode = referenceMode;
  c.raysParam = raysParam;
  c.traced = kTracedRays;
  c.sharedParams = {voxelResolutionParam()};
  // A voxel column: the hit points, and so the noise's spatial scale, are voxel-accurate, and the
  // neighbours on one flat surface lie on its plane to well within that.
  c.depthScale = [](const ParamSet& p, const Scene& scene) {
    return BinaryGridGeometry::of(scene, p.getInt("voxel.resolution")).columnSize;
  };
  return c;
}

// --- Composite -----------------------------------------------------------------------------------

CompositeTerms compositeTerms() {
  CompositeTerms t;
  t.summary = "Add the direct light and the near-field indirect light, then tonemap.";
  t.combinedHelp = "direct + near-field indirect, linear radiance";
  t.params = {voxelResolutionParam(), kTracedRays.resolutionParam(), compositeExposureParam(),
              ParamDesc::real("composite.indirect", 1.0, 0.0, 4.0, "weight of the indirect term (1 = physical)")};
  t.indirect = {{"indirect-filtered", "composite.indirect"}};
  t.traced = kTracedRays;
  t.planeDistance = [](const ParamSet& p, const Scene& scene) {
    return 2.0f * BinaryGridGeometry::of(scene, p.getInt("voxel.resolution")).columnSize;
  };
  return t;
}

}  // namespace voxlab::nearfield
