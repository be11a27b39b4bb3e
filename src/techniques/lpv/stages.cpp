// The stages of lpv (see lpv.cpp for the overview and the choice of every default).
#include "techniques/lpv/stages.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

#include "common/shared.h"
#include "core/error.h"
#include "gpu/shader_library.h"
#include "scene/scene.h"
#include "techniques/common/voxel_space.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/lpv/reference.h"
#include "techniques/lpv/sh.h"

namespace voxlab::lpv {

const char* const kCascadeNames[kCascades] = {"fine", "coarse"};
const char* const kChannelNames[3] = {"red", "green", "blue"};

std::string shVolume(const char* prefix, int cascade, int channel) {
  return std::string(prefix) + "-" + kCascadeNames[cascade] + "-" + kChannelNames[channel];
}
static std::string voxelBuffer(int cascade) { return std::string("voxels-") + kCascadeNames[cascade]; }
static std::string voxelColourVolume(int cascade) { return std::string("voxel-colour-") + kCascadeNames[cascade]; }

// --- Parameters (one definition each; every stage that needs one declares the same) -------------

static ParamDesc resolutionParam() {
  return ParamDesc::integer("lpv.resolution", 32, 8, 64, "cells along each axis of each cascade", "cells").pow2();
}
static ParamDesc fineExtentParam() {
  return ParamDesc::real("lpv.fine-extent", 1.5, 0.25, 4.0,
                         "edge of the fine grid as a multiple of the scene's largest extent (1.5: the whole scene "
                         "inside the cascade blend shell)");
}
static ParamDesc cascadeRatioParam() {
  return ParamDesc::real("lpv.cascade-ratio", 2.0, 1.25, 4.0,
                         "coarse cell / fine cell (2: the thesis' 8x volume; GPU Pro 4 uses 1.6)");
}
static ParamDesc centreParam() {
  return ParamDesc::choice("lpv.centre", {"scene", "camera"}, 0,
                           "centre of the grids: the scene's bounds, or ahead of the camera as GPU Pro 4 "
                           "(fine at camera + forward * half its extent)");
}
static ParamDesc stepsParam() {
  return ParamDesc::integer("lpv.steps", 8, 1, 64, "propagation steps (iterations); light travels one cell per step", "steps");
}
// Cell indices, so that the viewer's volume probe (a click on a cell of an lpv volume) sets them;
// -1 (the default) is the middle cell, larger values are clamped to the grid.
static ParamDesc probeParam(const char* axis) {
  return ParamDesc::integer(std::string("probe.cell-") + axis, -1, -1, 1023,
                            std::string("picked cell along ") + axis + " (-1: the middle cell; clamped to the grid)",
                            "cells");
}
static ParamDesc probeCascadeParam() {
  return ParamDesc::choice("probe.cascade", {"fine", "coarse"}, 0, "cascade of the picked cell");
}
static ParamDesc lookupOffsetParam() {
  return ParamDesc::real("gi.lookup-offset", 0.5, 0.0, 1.0,
                         "surfaces read the grid this far along their normal (against self-illumination)", "cells");
}

static glm::ivec3 probeCell(const ParamSet& p) {
  int res = p.getInt("lpv.resolution");
  auto c = [&](const char* n) {
    const int v = p.getInt(n);
    return v < 0 ? res / 2 : std::min(v, res - 1);
  };
  return {c("probe.cell-x"), c("probe.cell-y"), c("probe.cell-z")};
}

static TextureDesc shDesc(int res) {
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = GL_RGBA32F;
  d.size = {res, res, res};
  d.minFilter = d.magFilter = GL_LINEAR;
  return d;
}
static TextureDesc screenDesc(const ViewState& view, GLenum format) {
  TextureDesc d;
  d.format = format;
  d.size = {view.width, view.height, 1};
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}
// The descs and sizes execute() allocates, shared with declare() (the resource budget).
static TextureDesc voxelColourDesc(int res) {
  TextureDesc d = shDesc(res);
  d.format = GL_RGBA8;
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}
static size_t cellCount(const ParamSet& p) {
  const size_t res = size_t(p.getInt("lpv.resolution"));
  return res * res * res;
}
static size_t voxelBufferBytes(const ParamSet& p) { return sizeof(gpu::LpvVoxel) * cellCount(p); }
static std::string occlusionBuffer(int cascade) { return std::string("occlusion-") + kCascadeNames[cascade]; }
static size_t occlusionBytes(const ParamSet& p) { return sizeof(gpu::LpvOcclusion) * cellCount(p); }
static size_t voxelFragmentsBytes(const ParamSet& p) {
  const size_t res = size_t(p.getInt("voxel.resolution"));
  return 4 * res * res * res;
}

float areaUnits(float cellSize, float voxelSize) {
  const double edge = std::ceil(double(cellSize) / double(voxelSize)) + 1.0;
  return float(std::min(65536.0, std::floor(double(1u << 31) / (edge * edge * edge))));
}
static size_t unshiftedBytes(const ParamSet& p) { return 64 * cellCount(p); }
static size_t stateBytes(const ParamSet& p) { return 6 * cellCount(p) * 16; }  // six sections of RGBA32F
static size_t energyBytes(const ParamSet& p) {
  return sizeof(gpu::LpvEnergy) * kCascades * size_t(p.getInt("lpv.steps") + 1);
}
// propagate.comp.glsl runs one invocation per column of cells along x, in work groups of 8 x 4
// columns (y, z), and writes two vec4 of partial energy sums per column (per invocation of the
// dispatch, the padding of the last work groups included).
static const glm::ivec3 kPropagateColumns(8, 4, 1);
static glm::ivec2 propagateInvocations(glm::ivec3 box) {
  return glm::ivec2((box.y + kPropagateColumns.x - 1) / kPropagateColumns.x * kPropagateColumns.x,
                    (box.z + kPropagateColumns.y - 1) / kPropagateColumns.y * kPropagateColumns.y);
}
static size_t energyPartialsBytes(const ParamSet& p) {
  const glm::ivec2 n = propagateInvocations(glm::ivec3(p.getInt("lpv.resolution")));
  return 32 * size_t(n.x) * n.y;
}
static std::string stateBuffer(int p, int cascade) {
  return "propagate.state" + std::to_string(p) + "-" + kCascadeNames[cascade];
}
static void barrier() {
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT |
                  GL_TEXTURE_UPDATE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}
static std::array<gpu::LpvGrid, kCascades> readGrids(Blackboard& board) {
  std::array<gpu::LpvGrid, kCascades> g;
  auto bytes = board.buffer("lpv-grids").download(sizeof(g));
  std::memcpy(g.data(), bytes.data(), sizeof(g));
  return g;
}
static void setGridUniforms(GLuint program, const gpu::LpvGrid& g) {
  setUniform(program, "u_gridOrigin", glm::vec3(g.originCell));
  setUniform(program, "u_cellSize", g.originCell.w);
  setUniform(program, "u_gridRes", int(g.centreRes.w));
}

// --- place ---------------------------------------------------------------------------------------

std::array<gpu::LpvGrid, kCascades> placeGrids(const Scene& scene, const ViewState& view, const ParamSet& params) {
  const int res = params.getInt("lpv.resolution");
  glm::vec3 ext = scene.bounds.max - scene.bounds.min;
  float largest = std::max({ext.x, ext.y, ext.z, 1e-3f});
  float fineEdge = params.getFloat("lpv.fine-extent") * largest;
  float cell[kCascades] = {fineEdge / float(res), fineEdge / float(res) * params.getFloat("lpv.cascade-ratio")};
  glm::vec3 centre[kCascades];
  if (params.getChoice("lpv.centre") == "camera") {
    glm::vec3 forward = -glm::vec3(view.view[0][2], view.view[1][2], view.view[2][2]);
    float halfFine = 0.5f * cell[0] * float(res), halfCoarse = 0.5f * cell[1] * float(res);
    centre[0] = view.position + forward * (0.5f * halfFine);
    centre[1] = view.position + forward * (halfCoarse - 0.5f * halfFine);
  } else {
    centre[0] = centre[1] = 0.5f * (scene.bounds.min + scene.bounds.max);
  }
  std::array<gpu::LpvGrid, kCascades> g;
  for (int c = 0; c < kCascades; ++c) {
    glm::vec3 snapped = glm::floor(centre[c] / cell[c]) * cell[c];
    g[c].originCell = glm::vec4(snapped - float(res / 2) * cell[c], cell[c]);
    g[c].centreRes = glm::vec4(centre[c], float(res));
  }
  return g;
}

void PlaceStage::declare(StageBuilder& b) const {
  b.param(resolutionParam());
  b.param(fineExtentParam());
  b.param(cascadeRatioParam());
  b.param(centreParam());
  b.readView();
  BufferLayout layout;
  layout.stride = sizeof(gpu::LpvGrid);
  layout.fields = {{"origin-cell", FieldType::Vec4, 0, FieldRole::Other}, {"centre", FieldType::Vec4, 16, FieldRole::Position}};
  OutputDesc& o = b.output("grids", OutputKind::Buffer, Semantic::Points,
                           "per cascade (fine, coarse): snapped minimum corner + cell size (m), unsnapped centre + "
                           "cells per axis");
  o.layout = layout;
  o.resource = "lpv-grids";
  b.buffer("lpv-grids", [](const ParamSet&, const ViewState&) { return sizeof(std::array<gpu::LpvGrid, kCascades>); });
}

void PlaceStage::execute(StageContext& ctx) {
  auto grids = placeGrids(ctx.scene, ctx.view, ctx.params);
  ctx.board.ensureBuffer("lpv-grids", sizeof(grids)).upload(grids.data(), sizeof(grids));
  // Every volume of a cascade sits in that cascade's box.
  for (int c = 0; c < kCascades; ++c) {
    float edge = grids[c].originCell.w * grids[c].centreRes.w;
    WorldBox box{glm::vec3(grids[c].originCell), glm::vec3(grids[c].originCell) + glm::vec3(edge)};
    ctx.board.place(voxelColourVolume(c), box);
    if (c == 0) {
      ctx.board.place("reflection", box);
      ctx.board.place("reflection-colour", box);
    }
    for (const char* prefix : {"vpl", "light", "wavefront"})
      for (int ch = 0; ch < 3; ++ch) ctx.board.place(shVolume(prefix, c, ch), box);
    ctx.stats[std::string(kCascadeNames[c]) + "_cell_m"] = grids[c].originCell.w;
  }
}

// --- bin -----------------------------------------------------------------------------------------

static BufferLayout voxelLayout() {
  BufferLayout l;
  l.stride = sizeof(gpu::LpvVoxel);
  l.fields = {{"color-occlusion", FieldType::U32, 0, FieldRole::Other},
              {"fragments", FieldType::U32, 4, FieldRole::Other},
              {"cell", FieldType::Packed10_10_10, 8, FieldRole::Position},
              {"area", FieldType::U32, 12, FieldRole::Other},
              {"normal-0", FieldType::U32, 16, FieldRole::Other},
              {"normal-1", FieldType::U32, 20, FieldRole::Other},
              {"normal-2", FieldType::U32, 24, FieldRole::Other},
              {"normal-3", FieldType::U32, 28, FieldRole::Other}};
  return l;
}

void BinStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(resolutionParam());
  b.read("fragments");
  b.read("fragments.count");
  b.read("lpv-grids");
  for (int c = 0; c < kCascades; ++c) {
    b.output(voxelBuffer(c), OutputKind::Buffer, Semantic::Points,
             std::string("the ") + kCascadeNames[c] +
                 " LPV voxel grid, one record per cell: colour/contrast/occupancy word (Listing 4.27), fragment "
                 "count, cell, surface area (fixed point: the fragments of a voxel share its area), four "
                 "tetrahedron-channel normal masks (Listings 4.28/4.29)")
        .layout = voxelLayout();
    b.output(voxelColourVolume(c), OutputKind::Volume3D, Semantic::Color,
             std::string("decoded ") + kCascadeNames[c] + " cells: stored linear albedo, alpha = occupied");
  }
  b.buffer("bin.outside", [](const ParamSet&, const ViewState&) { return size_t(4 * kCascades); });
  b.write("voxel-fragments");
  b.buffer("voxel-fragments", [](const ParamSet& p, const ViewState&) { return voxelFragmentsBytes(p); });
  for (int c = 0; c < kCascades; ++c) {
    b.buffer(voxelBuffer(c), [](const ParamSet& p, const ViewState&) { return voxelBufferBytes(p); });
    b.texture(voxelColourVolume(c), [](const ParamSet& p, const ViewState&) {
      return voxelColourDesc(p.getInt("lpv.resolution"));
    });
  }
}

void BinStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("lpv.resolution");
  VoxelSpace space = VoxelSpace::fromScene(ctx.scene, ctx.params.getInt("voxel.resolution"));
  auto grids = readGrids(ctx.board);
  uint32_t count = voxelFragmentCount(ctx.board);
  Buffer& outside = ctx.board.ensureBuffer("bin.outside", 4 * kCascades);
  const uint32_t zeros[kCascades] = {0, 0};
  outside.upload(zeros, sizeof(zeros));
  // Fragments per voxel of the fragment list: the fragments of one voxel share its area.
  Buffer& shared = ctx.board.ensureBuffer("voxel-fragments", voxelFragmentsBytes(ctx.params));
  glClearNamedBufferData(shared.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
  {
    GLuint program = ctx.shaders.program({"lpv/bin_count.comp.glsl"});
    space.setUniforms(program);
    setUniform(program, "u_fragmentCount", unsigned(count));
    glUseProgram(program);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, ctx.board.buffer("fragments").id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_VOXEL_FRAGMENTS, shared.id());
    if (count > 0) dispatchCompute({int(count), 1, 1}, {64, 1, 1});
    barrier();
  }
  for (int c = 0; c < kCascades; ++c) {
    Buffer& voxels = ctx.board.ensureBuffer(voxelBuffer(c), voxelBufferBytes(ctx.params));
    GLuint clear = ctx.shaders.program({"lpv/bin_clear.comp.glsl"});
    setUniform(clear, "u_gridRes", res);
    glUseProgram(clear);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_VOXELS, voxels.id());
    dispatchCompute({res, res, res}, {4, 4, 4});
    barrier();

    GLuint program = ctx.shaders.program({"lpv/bin.comp.glsl"});
    space.setUniforms(program);
    setGridUniforms(program, grids[c]);
    setUniform(program, "u_fragmentCount", unsigned(count));
    setUniform(program, "u_cascade", c);
    setUniform(program, "u_areaUnits", areaUnits(grids[c].originCell.w, space.voxelSize));
    glUseProgram(program);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, ctx.board.buffer("fragments").id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_VOXELS, voxels.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_VOXEL_FRAGMENTS, shared.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_SCRATCH, outside.id());
    if (count > 0) dispatchCompute({int(count), 1, 1}, {64, 1, 1});
    barrier();

    Texture& colour = ctx.board.ensureTexture(voxelColourVolume(c), voxelColourDesc(res));
    GLuint decode = ctx.shaders.program({"lpv/bin_decode.comp.glsl"});
    setUniform(decode, "u_gridRes", res);
    glUseProgram(decode);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_VOXELS, voxels.id());
    glBindImageTexture(0, colour.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA8);
    dispatchCompute({res, res, res}, {4, 4, 4});
    barrier();
  }
  // Fragments outside a grid are dropped (the coarse grid should contain the fine one): reported.
  auto out = outside.download(sizeof(zeros));
  uint32_t dropped[kCascades];
  std::memcpy(dropped, out.data(), sizeof(dropped));
  ctx.stats["fragments"] = count;
  for (int c = 0; c < kCascades; ++c) ctx.stats[std::string("fragments_outside_") + kCascadeNames[c]] = dropped[c];
  ctx.stats["bytes_per_grid"] = double(sizeof(gpu::LpvVoxel)) * res * res * res;
  // The surface the cells hold (what injection lights) against fragments x voxel^2 (what it lit
  // before the fragments of a voxel shared its area: 7x more on Sponza at 128^3).
  for (int c = 0; c < kCascades; ++c) {
    auto records = ctx.board.buffer(voxelBuffer(c)).download(voxelBufferBytes(ctx.params));
    double units = 0;
    for (size_t i = 0; i < records.size() / sizeof(gpu::LpvVoxel); ++i) {
      gpu::LpvVoxel v;
      std::memcpy(&v, &records[i * sizeof v], sizeof v);
      units += v.area;
    }
    ctx.stats[std::string("surface_m2_") + kCascadeNames[c]] =
        units / areaUnits(grids[c].originCell.w, space.voxelSize) * space.voxelSize * space.voxelSize;
  }
  ctx.stats["fragments_m2"] = double(count) * space.voxelSize * space.voxelSize;
}

// --- inject --------------------------------------------------------------------------------------

static ParamDesc injectSourceParam() {
  return ParamDesc::choice("inject.source", {"direct-light", "point-vpl"}, 0,
                           "VPLs from the lit voxels, or one VPL of flux pi (per channel) in the picked cell "
                           "(probe.cell-x/y/z) for watching propagation alone");
}
static ParamDesc injectLightingParam() {
  return ParamDesc::choice("inject.lighting", {"per-cell", "per-fragment"}, 1,
                           "per-fragment: every fragment is lit at its own voxel with its own normal and shadow test "
                           "and the cell sums their lobes; per-cell (the thesis): an occupied cell is lit once, "
                           "through its most light-facing normal and one shadow test, and all its surface counts as "
                           "lit (on Sponza's 1.74 m cells that lights shaded surface: indirect 1.85x the reference "
                           "against 0.91x per fragment)");
}
static size_t fragmentSumsBytes(const ParamSet& p) { return 12 * sizeof(int32_t) * cellCount(p); }

static ParamDesc vplDirectionParam() {
  return ParamDesc::choice("inject.vpl-direction", {"+x", "-x", "+y", "-y", "+z", "-z"}, 4,
                           "normal of the point VPL's clamped-cosine lobe");
}

// The facing-plates experiment of the technical note (lesson 05, LpvLookup.FacingPlatesDecideTheSign):
// the point VPL this many cells behind the picked cell, so the probe record shows what receivers
// in front of an emitter read.
static ParamDesc vplDistanceParam() {
  return ParamDesc::integer("inject.vpl-distance", 0, 0, 16,
                            "the point VPL sits this many cells from the picked cell against its normal (0: in it)",
                            "cells");
}

void InjectStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(ParamDesc::real("inject.vpl-shift", 0.0, 0.0, 1.0,
                          "move each VPL this far along its normal before it is stored (K&D: 0.5, against "
                          "self-illumination; the thesis: 0); point VPLs stay put", "cells"));
  b.param(resolutionParam());
  b.param(injectSourceParam());
  b.param(injectLightingParam());
  b.param(vplDirectionParam());
  b.param(vplDistanceParam());
  b.param(probeParam("x"));
  b.param(probeParam("y"));
  b.param(probeParam("z"));
  b.read("lpv-grids");
  b.read("shadow-map");
  b.read("light");
  for (int c = 0; c < kCascades; ++c) b.read(voxelBuffer(c));
  b.write("inject.unshifted");
  for (int c = 0; c < kCascades; ++c)
    for (int ch = 0; ch < 3; ++ch)
      b.output(shVolume("vpl", c, ch), OutputKind::Volume3D, kShL1,
               std::string("sh-l1: injected VPL intensity (W/sr) of the ") + kChannelNames[ch] + " channel, " +
                   kCascadeNames[c] + " cascade, as L1 SH (c00, c1-1, c10, c11); shown as log c00, |b|/c00 or lobes");
  for (int c = 0; c < kCascades; ++c)
    for (int ch = 0; ch < 3; ++ch)
      b.texture(shVolume("vpl", c, ch), [](const ParamSet& p, const ViewState&) { return shDesc(p.getInt("lpv.resolution")); });
  b.buffer("inject.unshifted", [](const ParamSet& p, const ViewState&) { return unshiftedBytes(p); });
  b.read("fragments");
  b.read("fragments.count");
  b.read("voxel-fragments");
  b.write("inject.fragment-sums");
  b.write("inject.fragment-largest");
  b.buffer("inject.fragment-sums", [](const ParamSet& p, const ViewState&) { return fragmentSumsBytes(p); });
  b.buffer("inject.fragment-largest", [](const ParamSet&, const ViewState&) { return size_t(4); });
}

// inject.lighting=per-fragment: the fixed-point sums of the lit fragments' lobes per cell of
// cascade c (shaders/lpv/inject_fragments.comp.glsl). The unit is chosen so that the fullest cell
// cannot overflow: the largest single-fragment coefficient times the most fragments in a cell is
// 2^30 units. Returns the units per W/sr.
static float sumFragmentLobes(StageContext& ctx, int c, const gpu::LpvGrid& grid, const VoxelSpace& space, Buffer& sums,
                              Buffer& largest) {
  const uint32_t count = voxelFragmentCount(ctx.board);
  glClearNamedBufferData(sums.id(), GL_R32I, GL_RED_INTEGER, GL_INT, nullptr);
  const uint32_t zero = 0;
  largest.upload(&zero, 4);
  GLuint program = ctx.shaders.program({"lpv/inject_fragments.comp.glsl"});
  space.setUniforms(program);
  setGridUniforms(program, grid);
  setUniform(program, "u_fragmentCount", unsigned(count));
  setUniform(program, "u_fragmentArea", space.voxelSize * space.voxelSize);
  setUniform(program, "u_areaUnits", areaUnits(grid.originCell.w, space.voxelSize));
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, ctx.board.buffer("fragments").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_VOXEL_FRAGMENTS, ctx.board.buffer("voxel-fragments").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_PROBE, sums.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_SCRATCH, largest.id());
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  glBindTextureUnit(2, ctx.board.texture("shadow-map").id());
  setUniform(program, "u_pass", 0);
  setUniform(program, "u_unitsPerWatt", 1.0f);
  glUseProgram(program);
  if (count > 0) dispatchCompute({int(count), 1, 1}, {64, 1, 1});
  barrier();
  float biggest = 0.0f;
  uint32_t bits = readCounter(largest);
  std::memcpy(&biggest, &bits, 4);
  // The most fragments any cell holds (the bin stage counted them).
  auto records = ctx.board.buffer(voxelBuffer(c)).download(voxelBufferBytes(ctx.params));
  uint32_t most = 1;
  for (size_t i = 0; i < records.size() / sizeof(gpu::LpvVoxel); ++i) {
    gpu::LpvVoxel v;
    std::memcpy(&v, &records[i * sizeof v], sizeof v);
    most = std::max(most, v.fragmentCount);
  }
  const float units = biggest > 0.0f ? float(double(1u << 30) / (double(biggest) * most)) : 1.0f;
  setUniform(program, "u_pass", 1);
  setUniform(program, "u_unitsPerWatt", units);
  glUseProgram(program);
  if (count > 0 && biggest > 0.0f) dispatchCompute({int(count), 1, 1}, {64, 1, 1});
  barrier();
  return units;
}

void InjectStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("lpv.resolution");
  VoxelSpace space = VoxelSpace::fromScene(ctx.scene, ctx.params.getInt("voxel.resolution"));
  auto grids = readGrids(ctx.board);
  const bool point = ctx.params.getChoice("inject.source") == "point-vpl";
  glm::ivec3 probe = probeCell(ctx.params);
  const glm::ivec3 vplNormal = faceOffset(ctx.params.getInt("inject.vpl-direction"));
  glm::vec3 probeWorld = glm::vec3(grids[0].originCell) +
                         (glm::vec3(probe - ctx.params.getInt("inject.vpl-distance") * vplNormal) + 0.5f) *
                             grids[0].originCell.w;
  GLuint program = ctx.shaders.program({"lpv/inject.comp.glsl"});
  for (int c = 0; c < kCascades; ++c) {
    Texture* out[3];
    for (int ch = 0; ch < 3; ++ch) out[ch] = &ctx.board.ensureTexture(shVolume("vpl", c, ch), shDesc(res));
    glm::ivec3 vplCell = glm::ivec3(glm::floor((probeWorld - glm::vec3(grids[c].originCell)) / grids[c].originCell.w));
    setGridUniforms(program, grids[c]);
    setUniform(program, "u_fragmentArea", space.voxelSize * space.voxelSize);
    setUniform(program, "u_areaUnits", areaUnits(grids[c].originCell.w, space.voxelSize));
    setUniform(program, "u_pointVpl", point ? 1 : 0);
    setUniform(program, "u_vplCell", vplCell);
    setUniform(program, "u_vplNormal", glm::vec3(vplNormal));
    setUniform(program, "u_shift", ctx.params.getFloat("inject.vpl-shift"));
    Buffer& unshifted = ctx.board.ensureBuffer("inject.unshifted", unshiftedBytes(ctx.params));
    Buffer& sums = ctx.board.ensureBuffer("inject.fragment-sums", fragmentSumsBytes(ctx.params));
    Buffer& largest = ctx.board.ensureBuffer("inject.fragment-largest", 4);
    const bool perFragment = !point && ctx.params.getChoice("inject.lighting") == "per-fragment";
    float units = 1.0f;
    if (perFragment) {
      units = sumFragmentLobes(ctx, c, grids[c], space, sums, largest);
      ctx.stats[std::string("fixed_point_units_per_w_") + kCascadeNames[c]] = units;
    }
    setUniform(program, "u_perFragment", perFragment ? 1 : 0);
    setUniform(program, "u_unitsPerWatt", units);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_PROBE, sums.id());
    glUseProgram(program);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_VOXELS, ctx.board.buffer(voxelBuffer(c)).id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_STATE_OUT, unshifted.id());
    glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
    glBindTextureUnit(2, ctx.board.texture("shadow-map").id());
    for (int ch = 0; ch < 3; ++ch) glBindImageTexture(ch, out[ch]->id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    const int passes = ctx.params.getFloat("inject.vpl-shift") > 0.0f ? 2 : 1;
    for (int pass = 0; pass < passes; ++pass) {
      setUniform(program, "u_pass", pass);
      dispatchCompute({res, res, res}, {4, 4, 4});
      barrier();
    }
  }
  ctx.stats["point_vpl"] = point ? 1 : 0;
  ctx.stats["vpl_shift_cells"] = ctx.params.getFloat("inject.vpl-shift");
}

// --- propagate -----------------------------------------------------------------------------------

static ParamDesc schemeParam() {
  return ParamDesc::choice("lpv.scheme", {"wavefront", "thesis"}, 0,
                           "wavefront (Kaplanyan-Dachsbacher): each step propagates only the last step's light and the "
                           "lookup sums all steps; thesis: each step propagates everything so far (energy grows "
                           "geometrically, near light counted many times)");
}

void PropagateStage::declare(StageBuilder& b) const {
  b.param(resolutionParam());
  b.param(stepsParam());
  b.param(schemeParam());
  b.param(ParamDesc::choice("lpv.weighting", {"flux-consistent", "thesis"}, 0,
                            "face weight: solid angle / pi (a face of flux F re-emits F / pi times a cosine lobe), or "
                            "solid angle / 4 pi times lpv.flux-amplifier as the thesis"));
  b.param(ParamDesc::real("lpv.flux-amplifier", 1.75, 0.0, 8.0,
                          "thesis weighting only: the factor GPU Pro 4 multiplies solid angle / 4 pi by (1.75)"));
  b.param(ParamDesc::boolean("lpv.clamp-faces", true,
                             "clamp each face's evaluated intensity at 0 (off: the linear operator, which conserves "
                             "flux exactly; on: negative back lobes are dropped, about +14 % on a first step)"));
  b.param(ParamDesc::choice("lpv.occlusion", {"two-sided", "thesis", "none"}, 0,
                            "blocking by the source cell's voxel: a surface blocks both ways, as the thesis (only light "
                            "travelling along its stored normal), or not at all"));
  b.param(ParamDesc::real("lpv.occlusion-amplifier", 1.0, 0.0, 4.0,
                          "blocked fraction = amplifier * (0.25 + 0.5 n.d), clamped to 1: 1 lets 25 % through head "
                          "on, 4/3 blocks all"));
  b.param(ParamDesc::boolean("lpv.first-step-unoccluded", true,
                             "the first step ignores occlusion, so a VPL's own voxel does not block its light"));
  b.param(probeParam("x"));
  b.param(probeParam("y"));
  b.param(probeParam("z"));
  b.param(probeCascadeParam());
  // A click on a cell of any volume shown in the viewer picks it (the cascade stays probe.cascade).
  b.probe(ProbeDesc::volume("probe.cell-x", "probe.cell-y", "probe.cell-z"));
  for (int c = 0; c < kCascades; ++c) {
    b.read(voxelBuffer(c));
    for (int ch = 0; ch < 3; ++ch) b.read(shVolume("vpl", c, ch));
  }
  b.write("energy.count");
  for (int c = 0; c < kCascades; ++c)
    for (int ch = 0; ch < 3; ++ch)
      b.output(shVolume("light", c, ch), OutputKind::Volume3D, kShL1,
               std::string("sh-l1: intensity (W/sr) the lookup reads, ") + kChannelNames[ch] + " channel, " +
                   kCascadeNames[c] + " cascade, after the steps so far; shown as log c00, |b|/c00 or lobes");
  for (int c = 0; c < kCascades; ++c)
    for (int ch = 0; ch < 3; ++ch)
      b.output(shVolume("wavefront", c, ch), OutputKind::Volume3D, kShL1,
               std::string("sh-l1: light that moved in the last step, ") + kChannelNames[ch] + ", " + kCascadeNames[c] +
                   " (the L1 diamond); shown as log c00, |b|/c00 or lobes");
  BufferLayout energy;
  energy.stride = sizeof(gpu::LpvEnergy);
  energy.fields = {{"wavefront", FieldType::Vec4, 0, FieldRole::Other}, {"total", FieldType::Vec4, 16, FieldRole::Other}};
  energy.countResource = "energy.count";
  b.output("energy", OutputKind::Buffer, kLpvEnergy,
           "per step (0 = injected) and cascade: flux of the wavefront (rgb, step) and of the grid (rgb, cascade), W")
      .layout = energy;
  BufferLayout probe;
  probe.stride = sizeof(gpu::LpvProbe);
  probe.fields = {{"cell", FieldType::I32, 0}, {"cell-y", FieldType::I32, 4}, {"cell-z", FieldType::I32, 8},
                  {"cascade", FieldType::I32, 12}};
  const char* rgb[3] = {"r", "g", "b"};
  for (int ch = 0; ch < 3; ++ch) probe.fields.push_back({std::string("light-") + rgb[ch], FieldType::Vec4, uint32_t(16 + 16 * ch)});
  for (int ch = 0; ch < 3; ++ch) probe.fields.push_back({std::string("wavefront-") + rgb[ch], FieldType::Vec4, uint32_t(64 + 16 * ch)});
  probe.fields.push_back({"color-occlusion", FieldType::U32, 112});
  probe.fields.push_back({"fragments", FieldType::U32, 116});
  probe.fields.push_back({"step", FieldType::U32, 120});
  for (int k = 0; k < 4; ++k) probe.fields.push_back({"normal-" + std::to_string(k), FieldType::U32, uint32_t(128 + 4 * k)});
  const char* dirs[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  for (int i = 0; i < 6; ++i) probe.fields.push_back({std::string("from") + dirs[i], FieldType::Vec4, uint32_t(144 + 16 * i)});
  for (int part = 0; part < 2; ++part)
    for (int f = 0; f < 30; ++f) {
      const int i = f / 5, k = f % 5, j = k < i ? k : k + 1;
      probe.fields.push_back({std::string(part == 0 ? "intensity" : "flux") + dirs[i] + "-face" + dirs[j],
                              FieldType::Vec4, uint32_t(240 + 480 * part + 16 * f)});
    }
  probe.fields.push_back({"weight", FieldType::F32, 1200});
  OutputDesc& cellRecord = b.output("probe-cell", OutputKind::Buffer, kLpvProbe,
           "the picked cell (probe.cell-x/y/z, probe.cascade) after the current step: SH per channel, its voxel's "
           "words, c00 gained from each neighbour (a: mean face transmission), and per neighbour its five face "
           "evaluations (intensity towards the face, solid angle, transmission, flux) that sum to it");
  cellRecord.layout = probe;
  cellRecord.probeRecord = true;  // checked and drawn by src/inspect/visualisers/lpv_probe.cpp
  BufferLayout occ;
  occ.stride = sizeof(gpu::LpvOcclusion);
  occ.fields = {{"cell", FieldType::Packed10_10_10, 0, FieldRole::Position},
                {"occupied", FieldType::U32, 4, FieldRole::Other},
                {"plus", FieldType::Vec4, 16, FieldRole::Other},
                {"minus", FieldType::Vec4, 32, FieldRole::Other}};
  for (int c = 0; c < kCascades; ++c) {
    b.output(occlusionBuffer(c), OutputKind::Buffer, kLpvOcclusion,
             std::string("per cell of the ") + kCascadeNames[c] +
                 " cascade: transmission of light leaving it head on along +x,+y,+z (plus.xyz) and -x,-y,-z "
                 "(minus.xyz), least (plus.w) and mean (minus.w) of the six, by lpv.occlusion and "
                 "lpv.occlusion-amplifier from step 1 on")
        .layout = occ;
    b.buffer(occlusionBuffer(c), [](const ParamSet& p, const ViewState&) { return occlusionBytes(p); });
  }
  for (int c = 0; c < kCascades; ++c)
    for (const char* prefix : {"light", "wavefront"})
      for (int ch = 0; ch < 3; ++ch)
        b.texture(shVolume(prefix, c, ch), [](const ParamSet& p, const ViewState&) { return shDesc(p.getInt("lpv.resolution")); });
  for (int c = 0; c < kCascades; ++c)
    for (int s = 0; s < 2; ++s) b.buffer(stateBuffer(s, c), [](const ParamSet& p, const ViewState&) { return stateBytes(p); });
  b.buffer("energy", [](const ParamSet& p, const ViewState&) { return energyBytes(p); });
  b.buffer("energy.count", [](const ParamSet&, const ViewState&) { return size_t(4); });
  b.buffer("probe-cell", [](const ParamSet&, const ViewState&) { return sizeof(gpu::LpvProbe); });
  b.buffer("propagate.energy-partials", [](const ParamSet& p, const ViewState&) { return energyPartialsBytes(p); });
  b.buffer("propagate.active-boxes", [](const ParamSet&, const ViewState&) { return 2 * kCascades * sizeof(glm::ivec4); });
}

int PropagateStage::iterations(const ParamSet& params) const { return params.getInt("lpv.steps"); }

// The occlusion view (outputs occlusion-fine/coarse): per cell and direction of travel the
// transmission the propagation applies to light leaving the cell head on, from the CPU reference's
// faceTransmission (the same maths as propagate.comp.glsl, tested against it), at step 1.
static void writeOcclusionView(StageContext& ctx, int occlusion) {
  PropagationSettings s;
  s.occlusion = occlusion == 0 ? Occlusion::TwoSided : occlusion == 1 ? Occlusion::Thesis : Occlusion::None;
  s.occlusionAmplifier = ctx.params.getFloat("lpv.occlusion-amplifier");
  double least = 1.0, occupied = 0, blocking = 0;
  for (int c = 0; c < kCascades; ++c) {
    auto bytes = ctx.board.buffer(voxelBuffer(c)).download(voxelBufferBytes(ctx.params));
    const size_t cells = bytes.size() / sizeof(gpu::LpvVoxel);
    std::vector<gpu::LpvOcclusion> view(cells);
    for (size_t i = 0; i < cells; ++i) {
      gpu::LpvVoxel v;
      std::memcpy(&v, &bytes[i * sizeof v], sizeof v);
      gpu::LpvOcclusion& o = view[i];
      o = gpu::LpvOcclusion{};
      o.cell = v.cell;
      o.occupied = decodeOccupied(v.colorOcclusion) ? 1u : 0u;
      float t[6], lo = 1.0f, mean = 0.0f;
      for (int f = 0; f < 6; ++f) {
        glm::vec3 travel = faceOffset(f);
        t[f] = faceTransmission(&v, travel, travel, s, 1);
        lo = std::min(lo, t[f]);
        mean += t[f] / 6.0f;
      }
      o.plus = glm::vec4(t[0], t[2], t[4], lo);
      o.minus = glm::vec4(t[1], t[3], t[5], mean);
      if (c == 0 && o.occupied) {
        ++occupied;
        blocking += lo < 1.0f;
        least = std::min(least, double(lo));
      }
    }
    ctx.board.ensureBuffer(occlusionBuffer(c), occlusionBytes(ctx.params)).upload(view.data(), view.size() * sizeof(view[0]));
  }
  ctx.stats["occupied_cells_fine"] = occupied;
  ctx.stats["blocking_cells_fine"] = blocking;
  ctx.stats["least_transmission_fine"] = least;
}

// Energy record (step, cascade) from sums of c00 per channel: flux = c00 * 2 sqrt(pi).
static void writeEnergy(Buffer& energy, int cascade, int step, glm::dvec3 lightC00, glm::dvec3 waveC00) {
  gpu::LpvEnergy record;
  record.wavefront = glm::vec4(glm::vec3(waveC00 * double(kFluxPerC00)), float(step));
  record.total = glm::vec4(glm::vec3(lightC00 * double(kFluxPerC00)), float(cascade));
  glNamedBufferSubData(energy.id(), GLintptr(sizeof record) * (step * kCascades + cascade), sizeof record, &record);
}

void PropagateStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("lpv.resolution");
  const int k = ctx.iteration;
  const bool thesisScheme = ctx.params.getChoice("lpv.scheme") == "thesis";
  const double pi = kPi;
  const float weightScale = ctx.params.getChoice("lpv.weighting") == "thesis"
                                ? float(ctx.params.getFloat("lpv.flux-amplifier") / (4.0 * pi))
                                : float(1.0 / pi);
  const int occlusion = ctx.params.getInt("lpv.occlusion");  // 0 two-sided, 1 thesis, 2 none
  Buffer& energy = ctx.board.ensureBuffer("energy", energyBytes(ctx.params));
  Buffer& energyCount = ctx.board.ensureBuffer("energy.count", 4);
  Buffer& probe = ctx.board.ensureBuffer("probe-cell", sizeof(gpu::LpvProbe));
  const int probeCascade = ctx.params.getInt("probe.cascade");

  GLuint prop = ctx.shaders.program({"lpv/propagate.comp.glsl"});
  // The picked cell's record comes from the same shader built with the recording (one invocation).
  GLuint recorder = ctx.shaders.program({"lpv/propagate.comp.glsl"}, "#define LPV_PROBE 1\n");
  if (k == 0) writeOcclusionView(ctx, occlusion);
  // Per cascade the lowest and highest cell holding injected light (none: lo > hi), found at step 0.
  std::array<glm::ivec4, 2 * kCascades> activeBoxes;
  if (k > 0) {
    auto bytes = ctx.board.buffer("propagate.active-boxes").download(sizeof(activeBoxes));
    std::memcpy(activeBoxes.data(), bytes.data(), sizeof(activeBoxes));
  }
  double updated = 0;
  for (int c = 0; c < kCascades; ++c) {
    // Step k reads the state step k-1 wrote (step 0: the injected VPLs, packed into state 0) and
    // writes the other state, then copies it into the output volumes (buffer -> texture copies).
    const size_t cells = size_t(res) * res * res, section = cells * 16;
    Buffer* state[2];
    for (int p = 0; p < 2; ++p)
      state[p] = &ctx.board.ensureBuffer(stateBuffer(p, c), stateBytes(ctx.params));
    Buffer& in = *state[k % 2];
    Buffer& out = *state[(k + 1) % 2];
    Texture *light[3], *wave[3];
    for (int ch = 0; ch < 3; ++ch) {
      light[ch] = &ctx.board.ensureTexture(shVolume("light", c, ch), shDesc(res));
      wave[ch] = &ctx.board.ensureTexture(shVolume("wavefront", c, ch), shDesc(res));
    }
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    if (k == 0) {
      glBindBuffer(GL_PIXEL_PACK_BUFFER, in.id());
      for (int ch = 0; ch < 3; ++ch)
        for (int part = 0; part < 2; ++part)
          glGetTextureImage(ctx.board.texture(shVolume("vpl", c, ch)).id(), 0, GL_RGBA, GL_FLOAT, GLsizei(section),
                            reinterpret_cast<void*>((part * 3 + ch) * section));
      glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
      barrier();
      // The box of cells holding injected light (cells outside it in the other state are never
      // written), and record 0 of the cascade: the injected flux (wavefront = grid), summed in cell
      // order.
      glClearNamedBufferData(out.id(), GL_R32F, GL_RED, GL_FLOAT, nullptr);
      auto injected = in.download(3 * section);
      glm::ivec4 lo(res, res, res, 0), hi(-1, -1, -1, 0);
      glm::dvec3 injectedSum(0.0);
      for (int ch = 0; ch < 3; ++ch) {
        const float* v = reinterpret_cast<const float*>(injected.data() + ch * section);
        for (size_t i = 0; i < cells; ++i) {
          injectedSum[ch] += v[4 * i];
          if (v[4 * i] == 0.0f && v[4 * i + 1] == 0.0f && v[4 * i + 2] == 0.0f && v[4 * i + 3] == 0.0f) continue;
          const glm::ivec3 cell(int(i % res), int(i / res % res), int(i / (size_t(res) * res)));
          lo = glm::ivec4(glm::min(glm::ivec3(lo), cell), 0);
          hi = glm::ivec4(glm::max(glm::ivec3(hi), cell), 0);
        }
      }
      activeBoxes[2 * c] = lo;
      activeBoxes[2 * c + 1] = hi;
      writeEnergy(energy, c, 0, injectedSum, injectedSum);
      ctx.board.ensureBuffer("propagate.active-boxes", sizeof(activeBoxes)).upload(activeBoxes.data(), sizeof(activeBoxes));
    }
    // Light moves at most one cell per step (locality), so after step k only cells within k + 1
    // cells of an injected one can hold any: the step runs over that box alone. Every cell outside
    // it would gather exactly 0 from dark neighbours and keep its 0, which both states hold there.
    const glm::ivec3 boxLo = glm::max(glm::ivec3(activeBoxes[2 * c]) - (k + 1), glm::ivec3(0));
    const glm::ivec3 boxHi = glm::min(glm::ivec3(activeBoxes[2 * c + 1]) + (k + 1), glm::ivec3(res - 1));
    const glm::ivec3 boxSize = glm::max(boxHi - boxLo + 1, glm::ivec3(0));
    for (int j = 0; j <= k; ++j) {  // the cells steps 0..k updated (statistic)
      const glm::ivec3 lo = glm::max(glm::ivec3(activeBoxes[2 * c]) - (j + 1), glm::ivec3(0));
      const glm::ivec3 hi = glm::min(glm::ivec3(activeBoxes[2 * c + 1]) + (j + 1), glm::ivec3(res - 1));
      const glm::ivec3 n = glm::max(hi - lo + 1, glm::ivec3(0));
      updated += double(n.x) * n.y * n.z;
    }
    auto bindCommon = [&](GLuint program) {
      setUniform(program, "u_gridRes", res);
      setUniform(program, "u_step", k);
      setUniform(program, "u_thesisScheme", thesisScheme ? 1 : 0);
      setUniform(program, "u_weightScale", weightScale);
      setUniform(program, "u_clampFaces", ctx.params.getBool("lpv.clamp-faces") ? 1 : 0);
      setUniform(program, "u_occlusion", occlusion);
      setUniform(program, "u_occlusionAmplifier", ctx.params.getFloat("lpv.occlusion-amplifier"));
      setUniform(program, "u_firstStepUnoccluded", ctx.params.getBool("lpv.first-step-unoccluded") ? 1 : 0);
      glUseProgram(program);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_STATE_IN, in.id());
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_STATE_OUT, out.id());
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_VOXELS, ctx.board.buffer(voxelBuffer(c)).id());
    };
    bindCommon(prop);
    setUniform(prop, "u_boxLo", boxLo);
    setUniform(prop, "u_boxHi", boxHi);
    glUseProgram(prop);
    Buffer& partials = ctx.board.ensureBuffer("propagate.energy-partials", energyPartialsBytes(ctx.params));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_ENERGY_PARTIALS, partials.id());
    const glm::ivec2 invocations = propagateInvocations(boxSize);
    const size_t columns = boxSize.x > 0 ? size_t(invocations.x) * invocations.y : 0;
    if (columns > 0) dispatchCompute({boxSize.y, boxSize.z, 1}, kPropagateColumns);
    barrier();
    // The step's energy record: the columns' partial sums added in column order (deterministic
    // whatever the thread count; cells outside the box hold 0 and add nothing).
    {
      glm::dvec3 lightSum(0.0), waveSum(0.0);
      if (columns > 0) {
        auto bytes = partials.download(32 * columns);
        const float* v = reinterpret_cast<const float*>(bytes.data());
        for (size_t i = 0; i < columns; ++i) {
          lightSum += glm::dvec3(v[8 * i], v[8 * i + 1], v[8 * i + 2]);
          waveSum += glm::dvec3(v[8 * i + 4], v[8 * i + 5], v[8 * i + 6]);
        }
      }
      writeEnergy(energy, c, k + 1, lightSum, waveSum);
    }
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, out.id());
    for (int ch = 0; ch < 3; ++ch) {
      glTextureSubImage3D(light[ch]->id(), 0, 0, 0, 0, res, res, res, GL_RGBA, GL_FLOAT, reinterpret_cast<void*>(ch * section));
      glTextureSubImage3D(wave[ch]->id(), 0, 0, 0, 0, res, res, res, GL_RGBA, GL_FLOAT, reinterpret_cast<void*>((3 + ch) * section));
    }
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    barrier();
    if (c == probeCascade) {
      setUniform(recorder, "u_probeCell", probeCell(ctx.params));
      setUniform(recorder, "u_cascade", c);
      bindCommon(recorder);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_PROBE, probe.id());
      dispatchCompute({1, 1, 1}, kPropagateColumns);  // one work group; its first invocation records
      barrier();
    }
  }
  uint32_t records = uint32_t((k + 2) * kCascades);
  energyCount.upload(&records, 4);
  ctx.stats["steps_done"] = k + 1;
  // Of all cells of both cascades over the steps so far, the fraction the steps ran over.
  ctx.stats["cells_updated_fraction"] = updated / (double(kCascades) * (k + 1) * res * res * res);
  // Per cascade: VPL, light and wavefront volumes (3 channels each) and two states of 6 sections.
  ctx.stats["bytes_sh_per_cascade"] = double(res) * res * res * 16.0 * (9 + 12);
}

// --- reflection ----------------------------------------------------------------------------------

// Incident radiance from intensity (lpv.cpp, Details; docs/fidelity.md has the measured calibration).
static ParamDesc radianceScaleParam() {
  return ParamDesc::real("gi.radiance-scale", 1.0, 0.0, 64.0,
                         "incident radiance = scale * intensity / cell^2 (1: a cell face radiating its intensity)");
}

static ParamDesc reflectionResolutionParam() {
  return ParamDesc::integer("reflection.resolution", 64, 16, 256,
                            "voxels along each axis of the reflection grid over the fine cascade's box (the thesis "
                            "uses 256: 146 MiB with mips in RGBA16F)", "voxels")
      .pow2();
}

static int reflectionLevels(const ParamSet& params) {
  int res = params.getInt("reflection.resolution"), levels = 1;
  while (res > 1) res >>= 1, ++levels;
  return levels;
}
static TextureDesc reflectionColourDesc(const ParamSet& params) {
  const int res = params.getInt("reflection.resolution");
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = GL_R32UI;
  d.size = {res, res, res};
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}
static TextureDesc reflectionDesc(const ParamSet& params) {
  TextureDesc d = reflectionColourDesc(params);
  d.format = GL_RGBA16F;
  d.levels = reflectionLevels(params);
  d.minFilter = GL_LINEAR_MIPMAP_LINEAR;
  d.magFilter = GL_LINEAR;
  return d;
}

void ReflectionStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(resolutionParam());
  b.param(reflectionResolutionParam());
  b.param(radianceScaleParam());
  b.read("fragments");
  b.read("fragments.count");
  b.read("lpv-grids");
  for (int ch = 0; ch < 3; ++ch) b.read(shVolume("light", 0, ch));
  b.output("reflection-colour", OutputKind::Volume3D, Semantic::Occupancy,
           "the reflection grid's colour/contrast/occupancy words (Listing 4.27), white = occupied");
  b.output("reflection", OutputKind::Volume3D, Semantic::RadianceHDR,
           "outgoing radiance per reflection voxel (L0 of the fine cascade's light), alpha = occupancy; level k = mean "
           "of 8 texels of level k-1");
  b.texture("reflection-colour", [](const ParamSet& p, const ViewState&) { return reflectionColourDesc(p); });
  b.texture("reflection", [](const ParamSet& p, const ViewState&) { return reflectionDesc(p); });
}

int ReflectionStage::iterations(const ParamSet& params) const { return reflectionLevels(params); }

void ReflectionStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("reflection.resolution");
  const int k = ctx.iteration;
  auto grids = readGrids(ctx.board);
  Texture& colour = ctx.board.ensureTexture("reflection-colour", reflectionColourDesc(ctx.params));
  Texture& grid = ctx.board.ensureTexture("reflection", reflectionDesc(ctx.params));
  if (k == 0) {
    const uint32_t zero = 0;
    glClearTexImage(colour.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    const float none[4] = {0, 0, 0, 0};
    for (int level = 0; level < grid.levels(); ++level) glClearTexImage(grid.id(), level, GL_RGBA, GL_FLOAT, none);
    // Same footprint as the fine cascade, res voxels along each axis.
    gpu::LpvGrid g = grids[0];
    const float fineEdge = g.originCell.w * g.centreRes.w;
    gpu::LpvGrid r = g;
    r.originCell.w = fineEdge / float(res);
    r.centreRes.w = float(res);
    VoxelSpace space = VoxelSpace::fromScene(ctx.scene, ctx.params.getInt("voxel.resolution"));
    uint32_t count = voxelFragmentCount(ctx.board);
    GLuint bin = ctx.shaders.program({"lpv/reflection_bin.comp.glsl"});
    space.setUniforms(bin);
    setGridUniforms(bin, r);
    setUniform(bin, "u_fragmentCount", unsigned(count));
    glUseProgram(bin);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, ctx.board.buffer("fragments").id());
    glBindImageTexture(0, colour.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
    if (count > 0) dispatchCompute({int(count), 1, 1}, {64, 1, 1});
    barrier();
    GLuint light = ctx.shaders.program({"lpv/reflection_light.comp.glsl"});
    setGridUniforms(light, r);
    setUniform(light, "u_fineOrigin", glm::vec3(g.originCell));
    setUniform(light, "u_fineCell", g.originCell.w);
    setUniform(light, "u_fineRes", g.centreRes.w);
    setUniform(light, "u_radianceScale", ctx.params.getFloat("gi.radiance-scale"));
    glUseProgram(light);
    for (int ch = 0; ch < 3; ++ch) glBindTextureUnit(ch, ctx.board.texture(shVolume("light", 0, ch)).id());
    glBindImageTexture(0, colour.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32UI);
    glBindImageTexture(1, grid.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA16F);
    dispatchCompute({res, res, res}, {4, 4, 4});
    barrier();
  } else {
    GLuint mip = ctx.shaders.program({"lpv/reflection_mip.comp.glsl"});
    setUniform(mip, "u_sourceLevel", k - 1);
    glUseProgram(mip);
    glBindTextureUnit(0, grid.id());
    glBindImageTexture(0, grid.id(), k, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA16F);
    dispatchCompute(grid.levelSize(k), {4, 4, 4});
    barrier();
  }
  ctx.stats["levels_built"] = k + 1;
  ctx.stats["bytes"] = double(grid.byteSize() + colour.byteSize());
}

// --- gi ------------------------------------------------------------------------------------------

static const std::pair<const char*, GLenum> kGiImages[] = {{"irradiance-fine", GL_RGBA32F},
                                                           {"irradiance-coarse", GL_RGBA32F},
                                                           {"cascade-blend", GL_R32F},
                                                           {"indirect-diffuse", GL_RGBA32F},
                                                           {"glossy", GL_RGBA16F}};

void GiStage::declare(StageBuilder& b) const {
  b.param(resolutionParam());
  b.param(ParamDesc::choice("gi.lookup-sign", {"minus-n", "plus-n"}, 0,
                            "convolve with the cosine around -n (light arriving at the surface, consistent with "
                            "injection) or +n as the thesis listings (a surface sees light leaving it)"));
  b.param(lookupOffsetParam());
  b.param(radianceScaleParam());
  b.param(reflectionResolutionParam());
  b.param(ParamDesc::boolean("gi.glossy", false,
                             "trace the glossy cone through the reflection grid (off: the glossy output stays black; "
                             "the scenes are Lambertian and composite.glossy is 0, and the cone costs more than the "
                             "rest of the lookup on llvmpipe)"));
  b.param(ParamDesc::real("gi.glossy-aperture", 10.0, 1.0, 60.0,
                          "full opening angle of the glossy cone through the reflection grid", "degrees"));
  b.param(ParamDesc::real("gi.glossy-distance", 0.5, 0.05, 1.0,
                          "longest glossy cone, as a fraction of the fine grid's edge"));
  b.param(ParamDesc::real("gi.blend-width", 4.0, 0.5, 8.0,
                          "width of the shell at the fine grid's edge where fine fades into coarse", "fine cells"));
  b.readView();
  b.read("lpv-grids");
  b.read("position");
  b.read("normal");
  b.read("albedo");
  for (int c = 0; c < kCascades; ++c)
    for (int ch = 0; ch < 3; ++ch) b.read(shVolume("light", c, ch));
  b.read("reflection");
  b.output("irradiance-fine", OutputKind::Image2D, Semantic::RadianceHDR, "indirect irradiance from the fine cascade (W/m^2)");
  b.output("irradiance-coarse", OutputKind::Image2D, Semantic::RadianceHDR, "indirect irradiance from the coarse cascade (W/m^2)");
  b.output("cascade-blend", OutputKind::Image2D, Semantic::Fraction, "weight of the coarse cascade (0 fine only, 1 coarse only)");
  b.output("indirect-diffuse", OutputKind::Image2D, Semantic::RadianceHDR,
           "outgoing indirect diffuse radiance: albedo / pi * blended irradiance")
      .referenceMode = "indirect-1";
  b.output("glossy", OutputKind::Image2D, Semantic::RadianceHDR,
           "radiance gathered by one cone along the mirrored view direction through the reflection grid's mips");
  BufferLayout boxes;
  boxes.stride = sizeof(gpu::LpvBox);
  boxes.fields = {{"lo-kind", FieldType::Vec4, 0, FieldRole::Other}, {"hi-cell", FieldType::Vec4, 16, FieldRole::Other}};
  b.output("cascade-boxes", OutputKind::Buffer, kLpvCascades,
           "world boxes: fine cascade, coarse cascade, and the blend shell between coarse weight 0 (inner box) and 1 "
           "(outer box, half a fine cell inside the fine grid's edge)")
      .layout = boxes;
  for (const auto& [name, format] : kGiImages)
    b.texture(name, [format = format](const ParamSet&, const ViewState& v) { return screenDesc(v, format); });
  b.buffer("cascade-boxes", [](const ParamSet&, const ViewState&) { return 4 * sizeof(gpu::LpvBox); });
}

// The boxes gi.comp.glsl blends by: the coarse weight rises from 0 to 1 between max-norm distances
// 0.5 res - 0.5 - width and 0.5 res - 0.5 fine cells from the fine grid's centre.
static std::array<gpu::LpvBox, 4> cascadeBoxes(const std::array<gpu::LpvGrid, kCascades>& grids, float blendWidth) {
  std::array<gpu::LpvBox, 4> boxes;
  for (int c = 0; c < kCascades; ++c) {
    glm::vec3 lo(grids[c].originCell);
    float cell = grids[c].originCell.w, edge = cell * grids[c].centreRes.w;
    boxes[c] = {glm::vec4(lo, float(c)), glm::vec4(lo + edge, cell)};
  }
  const float s = grids[0].originCell.w, res = grids[0].centreRes.w;
  const glm::vec3 centre = glm::vec3(grids[0].originCell) + 0.5f * res * s;
  const float half[2] = {(0.5f * res - 0.5f - blendWidth) * s, (0.5f * res - 0.5f) * s};
  for (int k = 0; k < 2; ++k) boxes[2 + k] = {glm::vec4(centre - half[k], float(2 + k)), glm::vec4(centre + half[k], s)};
  return boxes;
}

void GiStage::execute(StageContext& ctx) {
  auto grids = readGrids(ctx.board);
  Texture* images[5];
  for (int i = 0; i < 5; ++i) images[i] = &ctx.board.ensureTexture(kGiImages[i].first, screenDesc(ctx.view, kGiImages[i].second));
  Texture &fine = *images[0], &coarse = *images[1], &blend = *images[2], &indirect = *images[3], &glossy = *images[4];
  GLuint program = ctx.shaders.program({"lpv/gi.comp.glsl"});
  const float fineEdge = grids[0].originCell.w * grids[0].centreRes.w;
  const int reflRes = ctx.params.getInt("reflection.resolution");
  setUniform(program, "u_reflectionVoxel", fineEdge / float(reflRes));
  setUniform(program, "u_reflectionLevels", float(ctx.board.texture("reflection").levels()));
  setUniform(program, "u_glossyTan", std::tan(0.5f * ctx.params.getFloat("gi.glossy-aperture") * float(kPi) / 180.0f));
  setUniform(program, "u_glossyDistance", ctx.params.getFloat("gi.glossy-distance") * fineEdge);
  setUniform(program, "u_cameraPos", ctx.view.position);
  setUniform(program, "u_glossyOn", ctx.params.getBool("gi.glossy") ? 1 : 0);
  setUniform(program, "u_lookupSign", ctx.params.getChoice("gi.lookup-sign") == "minus-n" ? -1.0f : 1.0f);
  setUniform(program, "u_lookupOffset", ctx.params.getFloat("gi.lookup-offset"));
  setUniform(program, "u_radianceScale", ctx.params.getFloat("gi.radiance-scale"));
  setUniform(program, "u_blendWidth", ctx.params.getFloat("gi.blend-width"));
  glUseProgram(program);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_GRIDS, ctx.board.buffer("lpv-grids").id());
  glBindTextureUnit(0, ctx.board.texture("position").id());
  glBindTextureUnit(1, ctx.board.texture("normal").id());
  glBindTextureUnit(2, ctx.board.texture("albedo").id());
  for (int c = 0; c < kCascades; ++c)
    for (int ch = 0; ch < 3; ++ch) glBindTextureUnit(3 + c * 3 + ch, ctx.board.texture(shVolume("light", c, ch)).id());
  glBindImageTexture(0, fine.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glBindImageTexture(1, coarse.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glBindImageTexture(2, blend.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
  glBindImageTexture(3, indirect.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glBindImageTexture(4, glossy.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindTextureUnit(9, ctx.board.texture("reflection").id());
  dispatchCompute({ctx.view.width, ctx.view.height, 1}, {8, 8, 1});
  barrier();
  auto boxes = cascadeBoxes(grids, ctx.params.getFloat("gi.blend-width"));
  ctx.board.ensureBuffer("cascade-boxes", sizeof(boxes)).upload(boxes.data(), sizeof(boxes));
}

// --- composite -----------------------------------------------------------------------------------

static const std::pair<const char*, GLenum> kCompositeImages[] = {
    {"direct", GL_RGBA16F}, {"combined", GL_RGBA16F}, {"final", GL_RGBA8}};

void CompositeStage::declare(StageBuilder& b) const {
  b.param(ParamDesc::real("composite.exposure", 1.0, 0.01, 64.0, "scale applied before tonemapping"));
  b.param(ParamDesc::real("composite.indirect", 1.0, 0.0, 4.0, "weight of the indirect diffuse term (1 = physical)"));
  b.param(ParamDesc::real("composite.glossy", 0.0, 0.0, 1.0,
                          "weight of the glossy term (0: the scenes are Lambertian, as the reference path tracer)"));
  b.read("position");
  b.read("normal");
  b.read("albedo");
  b.read("emission");
  b.read("indirect-diffuse");
  b.read("glossy");
  b.read("shadow-map");
  b.read("light");
  b.output("direct", OutputKind::Image2D, Semantic::RadianceHDR, "direct light plus emission").referenceMode = "direct";
  b.output("combined", OutputKind::Image2D, Semantic::RadianceHDR,
           "direct + indirect diffuse (one bounce), linear radiance")
      .referenceMode = "full";
  b.output("final", OutputKind::Image2D, Semantic::Color, "the tonemapped image: x / (1 + x) of exposure * combined");
  for (const auto& [name, format] : kCompositeImages)
    b.texture(name, [format = format](const ParamSet&, const ViewState& v) { return screenDesc(v, format); });
}

void CompositeStage::execute(StageContext& ctx) {
  Texture* images[3];
  for (int i = 0; i < 3; ++i)
    images[i] = &ctx.board.ensureTexture(kCompositeImages[i].first, screenDesc(ctx.view, kCompositeImages[i].second));
  Texture &direct = *images[0], &combined = *images[1], &final = *images[2];
  GLuint program = ctx.shaders.program({"lpv/composite.comp.glsl"});
  setUniform(program, "u_indirectWeight", ctx.params.getFloat("composite.indirect"));
  setUniform(program, "u_exposure", ctx.params.getFloat("composite.exposure"));
  setUniform(program, "u_glossyWeight", ctx.params.getFloat("composite.glossy"));
  glUseProgram(program);
  const char* inputs[] = {"position", "normal", "albedo", "emission", "indirect-diffuse", "shadow-map", "glossy"};
  for (int i = 0; i < 7; ++i) glBindTextureUnit(1 + i, ctx.board.texture(inputs[i]).id());
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  glBindImageTexture(0, direct.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(1, combined.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(2, final.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA8);
  dispatchCompute({ctx.view.width, ctx.view.height, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
}

}  // namespace voxlab::lpv
