// The screen-space lpv stages: reflection, the per-pixel indirect lookup (gi) and compositing (see
// lpv.cpp for the overview).
#include "techniques/lpv/stages.h"
#include "techniques/lpv/stage_helpers.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "scene/scene.h"
#include "techniques/common/traced_image.h"
#include "techniques/common/voxel_space.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/lpv/sh.h"

namespace voxlab::lpv {

static ParamDesc lookupOffsetParam() {
  return ParamDesc::real("gi.lookup-offset", 0.5, 0.0, 1.0,
                         "surfaces read the grid this far along their normal (against self-illumination)", "cells");
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
  b.alongside({"reflection-colour"});  // the words the same pass turns into the radiance
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
  b.output("irradiance-fine", OutputKind::Image2D, Semantic::RadianceHDR, "indirect irradiance from the fine cascade (W/m^2)").alongside = true;
  b.output("irradiance-coarse", OutputKind::Image2D, Semantic::RadianceHDR, "indirect irradiance from the coarse cascade (W/m^2)").alongside = true;
  b.output("cascade-blend", OutputKind::Image2D, Semantic::Fraction, "weight of the coarse cascade (0 fine only, 1 coarse only)").alongside = true;
  b.output("indirect-diffuse", OutputKind::Image2D, Semantic::RadianceHDR,
           "outgoing indirect diffuse radiance: albedo / pi * blended irradiance")
      .referenceMode = "indirect-1";
  // Computed only when something reads it (composite.glossy above 0, a view, --only).
  b.output("glossy", OutputKind::Image2D, Semantic::RadianceHDR,
           "radiance gathered by one cone along the mirrored view direction through the reflection grid's mips")
      .onDemand = true;
  BufferLayout boxes;
  boxes.stride = sizeof(gpu::LpvBox);
  boxes.fields = {{"lo-kind", FieldType::Vec4, 0, FieldRole::Other}, {"hi-cell", FieldType::Vec4, 16, FieldRole::Other}};
  b.output("cascade-boxes", OutputKind::Buffer, kLpvCascades,
           "world boxes: fine cascade, coarse cascade, and the blend shell between coarse weight 0 (inner box) and 1 "
           "(outer box, half a fine cell inside the fine grid's edge)")
      .layout = boxes;
  b.alongside({"cascade-boxes"});
  for (const auto& [name, format] : kGiImages)
    b.texture(name, [format = format](const ParamSet&, const ViewState& v) { return viewImageDesc(v, format); });
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
  const bool glossyWanted = ctx.wants("glossy");
  Texture* images[5] = {};
  for (int i = 0; i < 5; ++i)
    if (i < 4 || glossyWanted)
      images[i] = &ctx.board.ensureTexture(kGiImages[i].first, viewImageDesc(ctx.view, kGiImages[i].second));
  Texture &fine = *images[0], &coarse = *images[1], &blend = *images[2], &indirect = *images[3];
  GLuint program = ctx.shaders.program({"lpv/gi.comp.glsl"});
  const float fineEdge = grids[0].originCell.w * grids[0].centreRes.w;
  const int reflRes = ctx.params.getInt("reflection.resolution");
  setUniform(program, "u_reflectionVoxel", fineEdge / float(reflRes));
  setUniform(program, "u_reflectionLevels", float(ctx.board.texture("reflection").levels()));
  setUniform(program, "u_glossyTan", std::tan(0.5f * ctx.params.getFloat("gi.glossy-aperture") * float(kPi) / 180.0f));
  setUniform(program, "u_glossyDistance", ctx.params.getFloat("gi.glossy-distance") * fineEdge);
  setUniform(program, "u_cameraPos", ctx.view.position);
  setUniform(program, "u_glossyOn", ctx.params.getBool("gi.glossy") ? 1 : 0);
  setUniform(program, "u_glossyWanted", glossyWanted ? 1 : 0);
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
  // Without the glossy image its unit is left empty; the shader does not write it then.
  glBindImageTexture(4, glossyWanted ? images[4]->id() : 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindTextureUnit(9, ctx.board.texture("reflection").id());
  dispatchCompute({ctx.view.width, ctx.view.height, 1}, {8, 8, 1});
  barrier();
  auto boxes = cascadeBoxes(grids, ctx.params.getFloat("gi.blend-width"));
  ctx.board.ensureBuffer("cascade-boxes", sizeof(boxes)).upload(boxes.data(), sizeof(boxes));
}

// --- composite -----------------------------------------------------------------------------------

CompositeTerms compositeTerms() {
  CompositeTerms t;
  t.summary = "Add direct light and the LPV's indirect diffuse light, then tonemap.";
  t.combinedHelp = "direct + indirect diffuse (one bounce), linear radiance";
  t.params = {compositeExposureParam(),
              ParamDesc::real("composite.indirect", 1.0, 0.0, 4.0, "weight of the indirect diffuse term (1 = physical)"),
              ParamDesc::real("composite.glossy", 0.0, 0.0, 1.0,
                              "weight of the glossy term (0: the scenes are Lambertian, as the reference path tracer)")};
  // Both looked up per pixel at full resolution.
  t.indirect = {{"indirect-diffuse", "composite.indirect", false}, {"glossy", "composite.glossy", false}};
  t.sky = false;
  return t;
}

}  // namespace voxlab::lpv
