// The screen-space stages of the clipmap: cone tracing and compositing (see clipmap.cpp for the
// overview).
#include "techniques/clipmap/stages.h"
#include "techniques/clipmap/stage_helpers.h"

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "scene/scene.h"
#include "techniques/common/composite_stage.h"
#include "techniques/common/cone_layout.h"
#include "techniques/common/cone_setup.h"
#include "techniques/common/probe_recorder.h"
#include "techniques/common/sky.h"
#include "techniques/common/traced_image.h"

namespace voxlab::clipmap {

// --- Cone tracing ---------------------------------------------------------------------------------

// Distances in the coarsest level's edge, the start offset in voxels of the finest level there;
// no soft-shadow cone. The start offset is 3/8 of a voxel, not vct-grid's 1.75: the levels are
// around the camera, so a surface a metre away lies in a level of coarse voxels (7 cm on the
// Cornell box, an eighth of the box) and every voxel of offset moves the cones that far off it; at
// 1.75, plus the first step of one voxel along the cone, cones from the boxes' camera-facing faces
// began outside the box's open side and gathered almost nothing. The faces show a cone only the
// fronts it sees (resolve.comp.glsl), so the surface a cone starts from, seen from behind or
// edge-on, does not block it, and the offset need not clear the surface's cell. Measured at
// 128x128 (indirect energy against the reference, Cornell box / sponza / skylight room / two rooms
// / corridor / spheres room, light injected at each triangle's point nearest the cell centre):
// offset 1: 1.29 / 0.86 / 0.87 / 0.84 / 0.52 / 0.90; 0.25: 1.17 / 0.84 / 0.82 / 0.93 / 0.60 / 0.85;
// 0: 1.05 / 0.82 / 0.76 / 0.97 / 0.63 / 0.83 (the skylight room drops below 0.8). With the fronts
// held half a cell (clipmap.front-hold), walls in coarse cells stop the cones that leaked through
// them, which lifts the over-lit top of the Cornell box too: 0.25: 1.28 / 0.83 / 0.87 / 0.93 / 0.67
// / 0.85; 0.125: 1.18 / 0.81 / 0.85 / 0.97 / 0.68 / 0.85; 0: 1.11 / 0.81 / 0.83 / 1.04 / 0.70 /
// 0.84 (the two rooms' SSIM drops from 0.76 to 0.70). With level 0 reading its faces and the
// levels led an eighth of their extent ahead of the camera (256x256): 0.125: 0.95 / 0.77 / 0.85 /
// 0.88 / 0.70 / 0.82 (sponza below 0.8); 0.25: 0.98 / 0.80 / 0.87 / 0.86 / 0.68 / 0.82; 0.375:
// 1.02 / 0.82 / 0.88 / 0.83 / 0.66 / 0.83, the default, the farthest of the three from the band's
// edge at 0.8.
// Nine cones, not vct-grid's six: a cone reads a level of half its diameter (cone.lod-bias = -1),
// so what it sees is the middle half of its footprint, and five ring cones of 60 degrees leave
// gaps between them around the ring (a ring at 60 degrees is 5.4 radians round; five cones see
// about 2.6 of it). Eight around the normal close most of the gaps. Light that arrives from one
// narrow direction falls into them: the corridor's end wall gets most of its light from the
// ceiling and side walls next to the lamp, 65 to 80 degrees off its normal. Measured at 256x256
// (indirect energy against the reference, SSIM, same scene order), six cones: 1.02 (0.86) / 0.82
// / 0.88 (0.81) / 0.83 / 0.66 / 0.83; nine: 0.99 (0.88) / 0.83 / 0.95 (0.86) / 0.84 / 0.74 /
// 0.84; eleven: 0.97 / 0.84 / 1.01 / 0.85 / 0.74 / 0.84 (128x128: seven 0.74 on the corridor, eight
// 0.71, thirteen 0.75). The cone stage costs about 1.5 times six cones' (docs/performance.md).
static ConeDefaults coneDefaults() {
  ConeDefaults d;
  d.count = 9;
  d.aperture = 60.0;
  d.apertureHelp = "full opening angle of each diffuse cone";
  d.startOffset = 0.375;
  d.startOffsetHelp = "cones start this far from the surface along its normal, in voxels of the finest level there";
  d.lodBiasHelp = "level = log2(diameter / s_0) + bias, at least the finest level holding the sample";
  d.maxDistance = 0.5;
  d.maxDistanceLimit = 1.0;
  d.maxDistanceHelp = "longest cone, as a fraction of the coarsest level's edge";
  d.aoRange = 0.125;
  d.aoRangeLimit = 1.0;
  d.aoRangeHelp = "ambient occlusion counts occluders up to this distance, as a fraction of the coarsest level's edge";
  d.softShadowCone = false;
  return d;
}

// The transition band: within this many cells of the border of the finest level that holds a
// sample, the level read ramps up to the next level, so a sample crossing the border changes
// level continuously instead of jumping (0: off, the finest level's whole region is used).
static ParamDesc levelBandParam() {
  return ParamDesc::real("clipmap.transition-band", 0.0, 0.0, 8.0,
                         "within this many cells of the border of the finest level holding a sample, the level read "
                         "ramps linearly to the next level (0 = off)",
                         "cells");
}

// How far behind its surface a front keeps its opacity, in cells of the level read, where a
// sample's level is raised above the cone's own because the finer levels do not reach it
// (shaders/clipmap/cone_trace.comp.glsl, nearFaces). Measured at 128x128 (indirect
// energy against the reference, Cornell box / sponza / skylight room / two rooms / corridor /
// spheres room, start offset 0.125): 0 (off): 1.11 / 0.82 / 0.79 / 0.95 / 0.62 / 0.84;
// 0.5: 1.18 / 0.81 / 0.85 / 0.97 / 0.68 / 0.85; 1: 1.21 / 0.79 / 0.98 / 1.27 / 0.68 / 0.84, the
// light of the lit room through the two rooms' 4 cm wall (their SSIM drops from 0.76 to 0.54).
static ParamDesc frontHoldParam() {
  return ParamDesc::real("clipmap.front-hold", 0.5, 0.0, 1.0,
                         "where a sample reads a level coarser than its cone asks for (the finer levels do not reach "
                         "it), each directional face is also read this many cells back along the cone and the more "
                         "opaque kept, so a surface the cone crosses between samples still stops it (0 = off)",
                         "cells");
}

void ConeTraceStage::declare(StageBuilder& b) const {
  for (const auto& p : layoutParams()) b.param(p);
  for (const auto& p : pathParams()) b.param(p);
  b.param(levelBandParam());
  b.param(frontHoldParam());
  b.param(kTracedCones.resolutionParam());
  declareConeParams(b, coneDefaults());
  declareSky(b);
  b.readView();
  b.read("clip-atlas");
  b.read("clip-mips");
  b.read("position");
  b.read("normal");
  b.read("albedo");
  b.read("light");
  b.output("indirect-diffuse", OutputKind::Image2D, Semantic::RadianceHDR,
           "outgoing indirect diffuse radiance: albedo * weighted sum of the diffuse cones")
      .referenceMode = "indirect-1";
  // Traced only when something reads it (composite.specular above 0, a view, --only).
  b.output("indirect-specular", OutputKind::Image2D, Semantic::RadianceHDR, "radiance gathered by the specular cone")
      .onDemand = true;
  b.output("ambient-occlusion", OutputKind::Image2D, Semantic::Fraction,
           "cosine-weighted visible fraction within ao.range (1 = open)").alongside = true;
  b.output("level-used", OutputKind::Image2D, Semantic::Scalar,
           "per pixel, the finest clip level whose region holds the surface point (-1: outside every level, or sky)").alongside = true;
  coneSamplesOutput(b, "every sample of the probed pixel's cones: centre+diameter, accumulated radiance+opacity, "
                       "cone/distance/level read (floor: the finer level, fraction: the next level's weight)/alpha");
  const std::pair<const char*, GLenum> traced[] = {{"indirect-diffuse", GL_RGBA16F}, {"indirect-specular", GL_RGBA16F},
                                                   {"ambient-occlusion", GL_R16F}, {"level-used", GL_R16F}};
  for (const auto& [name, format] : traced)
    kTracedCones.declareImage(b, name, format);
}

void ConeTraceStage::execute(StageContext& ctx) {
  const Layout layout = layoutOf(ctx.params, ctx.scene);
  const auto path = cameraPath(ctx.params, ctx.scene, ctx.view);
  const auto& origins = path.back().origins;
  Texture& indirect = ctx.board.ensureTexture("indirect-diffuse", kTracedCones.desc(ctx.params, ctx.view, GL_RGBA16F));
  const bool traceSpecular = ctx.wants("indirect-specular");
  // Without the specular cone its image unit is bound to the indirect image, never written there.
  Texture& specular = traceSpecular ? ctx.board.ensureTexture("indirect-specular", kTracedCones.desc(ctx.params, ctx.view, GL_RGBA16F)) : indirect;
  Texture& ao = ctx.board.ensureTexture("ambient-occlusion", kTracedCones.desc(ctx.params, ctx.view, GL_R16F));
  Texture& level = ctx.board.ensureTexture("level-used", kTracedCones.desc(ctx.params, ctx.view, GL_R16F));
  Buffer& samples = ctx.board.ensureBuffer("cone-samples", coneSamplesBytes());
  Buffer& sampleCount = ctx.board.ensureBuffer("cone-samples.count", 4);
  const uint32_t zero = 0;
  sampleCount.upload(&zero, 4);

  // Every pixel, then the probed pixel's samples (common/probe_recorder.glsl).
  const auto [tracer, recorder] = tracerAndRecorder(ctx.shaders, {"clipmap/cone_trace.comp.glsl"},
                                                    "#define CLIPMAP_FACES " + std::to_string(facesOf(ctx.params)) +
                                                        "\n#define CLIPMAP_LEVEL_BAND " +
                                                        (ctx.params.getFloat("clipmap.transition-band") > 0.0f ? "1\n" : "0\n"));
  std::vector<glm::vec3> mins(kMaxLevels, glm::vec3(0.0f)), offsets(kMaxLevels, glm::vec3(0.0f));
  for (int k = 0; k < layout.levels; ++k) {
    mins[size_t(k)] = glm::vec3(glm::dvec3(origins[size_t(k)]) * layout.voxelSize(k));
    offsets[size_t(k)] = glm::vec3(toroidal(origins[size_t(k)], layout.n));
  }
  const float coarsestEdge = float(layout.voxelSize(layout.levels - 1) * layout.n);
  const glm::ivec3 traced = indirect.desc().size;
  glm::ivec2 probe(0);
  for (GLuint program : {tracer, recorder}) {
    setClipUniforms(program, layout, origins);
    glProgramUniform3fv(program, glGetUniformLocation(program, "u_levelMin"), kMaxLevels, &mins[0].x);
    glProgramUniform3fv(program, glGetUniformLocation(program, "u_levelToroidal"), kMaxLevels, &offsets[0].x);
    setUniform(program, "u_voxelSize0", float(layout.voxelSize0));
    setUniform(program, "u_levelBand", ctx.params.getFloat("clipmap.transition-band"));
    setUniform(program, "u_frontHold", ctx.params.getFloat("clipmap.front-hold"));
    setUniform(program, "u_mipLevels", mipCount(layout.n));
    // The start offset is in voxels of the finest level holding the surface (the shader scales it).
    // The camera at the end of the path (the G-buffer's), for the specular cone's view direction.
    probe = setConeUniforms(program, ctx.params, pathEndView(ctx.params, ctx.view), 1.0f, coarsestEdge,
                            glm::ivec2(traced), kTracedCones.scale(ctx.params));
    setSkyUniforms(program, ctx.params, ctx.scene);
    setUniform(program, "u_traceSpecular", traceSpecular ? 1 : 0);
  }
  glUseProgram(tracer);
  glBindTextureUnit(0, ctx.board.texture("clip-atlas").id());
  glBindTextureUnit(4, ctx.board.texture("clip-mips").id());
  glBindTextureUnit(1, ctx.board.texture("position").id());
  glBindTextureUnit(2, ctx.board.texture("normal").id());
  glBindTextureUnit(3, ctx.board.texture("albedo").id());
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_CONE_SAMPLES, samples.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_CONE_SAMPLE_COUNT, sampleCount.id());
  glBindImageTexture(0, indirect.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(1, specular.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(2, ao.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R16F);
  glBindImageTexture(3, level.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R16F);
  dispatchCompute({traced.x, traced.y, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  dispatchRecorder(recorder, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  ctx.stats["diffuse_cones"] = double(ctx.params.getInt("cone.count"));
  ctx.stats["traced_pixels"] = double(traced.x) * traced.y;
  ctx.stats["probe_x"] = probe.x;
  ctx.stats["probe_y_from_top"] = traced.y - 1 - probe.y;
}

// --- Composite ------------------------------------------------------------------------------------

CompositeTerms compositeTerms() {
  CompositeTerms t;
  t.summary = "Add direct light, indirect diffuse and indirect specular, then tonemap.";
  t.combinedHelp = "direct + indirect diffuse + specular, linear radiance";
  t.params = layoutParams();
  for (const ParamDesc& p :
       {kTracedCones.resolutionParam(), compositeExposureParam(),
        ParamDesc::real("composite.indirect", 1.0, 0.0, 4.0, "weight of the indirect diffuse term (1 = physical)"),
        compositeSpecularParam()})
    t.params.push_back(p);
  t.indirect = {{"indirect-diffuse", "composite.indirect"}, {"indirect-specular", "composite.specular"}};
  t.traced = kTracedCones;
  // Samples more than two level-0 voxels off the pixel's plane belong to another surface.
  t.planeDistance = [](const ParamSet& p, const Scene& scene) { return float(2.0 * layoutOf(p, scene).voxelSize0); };
  return t;
}

}  // namespace voxlab::clipmap
