// The screen-space stages of vct-grid: cone tracing and compositing (the G-buffer is shared:
// techniques/common/gbuffer_stage.h).
#include <algorithm>
#include <cmath>
#include <vector>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "scene/gpu_scene.h"
#include "techniques/common/composite_stage.h"
#include "techniques/common/cone_layout.h"
#include "techniques/common/cone_setup.h"
#include "techniques/common/sky.h"
#include "techniques/common/traced_image.h"
#include "techniques/common/voxel_space.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/vct_grid/stages.h"

namespace voxlab::vct {

// --- Cone tracing --------------------------------------------------------------------------------

void ConeTraceStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(kTracedCones.resolutionParam());
  declareConeParams(b, ConeDefaults{});  // one voxel volume's cones (cone_setup.h)
  b.param(mipmapModeParam());
  b.param(mipmapFrontsParam());
  declareSky(b);
  b.readView();
  declareGatheredGridReads(b);  // the mip stage's grid, or the last bounce's (bounce_stage.cpp)
  declarePackedDirectional(b);
  b.read("position");
  b.read("normal");
  b.read("albedo");
  b.read("light");
  b.write("cone-trace.counts");
  b.buffer("cone-trace.counts", [](const ParamSet&, const ViewState&) { return size_t(20); });
  // One diffuse gather of the direct-lit voxels: exactly one indirect bounce (docs/fidelity.md).
  b.output("indirect-diffuse", OutputKind::Image2D, Semantic::RadianceHDR,
           "outgoing indirect diffuse radiance: albedo * weighted sum of the diffuse cones (at cone.resolution)")
      .referenceMode = "indirect-1";
  // Traced only when something reads it (composite.specular above 0, a view, --only).
  b.output("indirect-specular", OutputKind::Image2D, Semantic::RadianceHDR, "radiance gathered by the specular cone")
      .onDemand = true;
  b.output("ambient-occlusion", OutputKind::Image2D, Semantic::Fraction,
           "cosine-weighted visible fraction within ao.range (1 = open)").alongside = true;
  // Traced only when something reads it (composite.shadow=soft-shadow-cone, a view, --only): the
  // default composite takes its visibility from the shadow map.
  b.output("soft-shadow", OutputKind::Image2D, Semantic::Fraction, "visibility of the light through the voxels (1 = lit)")
      .onDemand = true;
  coneSamplesOutput(b, "every sample of the probed pixel's cones (probe.x/probe.y pick the traced pixel): centre+diameter, "
                       "accumulated radiance+opacity, cone/distance/lod/alpha");
  const std::pair<const char*, GLenum> traced[] = {{"indirect-diffuse", GL_RGBA16F}, {"indirect-specular", GL_RGBA16F},
                                                   {"ambient-occlusion", GL_R16F}, {"soft-shadow", GL_R16F}};
  for (const auto& [name, format] : traced)
    kTracedCones.declareImage(b, name, format);
}

void ConeTraceStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  VoxelSpace space = VoxelSpace::fromScene(ctx.scene, res);
  Texture& indirect = ctx.board.ensureTexture("indirect-diffuse", kTracedCones.desc(ctx.params, ctx.view, GL_RGBA16F));
  const bool traceSpecular = ctx.wants("indirect-specular");
  // Without the specular cone its image unit is bound to the indirect image, never written there.
  Texture& specular = traceSpecular ? ctx.board.ensureTexture("indirect-specular", kTracedCones.desc(ctx.params, ctx.view, GL_RGBA16F)) : indirect;
  Texture& ao = ctx.board.ensureTexture("ambient-occlusion", kTracedCones.desc(ctx.params, ctx.view, GL_R16F));
  const bool traceShadow = ctx.wants("soft-shadow");
  // Without the shadow cone its image unit is bound to the ambient-occlusion image, never written.
  Texture& shadow = traceShadow ? ctx.board.ensureTexture("soft-shadow", kTracedCones.desc(ctx.params, ctx.view, GL_R16F)) : ao;
  Buffer& samples = ctx.board.ensureBuffer("cone-samples", coneSamplesBytes());
  Buffer& sampleCount = ctx.board.ensureBuffer("cone-samples.count", 4);
  Buffer& counts = ctx.board.ensureBuffer("cone-trace.counts", 20);
  glm::ivec3 traced = indirect.desc().size;
  // Bands of rows (a multiple of the 8-row work group), top of the image first as a reader scans.
  const int bandRows = (traced.y + kBands * 8 - 1) / (kBands * 8) * 8;
  const int firstRow = std::max(traced.y - (ctx.iteration + 1) * bandRows, 0);
  const int rows = traced.y - ctx.iteration * bandRows - firstRow;
  if (ctx.iteration == 0) {
    // Start empty, so a stepped run shows exactly the bands traced so far.
    const uint32_t zero = 0;
    sampleCount.upload(&zero, 4);
    const uint32_t noCounts[5] = {0, 0, 0, 0, 0};
    counts.upload(noCounts, sizeof(noCounts));
    const float none[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    for (Texture* t : {&indirect, &specular, &ao, &shadow}) glClearTexImage(t->id(), 0, GL_RGBA, GL_FLOAT, none);
  }

  GLuint program = ctx.shaders.program({"vct_grid/cone_trace.comp.glsl"}, coneVolumeDefines(ctx.params));
  space.setUniforms(program);
  const glm::ivec2 probe = setConeUniforms(program, ctx.params, ctx.view, space, glm::ivec2(traced), kTracedCones.scale(ctx.params));
  const int probeX = probe.x, probeY = probe.y;
  const size_t coneCount = size_t(ctx.params.getInt("cone.count"));

  setUniform(program, "u_traceShadow", traceShadow ? 1 : 0);
  setUniform(program, "u_traceSpecular", traceSpecular ? 1 : 0);
  setSkyUniforms(program, ctx.params, ctx.scene);
  glUseProgram(program);
  bindRadianceGrid(ctx, ctx.params.getInt("bounces"));
  glBindTextureUnit(1, ctx.board.texture("position").id());
  glBindTextureUnit(2, ctx.board.texture("normal").id());
  glBindTextureUnit(3, ctx.board.texture("albedo").id());
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_CONE_SAMPLES, samples.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_CONE_SAMPLE_COUNT, sampleCount.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_CONE_TRACE_COUNTS, counts.id());
  glBindImageTexture(0, indirect.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(1, specular.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(2, ao.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R16F);
  glBindImageTexture(3, shadow.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R16F);
  setUniform(program, "u_firstRow", firstRow);
  setUniform(program, "u_endRow", firstRow + rows);
  if (rows > 0) dispatchCompute({traced.x, rows, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  // Totals over the bands traced so far: what the cones cost, comparable across machines.
  uint32_t totals[5] = {0, 0, 0, 0, 0};
  glGetNamedBufferSubData(counts.id(), 0, sizeof(totals), totals);
  const double shaded = std::max(1.0, double(totals[4]));
  const double allSamples = std::max(1.0, double(totals[0]) + totals[1] + totals[2]);
  ctx.stats["samples_diffuse"] = totals[0];
  ctx.stats["samples_specular"] = totals[1];
  ctx.stats["samples_shadow"] = totals[2];
  ctx.stats["volume_fetches"] = totals[3];
  ctx.stats["shaded_pixels"] = totals[4];
  ctx.stats["samples_per_diffuse_cone"] = totals[0] / (shaded * double(coneCount));
  ctx.stats["samples_per_specular_cone"] = totals[1] / shaded;
  ctx.stats["samples_per_shadow_cone"] = totals[2] / shaded;
  ctx.stats["fetches_per_sample"] = totals[3] / allSamples;
  ctx.stats["diffuse_cones"] = double(coneCount);
  ctx.stats["traced_pixels"] = double(traced.x) * traced.y;
  ctx.stats["probe_x"] = probeX;
  ctx.stats["probe_y_from_top"] = traced.y - 1 - probeY;
}

// --- Composite -----------------------------------------------------------------------------------

CompositeTerms compositeTerms() {
  CompositeTerms t;
  t.summary = "Add direct light, indirect diffuse and indirect specular, then tonemap.";
  t.combinedHelp = "direct + indirect diffuse + specular, linear radiance";
  t.params = {voxelResolutionParam(), kTracedCones.resolutionParam(), compositeExposureParam(),
              ParamDesc::real("composite.indirect", 1.0, 0.0, 4.0, "weight of the indirect diffuse term (1 = physical)"),
              compositeSpecularParam(),
              ParamDesc::choice("composite.shadow", {"shadow-map", "soft-shadow-cone"}, 0,
                                "visibility of direct light: the shadow map, or the soft-shadow cone")};
  t.indirect = {{"indirect-diffuse", "composite.indirect"}, {"indirect-specular", "composite.specular"}};
  t.visibility = CompositeVisibility{"composite.shadow", "soft-shadow-cone", "soft-shadow"};
  t.traced = kTracedCones;
  // Samples more than two voxels off the pixel's plane belong to another surface.
  t.planeDistance = [](const ParamSet& p, const Scene& scene) {
    return 2.0f * VoxelSpace::fromScene(scene, p.getInt("voxel.resolution")).voxelSize;
  };
  return t;
}

}  // namespace voxlab::vct
