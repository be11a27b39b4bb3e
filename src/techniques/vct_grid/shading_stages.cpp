// The screen-space stages of vct-grid: cone tracing and compositing (the G-buffer is shared:
// techniques/common/gbuffer_stage.h).
#include <algorithm>
#include <cmath>
#include <vector>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "scene/gpu_scene.h"
#include "techniques/common/sky.h"
#include "techniques/common/voxel_space.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/vct_grid/cone_layout.h"
#include "techniques/vct_grid/stages.h"

namespace voxlab::vct {

static constexpr float kDegrees = 3.14159265358979f / 180.0f;

static ParamDesc traceResolutionParam() {
  return ParamDesc::choice("cone.resolution", {"half", "full"}, 0,
                           "trace cones for every pixel (full) or every 2x2 block (half, 4x cheaper; composite "
                           "upsamples along surfaces)");
}

static int traceScale(const ParamSet& params) { return params.getChoice("cone.resolution") == "half" ? 2 : 1; }

// Size of the traced images: the view, divided by the trace scale (rounded up).
static TextureDesc tracedDesc(const ViewState& view, const ParamSet& params, GLenum format) {
  int s = traceScale(params);
  TextureDesc d;
  d.format = format;
  d.size = {(view.width + s - 1) / s, (view.height + s - 1) / s, 1};
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}

static TextureDesc screenDesc(const ViewState& view, GLenum format) {
  TextureDesc d;
  d.format = format;
  d.size = {view.width, view.height, 1};
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}

// --- Cone tracing --------------------------------------------------------------------------------

void ConeTraceStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(traceResolutionParam());
  b.param(ParamDesc::integer("cone.count", 6, 1, VOXLAB_MAX_CONES, "number of diffuse cones", "cones"));
  b.param(ParamDesc::real("cone.aperture", 45.0, 5.0, 120.0,
                          "full opening angle of each diffuse cone (ring layout: the outer cones are tilted by as much; "
                          "at 60 their lower edges graze the surface, which then occludes and lights itself)",
                          "degrees"));
  b.param(ParamDesc::choice("cone.layout", {"ring", "fibonacci"}, 0,
                            "ring: one cone on the normal and the rest around it; fibonacci: a cosine-distributed spiral"));
  b.param(ParamDesc::choice("cone.weighting", {"cosine", "equal"}, 0,
                            "cone weights, normalised to sum to 1: proportional to the cosine of each cone's axis, or equal"));
  b.param(ParamDesc::real("cone.start-offset", 1.75, 0.0, 8.0,
                          "cones start this far from the surface along its normal (avoids self-occlusion)", "voxels"));
  b.param(ParamDesc::real("cone.step", 0.5, 0.1, 1.0, "step length as a fraction of the sample diameter"));
  b.param(ParamDesc::real("cone.lod-bias", -1.0, -2.0, 1.0,
                          "mip level = log2(diameter / voxel) + bias; -1 makes the filter support equal the diameter"));
  b.param(ParamDesc::real("cone.max-distance", 1.75, 0.05, 2.0,
                          "longest cone, as a fraction of the volume edge (1.75: past the diagonal, so a cone can reach "
                          "any wall; cones also stop where they leave the volume)"));
  b.param(ParamDesc::real("ao.range", 0.25, 0.01, 2.0,
                          "ambient occlusion counts occluders up to this distance, as a fraction of the volume edge"));
  b.param(ParamDesc::real("specular.roughness", 0.2, 0.0, 1.0,
                          "specular cone aperture = max(2, 90 * roughness) degrees"));
  b.param(ParamDesc::real("shadow.cone-aperture", 8.0, 1.0, 60.0, "opening angle of the soft-shadow cone", "degrees"));
  b.param(ParamDesc::real("probe.x", 0.5, 0.0, 1.0, "horizontal position of the probed pixel (0 left, 1 right)"));
  b.param(ParamDesc::real("probe.y", 0.5, 0.0, 1.0, "vertical position of the probed pixel (0 top, 1 bottom)"));
  b.probe(ProbeDesc::screen("probe.x", "probe.y"));
  b.param(mipmapModeParam());
  b.param(skyRadianceParam());
  b.readView();
  declareGatheredGridReads(b);  // the mip stage's grid, or the last bounce's (bounce_stage.cpp)
  b.read("position");
  b.read("normal");
  b.read("albedo");
  b.read("light");
  b.write("cone-samples.count");
  b.write("cone-trace.counts");
  b.buffer("cone-trace.counts", [](const ParamSet&, const ViewState&) { return size_t(20); });
  // One diffuse gather of the direct-lit voxels: exactly one indirect bounce (docs/fidelity.md).
  b.output("indirect-diffuse", OutputKind::Image2D, Semantic::RadianceHDR,
           "outgoing indirect diffuse radiance: albedo * weighted sum of the diffuse cones (at cone.resolution)")
      .referenceMode = "indirect-1";
  b.output("indirect-specular", OutputKind::Image2D, Semantic::RadianceHDR, "radiance gathered by the specular cone");
  b.output("ambient-occlusion", OutputKind::Image2D, Semantic::Fraction,
           "cosine-weighted visible fraction within ao.range (1 = open)");
  b.output("soft-shadow", OutputKind::Image2D, Semantic::Fraction, "visibility of the light through the voxels (1 = lit)");
  BufferLayout samples;
  samples.stride = sizeof(gpu::ConeSample);
  samples.fields = {{"position", FieldType::Vec4, 0, FieldRole::Position},
                    {"accumulated", FieldType::Vec4, 16, FieldRole::Color},
                    {"info", FieldType::Vec4, 32, FieldRole::Other}};
  samples.countResource = "cone-samples.count";
  OutputDesc& probed = b.output("cone-samples", OutputKind::Buffer, Semantic::ConeSamples,
           "every sample of the probed pixel's cones (probe.x/probe.y pick the traced pixel): centre+diameter, accumulated radiance+opacity, cone/distance/lod/alpha");
  probed.layout = samples;
  probed.probeRecord = true;  // the records of the pixel the screen probe points at
  const std::pair<const char*, GLenum> traced[] = {{"indirect-diffuse", GL_RGBA16F}, {"indirect-specular", GL_RGBA16F},
                                                   {"ambient-occlusion", GL_R16F}, {"soft-shadow", GL_R16F}};
  for (const auto& [name, format] : traced)
    b.texture(name, [format = format](const ParamSet& p, const ViewState& v) { return tracedDesc(v, p, format); });
  b.buffer("cone-samples", [](const ParamSet&, const ViewState&) {
    return sizeof(gpu::ConeSample) * VOXLAB_MAX_CONES * VOXLAB_MAX_SAMPLES_PER_CONE;
  });
}

void ConeTraceStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  VoxelSpace space = VoxelSpace::fromScene(ctx.scene, res);
  Texture& indirect = ctx.board.ensureTexture("indirect-diffuse", tracedDesc(ctx.view, ctx.params, GL_RGBA16F));
  Texture& specular = ctx.board.ensureTexture("indirect-specular", tracedDesc(ctx.view, ctx.params, GL_RGBA16F));
  Texture& ao = ctx.board.ensureTexture("ambient-occlusion", tracedDesc(ctx.view, ctx.params, GL_R16F));
  Texture& shadow = ctx.board.ensureTexture("soft-shadow", tracedDesc(ctx.view, ctx.params, GL_R16F));
  Buffer& samples = ctx.board.ensureBuffer("cone-samples", sizeof(gpu::ConeSample) * VOXLAB_MAX_CONES * VOXLAB_MAX_SAMPLES_PER_CONE);
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

  float aperture = ctx.params.getFloat("cone.aperture") * kDegrees;
  auto cones = diffuseCones(ctx.params.getInt("cone.count"), aperture, ctx.params.getChoice("cone.layout"),
                            ctx.params.getChoice("cone.weighting"));
  std::vector<glm::vec4> packed;
  for (const auto& c : cones) packed.push_back(glm::vec4(c.direction, c.weight));

  GLuint program = ctx.shaders.program({"vct_grid/cone_trace.comp.glsl"});
  space.setUniforms(program);
  glProgramUniform4fv(program, glGetUniformLocation(program, "u_cones"), GLsizei(packed.size()), &packed[0].x);
  setUniform(program, "u_coneCount", int(cones.size()));
  setUniform(program, "u_diffuseAperture", aperture);
  setUniform(program, "u_specularAperture", std::max(2.0f, 90.0f * ctx.params.getFloat("specular.roughness")) * kDegrees);
  setUniform(program, "u_shadowAperture", ctx.params.getFloat("shadow.cone-aperture") * kDegrees);
  setUniform(program, "u_startOffset", ctx.params.getFloat("cone.start-offset") * space.voxelSize);
  setUniform(program, "u_stepScale", ctx.params.getFloat("cone.step"));
  setUniform(program, "u_lodBias", ctx.params.getFloat("cone.lod-bias"));
  setUniform(program, "u_maxSteps", 512);
  setUniform(program, "u_maxDistance", ctx.params.getFloat("cone.max-distance") * space.edge());
  setUniform(program, "u_aoRange", ctx.params.getFloat("ao.range") * space.edge());
  setUniform(program, "u_cameraPos", ctx.view.position);
  // probe.y counts from the top of the image; GL rows count from the bottom.
  int probeX = std::min(int(ctx.params.getFloat("probe.x") * traced.x), traced.x - 1);
  int probeY = std::min(int((1.0f - ctx.params.getFloat("probe.y")) * traced.y), traced.y - 1);
  setUniform(program, "u_scale", traceScale(ctx.params));
  glProgramUniform2i(program, glGetUniformLocation(program, "u_probePixel"), probeX, probeY);

  setUniform(program, "u_anisotropic", ctx.params.getChoice("mipmap.mode") == "anisotropic" ? 1 : 0);
  setSkyUniform(program, ctx.params);
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
  ctx.stats["samples_per_diffuse_cone"] = totals[0] / (shaded * double(cones.size()));
  ctx.stats["samples_per_specular_cone"] = totals[1] / shaded;
  ctx.stats["samples_per_shadow_cone"] = totals[2] / shaded;
  ctx.stats["fetches_per_sample"] = totals[3] / allSamples;
  ctx.stats["diffuse_cones"] = double(cones.size());
  ctx.stats["traced_pixels"] = double(traced.x) * traced.y;
  ctx.stats["probe_x"] = probeX;
  ctx.stats["probe_y_from_top"] = traced.y - 1 - probeY;
}

// --- Composite -----------------------------------------------------------------------------------

void CompositeStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(traceResolutionParam());
  b.param(ParamDesc::real("composite.exposure", 1.0, 0.01, 64.0, "scale applied before tonemapping"));
  b.param(ParamDesc::real("composite.indirect", 1.0, 0.0, 4.0, "weight of the indirect diffuse term (1 = physical)"));
  b.param(ParamDesc::real("composite.specular", 0.04, 0.0, 1.0,
                          "weight of the indirect specular term (0.04 = a dielectric's reflectance at normal incidence)"));
  b.param(ParamDesc::choice("composite.shadow", {"shadow-map", "soft-shadow-cone"}, 0,
                            "visibility of direct light: the shadow map, or the soft-shadow cone"));
  b.read("position");
  b.read("normal");
  b.read("albedo");
  b.read("emission");
  b.read("indirect-diffuse");
  b.read("indirect-specular");
  b.read("soft-shadow");
  b.read("shadow-map");
  b.read("light");
  b.output("direct", OutputKind::Image2D, Semantic::RadianceHDR, "direct light plus emission").referenceMode =
      "direct";
  b.output("combined", OutputKind::Image2D, Semantic::RadianceHDR, "direct + indirect diffuse + specular, linear radiance")
      .referenceMode = "full";
  b.output("final", OutputKind::Image2D, Semantic::Color, "the tonemapped image: x / (1 + x) of exposure * combined");
  const std::pair<const char*, GLenum> images[] = {{"direct", GL_RGBA16F}, {"combined", GL_RGBA16F}, {"final", GL_RGBA8}};
  for (const auto& [name, format] : images)
    b.texture(name, [format = format](const ParamSet&, const ViewState& v) { return screenDesc(v, format); });
}

void CompositeStage::execute(StageContext& ctx) {
  Texture& direct = ctx.board.ensureTexture("direct", screenDesc(ctx.view, GL_RGBA16F));
  Texture& combined = ctx.board.ensureTexture("combined", screenDesc(ctx.view, GL_RGBA16F));
  Texture& final = ctx.board.ensureTexture("final", screenDesc(ctx.view, GL_RGBA8));
  GLuint program = ctx.shaders.program({"vct_grid/composite.comp.glsl"});
  setUniform(program, "u_shadowSource", ctx.params.getInt("composite.shadow"));
  setUniform(program, "u_specularWeight", ctx.params.getFloat("composite.specular"));
  setUniform(program, "u_indirectWeight", ctx.params.getFloat("composite.indirect"));
  setUniform(program, "u_exposure", ctx.params.getFloat("composite.exposure"));
  setUniform(program, "u_traceScale", traceScale(ctx.params));
  // Samples more than two voxels off the pixel's plane belong to another surface.
  setUniform(program, "u_edgeDistance", 2.0f * VoxelSpace::fromScene(ctx.scene, ctx.params.getInt("voxel.resolution")).voxelSize);
  glUseProgram(program);
  const char* inputs[] = {"position", "normal", "albedo", "emission", "indirect-diffuse", "indirect-specular",
                          "soft-shadow", "shadow-map"};
  for (int i = 0; i < 8; ++i) glBindTextureUnit(1 + i, ctx.board.texture(inputs[i]).id());
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  glBindImageTexture(0, direct.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(1, combined.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(2, final.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA8);
  dispatchCompute({ctx.view.width, ctx.view.height, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
}

}  // namespace voxlab::vct
