#include "techniques/lrsm/stages.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "common/shared.h"
#include "core/error.h"
#include "gpu/shader_library.h"
#include "graph/scene_inputs.h"
#include "lrsm/lrsm_shared.h"
#include "scene/gpu_scene.h"
#include "scene/scene.h"
#include "techniques/common/composite_stage.h"
#include "techniques/common/cone_setup.h"
#include "techniques/common/light_stage.h"
#include "techniques/common/probe_recorder.h"
#include "techniques/common/sky.h"
#include "techniques/common/voxel_space.h"
#include "techniques/common/voxelize_stage.h"

namespace voxlab::lrsm {

static constexpr float kDegrees = 3.14159265f / 180.0f;

static gpu::GpuLight readLight(Blackboard& board) {
  gpu::GpuLight light{};
  auto bytes = board.buffer("light").download(sizeof(light));
  std::memcpy(&light, bytes.data(), sizeof(light));
  return light;
}

// Spot and point lights measure depth radially from their position; a directional light along its direction.
static bool radialDepth(const gpu::GpuLight& light) { return light.positionType.w > VOXLAB_LIGHT_DIRECTIONAL + 0.5f; }

int lrsmLevels(int width) {
  int l = 1;
  while ((1 << (l - 1)) < width) ++l;
  return l;
}

static int levelsOf(int res) { return lrsmLevels(res); }

// Must equal the shared RsmStage's declaration (parameters are shared by name).
static ParamDesc rsmResolutionParam() {
  return ParamDesc::integer("rsm.resolution", 512, 64, 4096, "reflective shadow map width and height", "px").pow2();
}
static ParamDesc depthSplitsParam() {
  return ParamDesc::integer("lrsm.depth-splits", 1, 0, kMaxSplits, "a: depth splits; a + 1 equal depth intervals");
}
static ParamDesc normalSplitsParam() {
  return ParamDesc::integer("lrsm.normal-splits", 1, 0, kMaxSplits, "b: <n.l> splits; b + 1 equal <n.l> intervals");
}
static ParamDesc overlapParam() {
  return ParamDesc::real("lrsm.overlap", 0.25, 0.0, 1.0,
                         "overlap width delta as a fraction of one depth interval (sampling only)");
}

static TextureDesc texDesc(glm::ivec3 size, GLenum format, int levels = 1, GLenum filter = GL_NEAREST,
                           GLenum target = GL_TEXTURE_2D) {
  TextureDesc d;
  d.target = target;
  d.format = format;
  d.size = size;
  d.levels = levels;
  d.minFilter = filter;
  d.magFilter = filter == GL_LINEAR_MIPMAP_LINEAR || filter == GL_LINEAR_MIPMAP_NEAREST ? GL_LINEAR : filter;
  return d;
}

// The descs execute() passes to ensureTexture, shared with declare() (the resource budget).
static TextureDesc occlusionVoxelsDesc(int res) { return texDesc({res, res, res}, GL_R8, 1, GL_NEAREST, GL_TEXTURE_3D); }
static TextureDesc occlusionMipsDesc(int res) {
  return texDesc({res, res, res}, GL_R8, levelsOf(res), GL_LINEAR_MIPMAP_LINEAR, GL_TEXTURE_3D);
}
static TextureDesc rsmTexDesc(int rsm, GLenum format) { return texDesc({rsm, rsm, 1}, format); }
static int layerCount(const ParamSet& p) { return (p.getInt("lrsm.depth-splits") + 1) * (p.getInt("lrsm.normal-splits") + 1); }
// The layer atlas: n layers of (rsm / 2)^2 side by side.
static glm::ivec3 atlasSize(int rsm, int n) { return {(rsm / 2) * n, rsm / 2, 1}; }
static TextureDesc lrsmMipDesc(glm::ivec3 base, GLenum format) {
  return texDesc(base, format, lrsmLevels(base.y), GL_LINEAR_MIPMAP_NEAREST);
}
static TextureDesc coverageSumDesc(int w) { return texDesc({w, w, 1}, GL_R16F, lrsmLevels(w)); }
static glm::ivec3 traceSize(const ParamSet& p, const ViewState& v) { return glm::ivec3(kTracedCones.size(p, v), 1); }
static constexpr size_t kGatherRecordsBytes = sizeof(gpu::LrsmGatherRecord) * LRSM_MAX_GATHER_RECORDS;
static constexpr double kProbeDefaultY = 0.6;  // a floor pixel of the Cornell box
static constexpr size_t kConeResultsBytes = sizeof(gpu::LrsmConeResult) * (LRSM_MAX_CONES + 1);

LayerLayout layoutFor(const Scene& scene, Blackboard& board, const ParamSet& params) {
  LayerLayout L;
  L.depthSplits = params.getInt("lrsm.depth-splits");
  L.normalSplits = params.getInt("lrsm.normal-splits");
  L.overlap = params.getFloat("lrsm.overlap");
  const gpu::GpuLight light = readLight(board);
  const glm::vec3 pos(light.positionType), dir(light.directionRange);
  const bool spot = radialDepth(light);
  float lo = 1e30f, hi = -1e30f;
  const Bounds& b = scene.bounds;
  for (int i = 0; i < 8; ++i) {
    glm::vec3 c((i & 1) ? b.max.x : b.min.x, (i & 2) ? b.max.y : b.min.y, (i & 4) ? b.max.z : b.min.z);
    float z = spot ? glm::length(c - pos) : glm::dot(c, dir);
    lo = std::min(lo, z);
    hi = std::max(hi, z);
  }
  if (spot) lo = glm::length(glm::clamp(pos, b.min, b.max) - pos);  // nearest point of the bounds
  // Grow by 1 % so that no surface lies exactly on zNear or zFar.
  const float pad = 0.01f * std::max(hi - lo, 1e-6f);
  L.zNear = lo - pad;
  L.zFar = hi + pad;
  return L;
}

static void setLayoutUniforms(GLuint program, const LayerLayout& L) {
  setUniform(program, "u_depthIntervals", L.depthIntervals());
  setUniform(program, "u_normalIntervals", L.normalIntervals());
  setUniform(program, "u_zNear", L.zNear);
  setUniform(program, "u_zFar", L.zFar);
  setUniform(program, "u_delta", L.delta());
}

// --- Occlusion voxels -----------------------------------------------------------------------------

void OcclusionVoxelsStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.read("fragments");
  b.read("fragments.count");
  auto& o = b.output("occlusion-voxels", OutputKind::Volume3D, Semantic::Occupancy,
                     "binary occlusion, R8 (1 byte per voxel): 1 where the conservative fragment list has a voxel");
  o.tier = CaptureTier::Exact;
  b.texture("occlusion-voxels",
            [](const ParamSet& p, const ViewState&) { return occlusionVoxelsDesc(p.getInt("voxel.resolution")); });
}

void OcclusionVoxelsStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  Texture& voxels = ctx.board.ensureTexture("occlusion-voxels", occlusionVoxelsDesc(res));
  const float zero = 0.0f;
  glClearTexImage(voxels.id(), 0, GL_RED, GL_FLOAT, &zero);
  const uint32_t fragments = voxelFragmentCount(ctx.board);
  GLuint program = ctx.shaders.program({"lrsm/occlusion_voxels.comp.glsl"});
  setUniform(program, "u_resolution", res);
  setUniform(program, "u_fragmentCount", fragments);
  glUseProgram(program);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, ctx.board.buffer("fragments").id());
  glBindImageTexture(0, voxels.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R8);
  if (fragments > 0) dispatchCompute({int(fragments), 1, 1}, {64, 1, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  ctx.stats["fragments_read"] = fragments;
  ctx.stats["bytes"] = double(res) * res * res;
}

// --- Occlusion mips -------------------------------------------------------------------------------

void OcclusionMipsStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.read("occlusion-voxels");
  b.output("occlusion", OutputKind::Volume3D, Semantic::Fraction,
           "isotropic occlusion mips (R8): level 0 = the binary voxels, level k = mean of its 8 children");
  b.texture("occlusion",
            [](const ParamSet& p, const ViewState&) { return occlusionMipsDesc(p.getInt("voxel.resolution")); });
}

int OcclusionMipsStage::iterations(const ParamSet& params) const { return levelsOf(params.getInt("voxel.resolution")); }

void OcclusionMipsStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  Texture& occ = ctx.board.ensureTexture("occlusion", occlusionMipsDesc(res));
  if (ctx.iteration == 0) {
    glCopyImageSubData(ctx.board.texture("occlusion-voxels").id(), GL_TEXTURE_3D, 0, 0, 0, 0, occ.id(), GL_TEXTURE_3D,
                       0, 0, 0, 0, res, res, res);
    // Later levels start empty, so a stepped run shows exactly the levels built so far.
    const float zero = 0.0f;
    for (int l = 1; l < occ.levels(); ++l) glClearTexImage(occ.id(), l, GL_RED, GL_FLOAT, &zero);
  } else {
    const int level = ctx.iteration;
    const glm::ivec3 size = occ.levelSize(level);
    GLuint program = ctx.shaders.program({"lrsm/occlusion_mip.comp.glsl"});
    setUniform(program, "u_sourceLevel", level - 1);
    setUniform(program, "u_size", size);
    glUseProgram(program);
    glBindTextureUnit(0, occ.id());
    glBindImageTexture(0, occ.id(), level, GL_TRUE, 0, GL_WRITE_ONLY, GL_R8);
    dispatchCompute(size, {4, 4, 4});
  }
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  ctx.stats["levels"] = occ.levels();
  ctx.stats["bytes"] = double(occ.byteSize());
}

// --- Layer assignment -------------------------------------------------------------------------------

void LayersStage::declare(StageBuilder& b) const {
  b.param(rsmResolutionParam());
  b.param(depthSplitsParam());
  b.param(normalSplitsParam());
  b.param(overlapParam());
  b.read("rsm-position");
  b.read("rsm-normal");
  b.read("rsm-radiance");
  b.read("light");
  b.read(kSceneLightsInput);  // the light's type: programs are built for it (lightKindDefines)
  b.output("rsm-depth", OutputKind::Image2D, Semantic::Scalar,
           "per RSM texel: x = light depth z (m; planar for a directional light, radial for a spot or point light), y = <n.l>, "
           "z = layer's warped depth z', 0 where empty").alongside = true;
  auto& id = b.output("layer-id", OutputKind::Image2D, kLayerId,
                      "layer of each RSM texel: depth interval * (b + 1) + <n.l> interval; 255 = empty");
  id.alongside = true;
  id.tier = CaptureTier::Exact;
  b.output("layer-radiance", OutputKind::Image2D, kLayerRadiance,
           "LRSM base, layers side by side: rgb = A*R (radiance premultiplied by coverage), a = alpha");
  b.output("layer-normal", OutputKind::Image2D, kLayerNormal, "LRSM base: xyz = alpha * n, w = alpha");
  b.output("layer-depth", OutputKind::Image2D, kLayerDepth,
           "LRSM base (UNORM16): alpha * z'^k, k = 1..4 (z' warped into the layer's range; alpha is the normal's .w)");
  auto rsmTex = [](GLenum format) {
    return [format](const ParamSet& p, const ViewState&) {
      return rsmTexDesc(p.getInt("rsm.resolution"), format);
    };
  };
  auto atlasTex = [](GLenum format) {
    return [format](const ParamSet& p, const ViewState&) {
      return texDesc(atlasSize(p.getInt("rsm.resolution"), layerCount(p)), format);
    };
  };
  b.texture("rsm-depth", rsmTex(GL_RGBA32F));
  b.texture("layer-id", rsmTex(GL_R8UI));
  b.texture("layer-radiance", atlasTex(GL_RGBA16F));
  b.texture("layer-normal", atlasTex(GL_RGBA16F));
  b.texture("layer-depth", atlasTex(GL_RGBA16));
}

void LayersStage::execute(StageContext& ctx) {
  const int rsm = ctx.params.getInt("rsm.resolution");
  const LayerLayout L = layoutFor(ctx.scene, ctx.board, ctx.params);
  const int n = L.count();
  const glm::ivec3 atlas = atlasSize(rsm, n);
  GLint maxSize = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxSize);
  const std::string tooWide = atlasSizeError(rsm, n, maxSize);
  if (!tooWide.empty()) throw Error(tooWide);
  Texture& depth = ctx.board.ensureTexture("rsm-depth", rsmTexDesc(rsm, GL_RGBA32F));
  Texture& ids = ctx.board.ensureTexture("layer-id", rsmTexDesc(rsm, GL_R8UI));
  Texture& rad = ctx.board.ensureTexture("layer-radiance", texDesc(atlas, GL_RGBA16F));
  Texture& nor = ctx.board.ensureTexture("layer-normal", texDesc(atlas, GL_RGBA16F));
  Texture& dep = ctx.board.ensureTexture("layer-depth", texDesc(atlas, GL_RGBA16));
  const int w = atlas.y;
  const gpu::GpuLight light = readLight(ctx.board);
  GLuint program = ctx.shaders.program({"lrsm/layers.comp.glsl"}, lightKindDefines(ctx.scene));
  setLayoutUniforms(program, L);
  setUniform(program, "u_layerWidth", w);
  glUseProgram(program);
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  glBindTextureUnit(0, ctx.board.texture("rsm-position").id());
  glBindTextureUnit(1, ctx.board.texture("rsm-normal").id());
  glBindTextureUnit(2, ctx.board.texture("rsm-radiance").id());
  glBindImageTexture(0, depth.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glBindImageTexture(1, ids.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R8UI);
  glBindImageTexture(2, rad.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(3, nor.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(4, dep.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16);
  dispatchCompute({w, w, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  ctx.stats["layers"] = n;
  ctx.stats["layer_width"] = w;
  ctx.stats["z_near_m"] = L.zNear;
  ctx.stats["z_far_m"] = L.zFar;
  ctx.stats["overlap_delta_m"] = L.delta();
  ctx.stats["depth_radial"] = radialDepth(light) ? 1 : 0;
}

// --- LRSM mips --------------------------------------------------------------------------------------

void LrsmMipsStage::declare(StageBuilder& b) const {
  b.param(rsmResolutionParam());
  b.read("layer-radiance");
  b.read("layer-normal");
  b.read("layer-depth");
  b.output("lrsm-radiance", OutputKind::Image2D, kLayerRadiance, "LRSM radiance mips per layer: rgb = A*R, a = alpha");
  b.output("lrsm-normal", OutputKind::Image2D, kLayerNormal, "LRSM normal mips per layer: xyz = alpha * n, w = alpha");
  b.output("lrsm-depth", OutputKind::Image2D, kLayerDepth,
           "LRSM moment mips per layer: alpha * z'^k, k = 1..4 (mu = x / alpha, sigma^2 = y / alpha - mu^2; alpha: lrsm-normal .w)");
  b.output("coverage-sum", OutputKind::Image2D, Semantic::Fraction,
           "sum over layers of alpha at every level: the RSM's covered fraction (1 where fully covered)").alongside = true;
  // The base is the layer atlas LayersStage allocates (execute() reads its size from it).
  auto mipTex = [](GLenum format) {
    return [format](const ParamSet& p, const ViewState&) {
      return lrsmMipDesc(atlasSize(p.getInt("rsm.resolution"), layerCount(p)), format);
    };
  };
  b.texture("lrsm-radiance", mipTex(GL_RGBA16F));
  b.texture("lrsm-normal", mipTex(GL_RGBA16F));
  b.texture("lrsm-depth", mipTex(GL_RGBA16));
  b.texture("coverage-sum",
            [](const ParamSet& p, const ViewState&) { return coverageSumDesc(p.getInt("rsm.resolution") / 2); });
}

int LrsmMipsStage::iterations(const ParamSet& params) const { return lrsmLevels(params.getInt("rsm.resolution") / 2); }

void LrsmMipsStage::execute(StageContext& ctx) {
  Texture& baseRad = ctx.board.texture("layer-radiance");
  const glm::ivec3 base = baseRad.desc().size;
  const int w = base.y, n = base.x / base.y, levels = lrsmLevels(w);
  // Filtered within a level (the gather's bilinear lookups, blended across two levels by the shader).
  Texture& rad = ctx.board.ensureTexture("lrsm-radiance", lrsmMipDesc(base, GL_RGBA16F));
  Texture& nor = ctx.board.ensureTexture("lrsm-normal", lrsmMipDesc(base, GL_RGBA16F));
  Texture& dep = ctx.board.ensureTexture("lrsm-depth", lrsmMipDesc(base, GL_RGBA16));
  Texture& sum = ctx.board.ensureTexture("coverage-sum", coverageSumDesc(w));
  const int level = ctx.iteration;
  if (level == 0) {
    const float zero[4] = {0, 0, 0, 0};
    for (Texture* t : {&rad, &nor, &dep, &sum})
      for (int l = 1; l < levels; ++l) glClearTexImage(t->id(), l, GL_RGBA, GL_FLOAT, zero);
  }
  GLuint program = ctx.shaders.program({"lrsm/lrsm_mip.comp.glsl"});
  setUniform(program, "u_reduce", level == 0 ? 0 : 1);
  setUniform(program, "u_sourceLevel", std::max(level - 1, 0));
  setUniform(program, "u_layers", n);
  setUniform(program, "u_tileWidth", w >> level);
  glUseProgram(program);
  glBindTextureUnit(0, level == 0 ? baseRad.id() : rad.id());
  glBindTextureUnit(1, level == 0 ? ctx.board.texture("layer-normal").id() : nor.id());
  glBindTextureUnit(2, level == 0 ? ctx.board.texture("layer-depth").id() : dep.id());
  glBindImageTexture(0, rad.id(), level, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(1, nor.id(), level, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(2, dep.id(), level, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16);
  glBindImageTexture(3, sum.id(), level, GL_FALSE, 0, GL_WRITE_ONLY, GL_R16F);
  dispatchCompute({n * (w >> level), w >> level, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  ctx.stats["levels"] = levels;
  ctx.stats["bytes"] = double(rad.byteSize() + nor.byteSize() + dep.byteSize());
}

// --- Cone gathering -----------------------------------------------------------------------------------

void ConeGatherStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(rsmResolutionParam());
  b.param(depthSplitsParam());
  b.param(normalSplitsParam());
  b.param(overlapParam());
  b.param(kTracedCones.resolutionParam());
  b.param(ParamDesc::choice("lrsm.falloff", {"smoothstep", "linear"}, 0,
                            "k of Eq. 15 across an overlap (both satisfy k(t) + k(1 - t) = 1)"));
  b.param(ParamDesc::real("lrsm.min-variance", kDefaultMinVariance, 1e-7, 0.01,
                          "floor of sigma^2 in warped depth units (UNORM16 moments move E[z^2] - mu^2 by up to 9.2e-5)"));
  b.param(ParamDesc::choice("lrsm.estimator", {"coverage", "paper"}, 0,
                            "what a sphere sample adds to Eq. 1: coverage = T_i * sum_l A*R V <n.v> / <n.l> (the lit "
                            "surface's radiance times the fraction of the cone it covers, depth window half a step); "
                            "paper = T_i * alpha_i * sum_l f A*R V N (Algorithm 1 as printed, window = the radius)"));
  b.param(ParamDesc::choice("lrsm.layer-select", {"window", "overlap"}, 0,
                            "layers a sample reads: window = every layer whose texels' depth interval meets the "
                            "sample's depth window, weight 1 (texels lie in one layer each); overlap = the layers "
                            "whose range holds z_c, weighted by Eq. 15's falloff (the paper's, made for texels "
                            "written to both layers of an overlap)"));
  b.param(ParamDesc::boolean("lrsm.lit-occlusion", true,
                             "coverage estimator: a sample's opacity is at least the coverage of the lit surfaces in its "
                             "window (either facing), so a lit slab blocks the cones the voxel mips let through"));
  b.param(ParamDesc::boolean("lrsm.visibility", true,
                             "Eq. 12's Gaussian depth visibility; off: V = 1, every texel of the sample's column counts"));
  b.param(ParamDesc::boolean("lrsm.two-lobes", true,
                             "V from two Gaussians matched to the layer's four depth moments (two surfaces at different "
                             "depths in one layer leave the air between them empty); off: Eq. 12's single Gaussian"));
  b.param(ParamDesc::real("lrsm.footprint-bias", -1.0, -2.0, 2.0,
                          "added to log2(d_circle), the LRSM level of a sample (blended between two levels)"));
  b.param(ParamDesc::real("cone.step", 1.0, 0.1, 2.0,
                          "step between sphere samples as a fraction of the diameter (1: touching spheres, as SRS14 Fig. 4)"));
  b.param(ParamDesc::boolean("cone.horizon", true,
                             "the receiver's plane bounds what its diffuse cones see: occlusion lookups take a finer mip "
                             "where the coarse one would reach the plane, and lit surfaces whose mean point lies less than "
                             "2 voxels above it are skipped (its own voxels shaded every cone near the surface, in stripes "
                             "where a face crosses voxel columns; the other faces of a box, lit at grazing angles, blotched it)"));
  b.param(ParamDesc::boolean("cone.interleave", true,
                              "each pixel of a 4 x 4 tile starts its diffuse cones' samples at its own 1/16 of the first "
                              "step (the filter stage averages the tile); off: every pixel at cone.start"));
  b.param(ParamDesc::real("cone.start", 1.5, 0.0, 8.0, "distance of the first sample from the surface", "voxels"));
  b.param(ParamDesc::real("cone.lod-bias", 0.0, -2.0, 2.0, "added to the voxel mip log2(diameter / voxel)"));
  b.param(ParamDesc::integer("cone.max-steps", 32, 1, LRSM_MAX_STEPS,
                             "sphere samples per cone at most (32: every default cone leaves the volume first; 48 gave the same image)"));
  b.param(ParamDesc::boolean("cone.specular", false,
                             "trace the 10-degree specular cone for every pixel (the paper traces it only where a pixel "
                             "has a specular component; voxlab's materials are Lambertian, so off by default)"));
  b.param(ParamDesc::real("cone.shadow-aperture", 10.0, 0.5, 30.0,
                          "full apex angle of the shadow cone (10: reaches across the volume within cone.max-steps)", "deg"));
  b.param(ParamDesc::real("cone.shadow-lod-bias", -1.0, -2.0, 2.0,
                          "the shadow cone's voxel mip bias (-1: filter support = the sphere's diameter; at 0, the "
                          "diffuse cones' paper value, it reads the boxes' one-voxel shells at coarse mips and sees "
                          "through them)"));
  b.param(ParamDesc::real("probe.x", 0.5, 0.0, 1.0, "probed pixel, fraction of the width"));
  b.param(ParamDesc::real("probe.y", kProbeDefaultY, 0.0, 1.0, "probed pixel, fraction of the height from the top"));
  b.probe(ProbeDesc::screen("probe.x", "probe.y"));
  declareSky(b);
  b.readView();
  b.read("occlusion");
  b.read("lrsm-radiance");
  b.read("lrsm-normal");
  b.read("lrsm-depth");
  b.read("position");
  b.read("normal");
  b.read("albedo");
  b.read("light");
  b.read(kSceneLightsInput);  // the light's type: programs are built for it (lightKindDefines)
  b.write("gather-records.count");
  b.output("indirect-diffuse", OutputKind::Image2D, Semantic::RadianceHDR,
           "outgoing one-bounce diffuse radiance: albedo / pi * sum_k w_k I_k (at cone.resolution)")
      .referenceMode = "indirect-1";
  b.output("indirect-specular", OutputKind::Image2D, Semantic::RadianceHDR,
           "radiance I gathered by the 10-degree cone along the mirror direction").alongside = true;
  b.output("soft-shadow", OutputKind::Image2D, Semantic::Fraction,
           "transmittance of the shadow cone toward the light through the occlusion mips (1 = lit)")
      .onDemand = true;
  coneSamplesOutput(b, "every sphere sample of the probed pixel's cones: centre + diameter, accumulated I + opacity, "
                       "cone / distance / voxel mip / alpha");
  BufferLayout g;
  g.stride = sizeof(gpu::LrsmGatherRecord);
  const char* names[] = {"centre", "cone", "march", "layer", "moments", "coverage", "contribution", "footprint"};
  for (uint32_t i = 0; i < 8; ++i)
    g.fields.push_back({names[i], FieldType::Vec4, 16 * i, i == 0 ? FieldRole::Position : FieldRole::Other});
  g.countResource = "gather-records.count";
  auto& gr = b.output("gather-records", OutputKind::Buffer, kGatherRecords,
                      "Algorithm 1 per layer for every sphere sample of the probed pixel: x_c r_c, cone/sample/voxel "
                      "mip/alpha, transmittance/RSM uv/LRSM mip, layer/in range/f/N, mu/sigma^2/V/z', A*R/alpha, "
                      "contribution/r', d_circle/z_c/Jacobian 1 / <n.l>");
  gr.alongside = true;
  gr.layout = g;
  gr.probeRecord = true;
  BufferLayout c;
  c.stride = sizeof(gpu::LrsmConeResult);
  c.fields = {{"direction", FieldType::Vec4, 0, FieldRole::Other},
              {"result", FieldType::Vec4, 16, FieldRole::Color},
              {"info", FieldType::Vec4, 32, FieldRole::Other}};
  auto& cr = b.output("cone-results", OutputKind::Buffer, Semantic::Scalar,
                      "the probed pixel's cones: axis + weight, I + opacity, index/samples/aperture/kind (0 diffuse, "
                      "1 specular, 2 shadow, 3 = the final sum: rgb = indirect diffuse)");
  cr.alongside = true;
  cr.layout = c;
  cr.probeRecord = true;
  auto traceTex = [](GLenum format) {
    return [format](const ParamSet& p, const ViewState& v) { return texDesc(traceSize(p, v), format); };
  };
  b.texture("indirect-diffuse", traceTex(GL_RGBA32F));
  b.texture("indirect-specular", traceTex(GL_RGBA16F));
  b.texture("soft-shadow", traceTex(GL_R16F));
  b.buffer("gather-records", [](const ParamSet&, const ViewState&) { return kGatherRecordsBytes; });
  b.buffer("gather-records.count", [](const ParamSet&, const ViewState&) { return size_t(4); });
  b.buffer("cone-results", [](const ParamSet&, const ViewState&) { return kConeResultsBytes; });
}

void ConeGatherStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  const VoxelSpace space = VoxelSpace::fromScene(ctx.scene, res);
  const LayerLayout L = layoutFor(ctx.scene, ctx.board, ctx.params);
  const int s = kTracedCones.scale(ctx.params);
  const glm::ivec3 traced = traceSize(ctx.params, ctx.view);
  const int tw = traced.x, th = traced.y;
  Texture& diffuse = ctx.board.ensureTexture("indirect-diffuse", texDesc(traced, GL_RGBA32F));
  Texture& specular = ctx.board.ensureTexture("indirect-specular", texDesc(traced, GL_RGBA16F));
  const bool traceShadow = ctx.wants("soft-shadow");
  Texture* shadow = traceShadow ? &ctx.board.ensureTexture("soft-shadow", texDesc(traced, GL_R16F)) : nullptr;
  Buffer& samples = ctx.board.ensureBuffer("cone-samples", coneSamplesBytes());
  Buffer& sampleCount = ctx.board.ensureBuffer("cone-samples.count", 4);
  Buffer& records = ctx.board.ensureBuffer("gather-records", kGatherRecordsBytes);
  Buffer& recordCount = ctx.board.ensureBuffer("gather-records.count", 4);
  Buffer& cones = ctx.board.ensureBuffer("cone-results", kConeResultsBytes);
  const uint32_t zero = 0;
  sampleCount.upload(&zero, 4);
  recordCount.upload(&zero, 4);
  std::vector<gpu::LrsmConeResult> none(LRSM_MAX_CONES + 1);
  std::memset(none.data(), 0, none.size() * sizeof(none[0]));
  cones.upload(none.data(), none.size() * sizeof(none[0]));

  Texture& rad = ctx.board.texture("lrsm-radiance");
  const int w = rad.desc().size.y;
  const auto diffuseSet = diffuseCones();
  const int probeX = std::min(int(ctx.params.getFloat("probe.x") * tw), tw - 1);
  const int probeY = std::min(int((1.0f - ctx.params.getFloat("probe.y")) * th), th - 1);

  // The gather's choices are program defines (gather.comp.glsl: llvmpipe runs both sides of a
  // branch on a uniform).
  const auto flag = [](const char* name, bool on) { return std::string("#define ") + name + (on ? " 1\n" : " 0\n"); };
  const std::string choices =
      std::string("#define LRSM_ESTIMATOR ") +
      (ctx.params.getChoice("lrsm.estimator") == "paper" ? "LRSM_ESTIMATOR_PAPER\n" : "LRSM_ESTIMATOR_COVERAGE\n") +
      flag("LRSM_WINDOW_LAYERS", ctx.params.getChoice("lrsm.layer-select") == "window") +
      flag("LRSM_SMOOTH_FALLOFF", ctx.params.getChoice("lrsm.falloff") == "smoothstep") +
      flag("LRSM_LIT_OCCLUSION", ctx.params.getBool("lrsm.lit-occlusion")) +
      flag("LRSM_HORIZON", ctx.params.getBool("cone.horizon")) +
      flag("LRSM_VISIBILITY", ctx.params.getBool("lrsm.visibility")) +
      flag("LRSM_TWO_LOBES", ctx.params.getBool("lrsm.two-lobes"));
  // The gatherer, every pixel with nothing recorded, and the recorder, which gathers the probed
  // pixel again and writes its records (probe_recorder.h).
  const auto [gatherer, recorder] =
      tracerAndRecorder(ctx.shaders, {"lrsm/gather.comp.glsl"}, choices + lightKindDefines(ctx.scene));
  for (GLuint program : {gatherer, recorder}) {
    space.setUniforms(program);
    setLayoutUniforms(program, L);
    setUniform(program, "u_layerWidth", w);
    setUniform(program, "u_lrsmLevels", rad.levels());
    setUniform(program, "u_voxelLevels", ctx.board.texture("occlusion").levels());
    setUniform(program, "u_minVariance", ctx.params.getFloat("lrsm.min-variance"));
    setUniform(program, "u_stepScale", ctx.params.getFloat("cone.step"));
    setUniform(program, "u_footprintBias", ctx.params.getFloat("lrsm.footprint-bias"));
    setUniform(program, "u_startVoxels", ctx.params.getFloat("cone.start"));
    setUniform(program, "u_interleave", ctx.params.getBool("cone.interleave") ? 1 : 0);
    setUniform(program, "u_lodBias", ctx.params.getFloat("cone.lod-bias"));
    setUniform(program, "u_shadowLodBias", ctx.params.getFloat("cone.shadow-lod-bias"));
    setUniform(program, "u_maxSteps", ctx.params.getInt("cone.max-steps"));
    setUniform(program, "u_diffuseTanHalf", std::tan(0.5f * kDiffuseAperture));
    setUniform(program, "u_specularTanHalf", std::tan(0.5f * kSpecularAperture));
    setUniform(program, "u_shadowTanHalf", std::tan(0.5f * ctx.params.getFloat("cone.shadow-aperture") * kDegrees));
    setUniform(program, "u_traceScale", s);
    setUniform(program, "u_traceSpecular", ctx.params.getBool("cone.specular") ? 1 : 0);
    setUniform(program, "u_traceShadow", traceShadow ? 1 : 0);
    setUniform(program, "u_cameraPos", ctx.view.position);
    for (int k = 0; k < kDiffuseCones; ++k) {
      const std::string name = "u_diffuseCones[" + std::to_string(k) + "]";
      setUniform(program, name.c_str(), glm::vec4(diffuseSet[k].direction, diffuseSet[k].weight));
  }
  glProgramUniform2i(program, glGetUniformLocation(program, "u_probePixel"), probeX, probeY);
  setSkyUniforms(program, ctx.params, ctx.scene);
  }
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  glBindTextureUnit(0, ctx.board.texture("occlusion").id());
  glBindTextureUnit(1, rad.id());
  glBindTextureUnit(2, ctx.board.texture("lrsm-normal").id());
  glBindTextureUnit(3, ctx.board.texture("lrsm-depth").id());
  glBindTextureUnit(4, ctx.board.texture("position").id());
  glBindTextureUnit(5, ctx.board.texture("normal").id());
  glBindTextureUnit(6, ctx.board.texture("albedo").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_CONE_SAMPLES, samples.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_CONE_SAMPLE_COUNT, sampleCount.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LRSM_BINDING_GATHER, records.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LRSM_BINDING_GATHER_COUNT, recordCount.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LRSM_BINDING_CONE_RESULTS, cones.id());
  glBindImageTexture(0, diffuse.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glBindImageTexture(1, specular.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(2, shadow ? shadow->id() : 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R16F);  // none: never written
  glUseProgram(gatherer);
  dispatchCompute({tw, th, 1}, {8, 8, 1});
  dispatchRecorder(recorder, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);

  uint32_t attempted = 0, conesSampled = 0;
  std::memcpy(&attempted, recordCount.download(4).data(), 4);
  std::memcpy(&conesSampled, sampleCount.download(4).data(), 4);
  const uint32_t cap = LRSM_MAX_GATHER_RECORDS;
  if (attempted > cap) {
    // Keep the count at the capacity so readers see only stored records; report what was dropped.
    recordCount.upload(&cap, 4);
  }
  const uint32_t sampleCap = VOXLAB_MAX_CONES * VOXLAB_MAX_SAMPLES_PER_CONE;
  if (conesSampled > sampleCap) sampleCount.upload(&sampleCap, 4);
  ctx.stats["probe_gather_records"] = std::min(attempted, cap);
  ctx.stats["probe_gather_records_dropped"] = attempted > cap ? attempted - cap : 0;
  ctx.stats["probe_cone_samples"] = std::min(conesSampled, sampleCap);
  ctx.stats["probe_cone_samples_dropped"] = conesSampled > sampleCap ? conesSampled - sampleCap : 0;
  ctx.stats["traced_pixels"] = double(tw) * th;
  ctx.stats["probe_x"] = probeX;
  ctx.stats["probe_y_from_top"] = th - 1 - probeY;
  const PaperMemory m = paperMemory(res, ctx.params.getInt("rsm.resolution"), L.count());
  ctx.stats["paper_layout_occlusion_mb"] = m.occlusion / 1e6;
  ctx.stats["paper_layout_rsm_mb"] = m.rsm / 1e6;
  ctx.stats["paper_layout_lrsm_mb"] = m.lrsm / 1e6;
  ctx.stats["paper_layout_total_mb"] = m.total() / 1e6;
}

// The shared a-trous filter over the gathered light: cone.interleave gives each pixel of a 4 x 4
// tile its own step phase, and the filter's kernel averages 16 of them per pixel (filter.samples
// 1024 at 16 per pixel: 2 passes, holes 1 and 2, 13 x 13 traced pixels) on the receiver's surface.
AtrousFilterConfig filterConfig() {
  AtrousFilterConfig c;
  c.source = "indirect-diffuse";
  c.output = "indirect-filtered";
  c.referenceMode = "indirect-1";
  c.raysPerPixel = 16;
  c.traced = kTracedCones;
  c.sharedParams = {voxelResolutionParam()};
  // One voxel: the G-buffer's neighbours on one flat face lie on its plane to well within it.
  c.depthScale = [](const ParamSet& p, const Scene& scene) {
    return VoxelSpace::fromScene(scene, p.getInt("voxel.resolution")).voxelSize;
  };
  return c;
}

// --- Composite ----------------------------------------------------------------------------------------

CompositeTerms compositeTerms() {
  CompositeTerms t;
  t.summary = "Direct light (shadowed by the shadow map, or by the shadow cone as a variant) + emission + the "
              "gathered indirect light, then tonemap.";
  t.combinedHelp = "direct + one-bounce indirect diffuse, linear";
  t.params = {voxelResolutionParam(), kTracedCones.resolutionParam(),
              ParamDesc::choice("composite.shadow", {"shadow-map", "cone"}, 0,
                                "direct shadows from the shadow map (sees every occluder the reference does) or from "
                                "the shadow cone through the occlusion voxels (soft, but a hollow slab's mips let up to "
                                "half of the light through: the ceiling of skylight-room lit 16.8x)"),
              compositeExposureParam(),
              ParamDesc::real("composite.indirect", 1.0, 0.0, 4.0, "weight of the indirect term (1 = physical)")};
  t.indirect = {{"indirect-filtered", "composite.indirect"}};
  t.visibility = CompositeVisibility{"composite.shadow", "cone", "soft-shadow"};
  t.traced = kTracedCones;
  t.planeDistance = [](const ParamSet& p, const Scene& scene) {
    return 2.0f * VoxelSpace::fromScene(scene, p.getInt("voxel.resolution")).voxelSize;
  };
  t.probeDefaultY = kProbeDefaultY;  // the cone-gather stage's probe
  return t;
}

}  // namespace voxlab::lrsm
