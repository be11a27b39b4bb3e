// The volumetric stages: density grid, phase function, ray march, blur, upsampling, compose.
#include "techniques/volumetric/stages.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "core/error.h"
#include "gpu/shader_library.h"
#include "graph/scene_inputs.h"
#include "scene/gpu_scene.h"
#include "techniques/common/light_stage.h"
#include "techniques/common/voxel_space.h"
#include "volumetric/volumetric_shared.h"

namespace voxlab::volumetric {

namespace {

constexpr int kPlotWidth = 256, kPlotHeight = 160;
// Relative surface-distance difference at which blur and upsampling weights fall to 1/e: 2 % of
// the distance separates a block from the wall behind it but not neighbouring floor pixels.
constexpr float kDepthSigma = 0.02f;

ParamDesc densityResolutionParam() {
  return ParamDesc::integer("density.resolution", 32, 8, 256,
                            "voxels along each axis of the density grid (a cube around the scene, as the voxel grid)",
                            "voxels")
      .pow2();
}

ParamDesc anisotropyParam() {
  return ParamDesc::real("medium.anisotropy", 0.3, -0.99, 0.99,
                         "Henyey-Greenstein g: mean cosine of the scattering angle (0 isotropic, > 0 forward); "
                         "|g| < 1, p is singular at g = 1");
}

ParamDesc marchResolutionParam() {
  return ParamDesc::choice("march.resolution", {"half", "full"}, 0,
                           "march one ray per 2x2 block of pixels (half, as the thesis) or per pixel (full)");
}

int marchScale(const ParamSet& params) { return params.getChoice("march.resolution") == "half" ? 2 : 1; }

TextureDesc imageDesc(glm::ivec2 size, GLenum format) {
  TextureDesc d;
  d.format = format;
  d.size = {size.x, size.y, 1};
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}

glm::ivec2 fullSize(const ViewState& view) { return {view.width, view.height}; }

glm::ivec2 marchedSize(const ViewState& view, const ParamSet& params) {
  int s = marchScale(params);
  return {(view.width + s - 1) / s, (view.height + s - 1) / s};
}

// The density grid's space: the voxel volume of vct-grid (a cube around the scene) at the
// density grid's resolution.
VoxelSpace densitySpace(const StageContext& ctx) {
  return VoxelSpace::fromScene(ctx.scene, ctx.params.getInt("density.resolution"));
}

// The density grids (declared and allocated from the same descs).
TextureDesc countGridDesc(int res) {
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = GL_R32UI;
  d.size = {res, res, res};
  d.minFilter = d.magFilter = GL_NEAREST;
  d.wrap = GL_CLAMP_TO_BORDER;
  return d;
}

TextureDesc scatteringGridDesc(int res) {
  TextureDesc d = countGridDesc(res);
  d.format = GL_R32F;
  d.minFilter = d.magFilter = GL_LINEAR;  // border 0: nothing scatters outside
  return d;
}

// The particle list is sized from the count (one vec4 each; the parameter's range caps it at 64 MiB).
size_t particleBytes(const ParamSet& params) {
  return std::max<size_t>(size_t(params.getInt("particles.count")) * 16, 16);
}

constexpr size_t kParticleStatsBytes = 16;
constexpr size_t kPhaseSamplesBytes = sizeof(gpu::PhaseSample) * VOXLAB_PHASE_SAMPLES;
constexpr size_t kRaySamplesBytes = sizeof(gpu::RaySample) * VOXLAB_MAX_MARCH_STEPS;
constexpr size_t kRaySampleCountBytes = 4;

TextureDesc plotDesc() { return imageDesc({kPlotWidth, kPlotHeight}, GL_RGBA8); }

void bindLight(const StageContext& ctx) {
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
}

}  // namespace

float mediumLength(const Scene& scene) {
  const glm::vec3 e = scene.bounds.extent();
  return std::max({e.x, e.y, e.z, 1e-4f});
}

// --- Density grid --------------------------------------------------------------------------------

void DensityStage::declare(StageBuilder& b) const {
  b.param(densityResolutionParam());
  b.param(ParamDesc::integer("particles.count", 60000, 0, 4000000,
                             "smoke particles (10000 in the thesis); 0 leaves only the uniform haze", "particles"));
  b.param(ParamDesc::real("particles.time", 4.0, 0.0, 1000.0, "time of the particle simulation", "s"));
  b.param(ParamDesc::real("particles.source-x", 0.72, 0.0, 1.0,
                          "where the plume rises: fraction of the scene's bounds along x (0 = min, 1 = max)"));
  b.param(ParamDesc::real("particles.source-z", 0.22, 0.0, 1.0,
                          "where the plume rises: fraction of the scene's bounds along z (0 = min, 1 = max)"));
  b.param(ParamDesc::real("medium.particle-optical-depth", kParticleOpticalDepth, 0.0, 100.0,
                          "optical depth one particle per voxel gives over the scene's largest extent L: each "
                          "particle in a voxel adds sigma_s = value / L there"));
  b.write("particles.stats");
  b.output("particle-count", OutputKind::Volume3D, Semantic::Scalar,
           "particles per voxel (R32UI, integer atomics: the same on every run)")
      .tier = CaptureTier::Exact;
  b.output("scattering", OutputKind::Volume3D, Semantic::Scalar,
           "the particles' scattering coefficient sigma_s = particle-optical-depth / L * count (1/m; L the scene's largest extent)");
  BufferLayout particles;
  particles.stride = 16;
  particles.fields = {{"voxel", FieldType::Vec3, 0, FieldRole::Position}, {"age", FieldType::F32, 12, FieldRole::Other}};
  particles.countResource = "particles.stats";
  particles.countOffset = 8;
  b.output("particles", OutputKind::Buffer, Semantic::Points,
           "every particle: position in density-grid voxels, age as a fraction of its lifetime")
      .layout = particles;
  b.alongside({"particles"});
  b.texture("particle-count", [](const ParamSet& p, const ViewState&) {
    return countGridDesc(p.getInt("density.resolution"));
  });
  b.texture("scattering", [](const ParamSet& p, const ViewState&) {
    return scatteringGridDesc(p.getInt("density.resolution"));
  });
  b.buffer("particles", [](const ParamSet& p, const ViewState&) { return particleBytes(p); });
  b.buffer("particles.stats", [](const ParamSet&, const ViewState&) { return kParticleStatsBytes; });
}

void DensityStage::execute(StageContext& ctx) {
  const VoxelSpace space = densitySpace(ctx);
  const int res = space.resolution;
  const uint32_t count = uint32_t(ctx.params.getInt("particles.count"));
  // The grids carry their own placement (a technique this is appended to may define another voxel space).
  if (definesVoxelSpace_) ctx.board.setVoxelSpace(space.box());
  ctx.board.place("particle-count", space.box());
  ctx.board.place("scattering", space.box());

  Texture& counts = ctx.board.ensureTexture("particle-count", countGridDesc(res));
  Texture& scattering = ctx.board.ensureTexture("scattering", scatteringGridDesc(res));
  Buffer& particles = ctx.board.ensureBuffer("particles", particleBytes(ctx.params));
  Buffer& stats = ctx.board.ensureBuffer("particles.stats", kParticleStatsBytes);
  const uint32_t initial[4] = {0, 0, count, 0};
  stats.upload(initial, sizeof(initial));
  const uint32_t zero = 0;
  glClearTexImage(counts.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);

  // The plume rises from a disc on the scene's floor towards its ceiling (on the Cornell box: in
  // front of the tall block, beside the short one, where the camera sees it against the block).
  const Bounds& bounds = ctx.scene.bounds;
  glm::vec3 extent = bounds.extent();
  float width = std::min(extent.x, extent.z);
  glm::vec3 source(bounds.min.x + ctx.params.getFloat("particles.source-x") * extent.x, bounds.min.y + 0.01f * extent.y,
                   bounds.min.z + ctx.params.getFloat("particles.source-z") * extent.z);
  GLuint program = ctx.shaders.program({"volumetric/particles.comp.glsl"});
  setUniform(program, "u_count", count);
  setUniform(program, "u_time", ctx.params.getFloat("particles.time"));
  setUniform(program, "u_lifetime", 6.0f);
  setUniform(program, "u_source", source);
  setUniform(program, "u_sourceRadius", 0.05f * width);
  setUniform(program, "u_riseHeight", 0.85f * extent.y);
  setUniform(program, "u_spread", 0.25f * width);
  setUniform(program, "u_volumeOrigin", space.origin);
  setUniform(program, "u_invVoxelSize", 1.0f / space.voxelSize);
  setUniform(program, "u_resolution", res);
  glUseProgram(program);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_PARTICLES, particles.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_PARTICLE_STATS, stats.id());
  glBindImageTexture(0, counts.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
  if (count > 0) dispatchCompute({int(count), 1, 1}, {64, 1, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);

  GLuint toScattering = ctx.shaders.program({"volumetric/scattering.comp.glsl"});
  const float perParticle = ctx.params.getFloat("medium.particle-optical-depth") / mediumLength(ctx.scene);
  setUniform(toScattering, "u_scatteringPerParticle", perParticle);
  setUniform(toScattering, "u_resolution", res);
  glUseProgram(toScattering);
  glBindTextureUnit(0, counts.id());
  glBindImageTexture(0, scattering.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
  dispatchCompute({res, res, res}, {4, 4, 4});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);

  uint32_t result[4];
  std::memcpy(result, stats.download(16).data(), 16);
  ctx.stats["particles"] = count;
  ctx.stats["deposited"] = result[0];
  ctx.stats["dropped_outside_grid"] = result[1];
  ctx.stats["grid_bytes"] = double(counts.byteSize() + scattering.byteSize());
  ctx.stats["medium_length_m"] = mediumLength(ctx.scene);
  ctx.stats["scattering_per_particle_per_m"] = perParticle;
}

// --- Phase function ------------------------------------------------------------------------------

void PhaseStage::declare(StageBuilder& b) const {
  b.param(anisotropyParam());
  b.output("phase-plot", OutputKind::Image2D, Semantic::Color,
           "log10 p(mu) over mu in [-1, 1]: Henyey-Greenstein white, the thesis' (1-g)^2 version red, isotropic grey; "
           "lines at powers of ten 1e-3..1e2 and mu = 0");
  BufferLayout samples;
  samples.stride = sizeof(gpu::PhaseSample);
  samples.fields = {{"mu", FieldType::F32, 0, FieldRole::Other},
                    {"henyey-greenstein", FieldType::F32, 4, FieldRole::Other},
                    {"thesis", FieldType::F32, 8, FieldRole::Other},
                    {"isotropic", FieldType::F32, 12, FieldRole::Other}};
  b.output("phase-samples", OutputKind::Buffer, Semantic::Scalar,
           "p(mu) at 2049 equally spaced mu from -1 to 1, from the GLSL the march uses (1/sr)")
      .layout = samples;
  b.texture("phase-plot", [](const ParamSet&, const ViewState&) { return plotDesc(); });
  b.buffer("phase-samples", [](const ParamSet&, const ViewState&) { return kPhaseSamplesBytes; });
}

void PhaseStage::execute(StageContext& ctx) {
  const float g = ctx.params.getFloat("medium.anisotropy");
  Texture& plot = ctx.board.ensureTexture("phase-plot", plotDesc());
  Buffer& samples = ctx.board.ensureBuffer("phase-samples", kPhaseSamplesBytes);
  GLuint program = ctx.shaders.program({"volumetric/phase_plot.comp.glsl"});
  setUniform(program, "u_g", g);
  glProgramUniform2i(program, glGetUniformLocation(program, "u_plotSize"), kPlotWidth, kPlotHeight);
  glUseProgram(program);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_PHASE_SAMPLES, samples.id());
  glBindImageTexture(0, plot.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA8);
  dispatchCompute({kPlotWidth, kPlotHeight, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);

  // The integrals over the sphere, 2 pi * int p dmu (Simpson's rule on the GPU's samples), and
  // the mean cosine: what the student reads next to the plot.
  std::vector<gpu::PhaseSample> s(VOXLAB_PHASE_SAMPLES);
  std::memcpy(s.data(), samples.download(s.size() * sizeof(gpu::PhaseSample)).data(), s.size() * sizeof(gpu::PhaseSample));
  double hg = 0, thesis = 0, meanCos = 0;
  const double h = 2.0 / (VOXLAB_PHASE_SAMPLES - 1);
  for (int i = 0; i < VOXLAB_PHASE_SAMPLES; ++i) {
    double w = (i == 0 || i == VOXLAB_PHASE_SAMPLES - 1) ? 1 : (i % 2 ? 4 : 2);
    hg += w * s[i].value.y;
    thesis += w * s[i].value.z;
    meanCos += w * s[i].value.x * s[i].value.y;
  }
  const double scale = 2.0 * M_PI * h / 3.0;
  ctx.stats["g"] = g;
  ctx.stats["integral_henyey_greenstein"] = hg * scale;
  ctx.stats["integral_thesis"] = thesis * scale;
  ctx.stats["integral_thesis_expected"] = (1.0 - g) / (1.0 + g);
  ctx.stats["mean_cosine_henyey_greenstein"] = meanCos * scale;
}

// --- Ray march -----------------------------------------------------------------------------------

void MarchStage::declare(StageBuilder& b) const {
  b.param(densityResolutionParam());
  b.param(anisotropyParam());
  b.param(marchResolutionParam());
  b.param(ParamDesc::integer("march.steps", 32, 1, VOXLAB_MAX_MARCH_STEPS,
                             "samples per ray (one iteration each): N in dt = length / N", "samples"));
  b.param(ParamDesc::choice("march.dither", {"bayer", "off", "thesis-0.22"}, 0,
                            "start offset of each ray in steps: the 4x4 Bayer pattern (k/16), none (banding), or "
                            "the thesis' matrix with 0.22 where 4/16 belongs"));
  b.param(ParamDesc::choice("march.phase", {"henyey-greenstein", "thesis"}, 0,
                            "phase function: normalised Henyey-Greenstein, or the thesis' (1-g)^2 numerator "
                            "(integrates to (1-g)/(1+g))"));
  b.param(ParamDesc::choice("march.clip", {"grid", "spot-cone"}, 0,
                            "where the samples go: the whole ray inside the density grid, or only its part inside a "
                            "spot light's cone (Vos 2014; the rest only attenuates, integrated separately)"));
  b.param(ParamDesc::real("medium.haze-optical-depth", kHazeOpticalDepth, 0.0, 100.0,
                          "optical depth of a uniform haze filling the density grid over the scene's largest extent "
                          "L: sigma_s = value / L, added to the particles'"));
  b.param(ParamDesc::real("medium.extinction-ratio", 1.0, 0.0, 100.0,
                          "sigma_t = ratio * sigma_s: 1 = nothing absorbed, > 1 absorbing, 0 = no extinction "
                          "(the thesis; unphysical)"));
  b.param(ParamDesc::real("probe.x", 0.5, 0.0, 1.0, "horizontal position of the probed pixel (0 left, 1 right)"));
  b.param(ParamDesc::real("probe.y", 0.5, 0.0, 1.0, "vertical position of the probed pixel (0 top, 1 bottom)"));
  b.probe(ProbeDesc::screen("probe.x", "probe.y"));  // a click on a camera image picks the recorded ray
  b.readView();
  b.read("position");
  b.read("scattering");
  b.read("particle-count");
  b.read("shadow-map");
  b.read("light");
  b.read(kSceneLightsInput);  // the light's type: programs are built for it (lightKindDefines)
  b.write("march.optical-depth");
  b.write("ray-samples.count");
  b.output("inscatter", OutputKind::Image2D, Semantic::RadianceHDR,
           "in-scattered radiance towards the camera after the samples taken so far, W/(m^2 sr) (at march.resolution)");
  b.output("transmittance", OutputKind::Image2D, Semantic::Fraction,
           "transmittance from the camera to the march front; after the last sample, to the surface");
  b.output("ray-length", OutputKind::Image2D, Semantic::Depth,
           "length of the marched segment: the camera ray inside the density grid and before the surface (m)").alongside = true;
  BufferLayout rec;
  rec.stride = sizeof(gpu::RaySample);
  rec.fields = {{"voxel+t", FieldType::Vec4, 0, FieldRole::Position},
                {"world+offset", FieldType::Vec4, 16, FieldRole::Other},
                {"lit,sigma_s,sigma_t,count", FieldType::Vec4, 32, FieldRole::Other},
                {"mu,phase,E,T", FieldType::Vec4, 48, FieldRole::Other},
                {"contribution+sum", FieldType::Vec4, 64, FieldRole::Other}};
  rec.countResource = "ray-samples.count";
  OutputDesc& samples = b.output(
      "ray-samples", OutputKind::Buffer, kRaySamples,
      "every sample of the probed pixel's ray (probe.x/probe.y pick it): voxel position and distance t, world "
      "position and start offset, lit/sigma_s/sigma_t/particle count, mu/p(mu)/E/T, contribution and running sum");
  samples.layout = rec;
  samples.alongside = true;  // a probe record of one pixel
  samples.tier = CaptureTier::Tolerance;  // float fields, compared with the tolerances
  samples.probeRecord = true;              // the Probe tab shows it (src/techniques/volumetric/views/volumetric_ray.cpp)
  b.output("ray-plot", OutputKind::Image2D, Semantic::Color,
           "the probed ray, one column band per sample: contribution over the largest (yellow bars; red tick: "
           "shadowed), transmittance T (blue) and running sum over its final value (green), 0..1").alongside = true;
  for (const char* name : {"transmittance", "march.optical-depth", "ray-length"})
    b.texture(name, [](const ParamSet& p, const ViewState& v) { return imageDesc(marchedSize(v, p), GL_R32F); });
  b.texture("inscatter", [](const ParamSet& p, const ViewState& v) { return imageDesc(marchedSize(v, p), GL_RGBA32F); });
  b.texture("ray-plot", [](const ParamSet&, const ViewState&) { return plotDesc(); });
  b.buffer("ray-samples", [](const ParamSet&, const ViewState&) { return kRaySamplesBytes; });
  b.buffer("ray-samples.count", [](const ParamSet&, const ViewState&) { return kRaySampleCountBytes; });
}

int MarchStage::iterations(const ParamSet& params) const { return params.getInt("march.steps"); }

void MarchStage::execute(StageContext& ctx) {
  const VoxelSpace space = densitySpace(ctx);
  const glm::ivec2 low = marchedSize(ctx.view, ctx.params);
  Texture& inscatter = ctx.board.ensureTexture("inscatter", imageDesc(low, GL_RGBA32F));
  Texture& depth = ctx.board.ensureTexture("march.optical-depth", imageDesc(low, GL_R32F));
  Texture& transmittance = ctx.board.ensureTexture("transmittance", imageDesc(low, GL_R32F));
  Texture& rayLength = ctx.board.ensureTexture("ray-length", imageDesc(low, GL_R32F));
  Buffer& records = ctx.board.ensureBuffer("ray-samples", kRaySamplesBytes);
  Buffer& recordCount = ctx.board.ensureBuffer("ray-samples.count", kRaySampleCountBytes);
  if (ctx.iteration == 0) {
    const uint32_t zero = 0;
    recordCount.upload(&zero, 4);
  }
  // probe.y counts from the top of the image; GL rows count from the bottom.
  const int probeX = std::min(int(ctx.params.getFloat("probe.x") * low.x), low.x - 1);
  const int probeY = std::min(int((1.0f - ctx.params.getFloat("probe.y")) * low.y), low.y - 1);

  GLuint program = ctx.shaders.program({"volumetric/march.comp.glsl"}, lightKindDefines(ctx.scene));
  space.setUniforms(program);
  setUniform(program, "u_sample", ctx.iteration);
  setUniform(program, "u_steps", ctx.params.getInt("march.steps"));
  setUniform(program, "u_scale", marchScale(ctx.params));
  setUniform(program, "u_invViewProj", glm::inverse(ctx.view.viewProjection()));
  setUniform(program, "u_cameraPos", ctx.view.position);
  const std::string& dither = ctx.params.getChoice("march.dither");
  setUniform(program, "u_dither", dither == "bayer" ? 0 : dither == "off" ? 1 : 2);
  setUniform(program, "u_phaseModel", ctx.params.getChoice("march.phase") == "thesis" ? 1 : 0);
  setUniform(program, "u_g", ctx.params.getFloat("medium.anisotropy"));
  const float haze = ctx.params.getFloat("medium.haze-optical-depth") / mediumLength(ctx.scene);
  setUniform(program, "u_hazeScattering", haze);
  ctx.stats["haze_scattering_per_m"] = haze;
  setUniform(program, "u_extinctionRatio", ctx.params.getFloat("medium.extinction-ratio"));
  setUniform(program, "u_clipToCone", ctx.params.getChoice("march.clip") == "spot-cone" ? 1 : 0);
  glProgramUniform2i(program, glGetUniformLocation(program, "u_probePixel"), probeX, probeY);
  glUseProgram(program);
  glBindTextureUnit(1, ctx.board.texture("position").id());
  glBindTextureUnit(2, ctx.board.texture("scattering").id());
  glBindTextureUnit(3, ctx.board.texture("shadow-map").id());
  glBindTextureUnit(4, ctx.board.texture("particle-count").id());
  bindLight(ctx);
  glBindImageTexture(0, inscatter.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  glBindImageTexture(1, depth.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32F);
  glBindImageTexture(2, transmittance.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
  glBindImageTexture(3, rayLength.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_RAY_RECORDS, records.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_RAY_RECORD_COUNT, recordCount.id());
  dispatchCompute({low.x, low.y, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  // The plot of the probed ray, redrawn from the records taken so far.
  Texture& plot = ctx.board.ensureTexture("ray-plot", plotDesc());
  GLuint plotProgram = ctx.shaders.program({"volumetric/ray_plot.comp.glsl"});
  setUniform(plotProgram, "u_steps", ctx.params.getInt("march.steps"));
  glUseProgram(plotProgram);
  glBindImageTexture(0, plot.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA8);
  dispatchCompute({kPlotWidth, kPlotHeight, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  ctx.stats["marched_pixels"] = double(low.x) * low.y;
  ctx.stats["steps"] = ctx.params.getInt("march.steps");
  ctx.stats["probe_x"] = probeX;
  ctx.stats["probe_y_from_top"] = low.y - 1 - probeY;
}

// --- Blur ----------------------------------------------------------------------------------------

void BlurStage::declare(StageBuilder& b) const {
  b.param(marchResolutionParam());
  b.param(ParamDesc::integer("blur.radius", 2, 0, 8,
                             "kernel half-width in marched pixels (0 = off); even radii weigh the 4 dither phases "
                             "equally along each axis",
                             "px"));
  b.readView();
  b.read("position");
  b.read("inscatter");
  b.read("transmittance");
  b.write("blur.horizontal");
  b.output("inscatter-blurred", OutputKind::Image2D, Semantic::RadianceHDR,
           "the in-scattered radiance after the bilateral blur, W/(m^2 sr) (alpha: the blurred transmittance)");
  b.output("transmittance-blurred", OutputKind::Image2D, Semantic::Fraction, "the transmittance after the bilateral blur").alongside = true;
  for (const char* name : {"blur.horizontal", "inscatter-blurred"})
    b.texture(name, [](const ParamSet& p, const ViewState& v) { return imageDesc(marchedSize(v, p), GL_RGBA32F); });
  b.texture("transmittance-blurred",
            [](const ParamSet& p, const ViewState& v) { return imageDesc(marchedSize(v, p), GL_R32F); });
}

void BlurStage::execute(StageContext& ctx) {
  const glm::ivec2 low = marchedSize(ctx.view, ctx.params);
  Texture& horizontal = ctx.board.ensureTexture("blur.horizontal", imageDesc(low, GL_RGBA32F));
  Texture& blurred = ctx.board.ensureTexture("inscatter-blurred", imageDesc(low, GL_RGBA32F));
  Texture& blurredT = ctx.board.ensureTexture("transmittance-blurred", imageDesc(low, GL_R32F));
  Texture scratchT("blur.scratch-transmittance", imageDesc(low, GL_R32F));
  GLuint program = ctx.shaders.program({"volumetric/blur.comp.glsl"});
  setUniform(program, "u_radius", ctx.params.getInt("blur.radius"));
  setUniform(program, "u_scale", marchScale(ctx.params));
  setUniform(program, "u_cameraPos", ctx.view.position);
  setUniform(program, "u_depthSigma", kDepthSigma);
  glUseProgram(program);
  glBindTextureUnit(1, ctx.board.texture("position").id());
  // Pass 1 along x: inscatter + transmittance -> horizontal (rgb, a).
  glProgramUniform2i(program, glGetUniformLocation(program, "u_axis"), 1, 0);
  setUniform(program, "u_packed", 0);
  glBindTextureUnit(2, ctx.board.texture("inscatter").id());
  glBindTextureUnit(3, ctx.board.texture("transmittance").id());
  glBindImageTexture(0, horizontal.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glBindImageTexture(1, scratchT.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
  dispatchCompute({low.x, low.y, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  // Pass 2 along y.
  glProgramUniform2i(program, glGetUniformLocation(program, "u_axis"), 0, 1);
  setUniform(program, "u_packed", 1);
  glBindTextureUnit(2, horizontal.id());
  glBindImageTexture(0, blurred.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glBindImageTexture(1, blurredT.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
  dispatchCompute({low.x, low.y, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
}

// --- Upsampling ----------------------------------------------------------------------------------

void UpsampleStage::declare(StageBuilder& b) const {
  b.param(marchResolutionParam());
  b.readView();
  b.read("position");
  b.read("inscatter-blurred");
  b.output("inscatter-full", OutputKind::Image2D, Semantic::RadianceHDR,
           "in-scattered radiance at the G-buffer's resolution, W/(m^2 sr)");
  b.output("transmittance-full", OutputKind::Image2D, Semantic::Fraction,
           "transmittance from the camera to the surface at the G-buffer's resolution");
  b.texture("inscatter-full", [](const ParamSet&, const ViewState& v) { return imageDesc(fullSize(v), GL_RGBA32F); });
  b.texture("transmittance-full", [](const ParamSet&, const ViewState& v) { return imageDesc(fullSize(v), GL_R32F); });
}

void UpsampleStage::execute(StageContext& ctx) {
  Texture& radiance = ctx.board.ensureTexture("inscatter-full", imageDesc(fullSize(ctx.view), GL_RGBA32F));
  Texture& transmittance = ctx.board.ensureTexture("transmittance-full", imageDesc(fullSize(ctx.view), GL_R32F));
  GLuint program = ctx.shaders.program({"volumetric/upsample.comp.glsl"});
  setUniform(program, "u_scale", marchScale(ctx.params));
  setUniform(program, "u_cameraPos", ctx.view.position);
  setUniform(program, "u_depthSigma", kDepthSigma);
  glUseProgram(program);
  glBindTextureUnit(1, ctx.board.texture("position").id());
  glBindTextureUnit(2, ctx.board.texture("inscatter-blurred").id());
  glBindImageTexture(0, radiance.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glBindImageTexture(1, transmittance.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
  dispatchCompute({ctx.view.width, ctx.view.height, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
}

// --- Compose -------------------------------------------------------------------------------------

void ComposeStage::declare(StageBuilder& b) const {
  std::vector<std::string> sources = {"direct", "none"};
  if (!surfaceInput_.empty()) sources.insert(sources.begin(), "input");
  b.param(ParamDesc::choice("compose.surface", sources, 0,
                            surfaceInput_.empty()
                                ? "surface term under the medium: direct light (Lambert, shadow map) + emission, or none"
                                : "surface term under the medium: the input image '" + surfaceInput_ +
                                      "', direct light + emission, or none"));
  b.param(ParamDesc::real("compose.exposure", 1.0, 0.01, 64.0, "scale applied before tonemapping"));
  b.read("position");
  b.read("normal");
  b.read("albedo");
  b.read("emission");
  b.read("shadow-map");
  b.read("light");
  b.read(kSceneLightsInput);  // the light's type: programs are built for it (lightKindDefines)
  b.read("inscatter-full");
  b.read("transmittance-full");
  if (!surfaceInput_.empty()) b.read(surfaceInput_);
  OutputDesc& surface = b.output("surface", OutputKind::Image2D, Semantic::RadianceHDR,
                                 "surface radiance before the medium, W/(m^2 sr)");
  surface.alongside = true;
  surface.resource = "volumetric-surface";
  // Alone, the surface term is direct light + emission (compose.surface=direct): the path tracer's
  // 'direct' mode (docs/fidelity.md). Over another technique's image it is that image's, untagged.
  if (surfaceInput_.empty()) surface.referenceMode = "direct";
  b.output("combined", OutputKind::Image2D, Semantic::RadianceHDR,
           "surface * transmittance + in-scattered radiance, W/(m^2 sr)")
      .resource = "volumetric-combined";
  b.alongside({"combined"});
  b.output("final", OutputKind::Image2D, Semantic::Color, "the tonemapped image: x / (1 + x) of exposure * combined")
      .resource = "volumetric-final";
  for (const char* name : {"volumetric-surface", "volumetric-combined"})
    b.texture(name, [](const ParamSet&, const ViewState& v) { return imageDesc(fullSize(v), GL_RGBA32F); });
  b.texture("volumetric-final", [](const ParamSet&, const ViewState& v) { return imageDesc(fullSize(v), GL_RGBA8); });
}

void ComposeStage::execute(StageContext& ctx) {
  const glm::ivec2 size = fullSize(ctx.view);
  Texture& surface = ctx.board.ensureTexture("volumetric-surface", imageDesc(size, GL_RGBA32F));
  Texture& combined = ctx.board.ensureTexture("volumetric-combined", imageDesc(size, GL_RGBA32F));
  Texture& final = ctx.board.ensureTexture("volumetric-final", imageDesc(size, GL_RGBA8));
  const std::string& source = ctx.params.getChoice("compose.surface");
  GLuint program = ctx.shaders.program({"volumetric/compose.comp.glsl"}, lightKindDefines(ctx.scene));
  setUniform(program, "u_surfaceSource", source == "direct" ? 0 : source == "none" ? 1 : 2);
  setUniform(program, "u_skyRadiance", glm::vec3(ctx.scene.skyRadiance));
  setUniform(program, "u_exposure", ctx.params.getFloat("compose.exposure"));
  glUseProgram(program);
  const char* inputs[] = {"position", "normal", "albedo", "emission", "shadow-map", "inscatter-full", "transmittance-full"};
  for (int i = 0; i < 7; ++i) glBindTextureUnit(1 + i, ctx.board.texture(inputs[i]).id());
  // Unit 8 needs a texture either way; without an input it is never read.
  glBindTextureUnit(8, ctx.board.texture(surfaceInput_.empty() ? "position" : surfaceInput_).id());
  bindLight(ctx);
  glBindImageTexture(0, surface.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glBindImageTexture(1, combined.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glBindImageTexture(2, final.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA8);
  dispatchCompute({size.x, size.y, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
}

}  // namespace voxlab::volumetric
