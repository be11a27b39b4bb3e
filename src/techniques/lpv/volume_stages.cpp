// The lpv stages that place the cascades and bin the voxels into them: place and bin (see lpv.cpp
// for the overview).
#include "techniques/lpv/stages.h"
#include "techniques/lpv/stage_helpers.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "scene/scene.h"
#include "techniques/common/voxel_space.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/lpv/sh.h"

namespace voxlab::lpv {

static std::string voxelColourVolume(int cascade) { return std::string("voxel-colour-") + kCascadeNames[cascade]; }
static ParamDesc cascadeRatioParam() {
  return ParamDesc::real("lpv.cascade-ratio", 2.0, 1.25, 4.0,
                         "coarse cell / fine cell (2: the thesis' 8x volume; GPU Pro 4 uses 1.6)");
}
static ParamDesc centreParam() {
  return ParamDesc::choice("lpv.centre", {"view", "scene", "camera"}, 0,
                           "centre of the grids. view: the fine grid on the point GPU Pro 4 puts it (camera + "
                           "forward * half its extent) moved into the scene's bounds, the coarse grid on the "
                           "scene's centre, so the coarse grid covers the whole scene and serves what the fine "
                           "one does not; scene: both on the scene's centre (the fine grid then covers it all "
                           "and the coarse one is not used); camera: both ahead of the camera as GPU Pro 4");
}
// The descs and sizes execute() allocates, shared with declare() (the resource budget).
static TextureDesc voxelColourDesc(int res) {
  TextureDesc d = shDesc(res);
  d.format = GL_RGBA8;
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}
static size_t voxelFragmentsBytes(const ParamSet& p) {
  const size_t res = size_t(p.getInt("voxel.resolution"));
  return 4 * res * res * res;
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
  } else if (params.getChoice("lpv.centre") == "view") {
    const glm::vec3 forward = -glm::vec3(view.view[0][2], view.view[1][2], view.view[2][2]);
    const float halfFine = 0.5f * cell[0] * float(res);
    centre[0] = glm::clamp(view.position + forward * (0.5f * halfFine), scene.bounds.min, scene.bounds.max);
    centre[1] = 0.5f * (scene.bounds.min + scene.bounds.max);
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
             std::string("decoded ") + kCascadeNames[c] + " cells: stored linear albedo, alpha = occupied")
        .alongside = true;  // decoded in the pass that bins the fragments
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

}  // namespace voxlab::lpv
