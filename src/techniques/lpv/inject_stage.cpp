// The lpv inject stage: the light's virtual point lights into SH per cell (see lpv.cpp for the
// overview).
#include "techniques/lpv/stages.h"
#include "techniques/lpv/stage_helpers.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "graph/scene_inputs.h"
#include "scene/scene.h"
#include "techniques/common/light_stage.h"
#include "techniques/common/voxel_space.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/lpv/sh.h"

namespace voxlab::lpv {

static size_t unshiftedBytes(const ParamSet& p) { return 64 * cellCount(p); }

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
  b.param(ParamDesc::real("inject.vpl-shift", 0.5, 0.0, 1.0,
                          "move each VPL this far along its normal before it is binned (K&D: 0.5, so a surface's "
                          "light starts on its own side; the thesis: 0); per fragment by default, a whole cell's "
                          "VPL with inject.lighting=per-cell; point VPLs stay put", "cells"));
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
  b.read(kSceneLightsInput);  // the light's type: programs are built for it (lightKindDefines)
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
  GLuint program = ctx.shaders.program({"lpv/inject_fragments.comp.glsl"}, lightKindDefines(ctx.scene));
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
  const float shift = ctx.params.getFloat("inject.vpl-shift");
  setUniform(program, "u_shift", shift);
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
  // Shifted fragments land in a neighbour (a shift of at most one cell): a cell can then also hold
  // those of any of the 26 cells around it.
  if (shift > 0.0f) most *= 27;
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
  GLuint program = ctx.shaders.program({"lpv/inject.comp.glsl"}, lightKindDefines(ctx.scene));
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
    const int passes = ctx.params.getFloat("inject.vpl-shift") > 0.0f && !perFragment ? 2 : 1;
    for (int pass = 0; pass < passes; ++pass) {
      setUniform(program, "u_pass", pass);
      dispatchCompute({res, res, res}, {4, 4, 4});
      barrier();
    }
  }
  ctx.stats["point_vpl"] = point ? 1 : 0;
  ctx.stats["vpl_shift_cells"] = ctx.params.getFloat("inject.vpl-shift");
}

}  // namespace voxlab::lpv
