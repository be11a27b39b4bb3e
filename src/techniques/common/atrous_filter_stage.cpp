// The shared edge-aware a-trous filter (atrous_filter_stage.h).
#include "techniques/common/atrous_filter_stage.h"

#include <algorithm>
#include <vector>

#include "gpu/shader_library.h"

namespace voxlab {

namespace {
constexpr int kMaxPasses = 6;
constexpr double kB3[5] = {1.0 / 16, 4.0 / 16, 6.0 / 16, 4.0 / 16, 1.0 / 16};
}  // namespace

double atrousEffectivePixels(int passes) {
  // The 1D equivalent kernel: the B3 taps with holes 1, 2, 4, ... convolved; the 2D kernel is its
  // outer product, so its sum of squares is the 1D sum squared.
  std::vector<double> kernel = {1.0};
  for (int p = 0; p < passes; ++p) {
    const int hole = 1 << p;
    std::vector<double> next(kernel.size() + 4 * hole, 0.0);
    for (size_t i = 0; i < kernel.size(); ++i)
      for (int t = 0; t < 5; ++t) next[i + size_t(t * hole)] += kernel[i] * kB3[t];
    kernel = std::move(next);
  }
  double squares = 0.0;
  for (double w : kernel) squares += w * w;
  return 1.0 / (squares * squares);
}

int atrousPassesFor(double samples, int raysPerPixel, int maxPasses) {
  int p = 0;
  while (p < maxPasses && atrousEffectivePixels(p) * raysPerPixel < samples) ++p;
  return p;
}

void AtrousFilterStage::declare(StageBuilder& b) const {
  for (const ParamDesc& p : config_.sharedParams) b.param(p);
  b.param(config_.traced.resolutionParam());
  b.param(ParamDesc::integer("filter.passes", -1, -1, kMaxPasses,
                             "a-trous passes (holes 1, 2, 4, ... traced pixels; 5 x 5 taps each); 0 = no filter; "
                             "-1 = the fewest that average filter.samples rays"));
  b.param(ParamDesc::real("filter.samples", 1024.0, 1.0, 65536.0,
                          "with filter.passes = -1: rays the kernel averages on a flat surface (rays per pixel times "
                          "the kernel's effective pixels: 13 for 1 pass, 66 for 2, 275 for 3, 1110 for 4)",
                          "rays"));
  b.param(ParamDesc::real("filter.normal-sigma", 0.3, 0.01, 2.0,
                          "normal edge-stopping: a tap keeps exp(-|n - n_q|^2 / sigma^2) of its weight"));
  b.read(config_.source);
  b.read("position");
  b.read("normal");
  b.write("filter.scratch");
  b.output(config_.output, OutputKind::Image2D, Semantic::RadianceHDR,
           "the indirect light after the passes so far (at the traced resolution)")
      .referenceMode = config_.referenceMode;
  config_.traced.declareImage(b, config_.output, GL_RGBA32F);
  config_.traced.declareImage(b, "filter.scratch", GL_RGBA32F);
}

int AtrousFilterStage::passes(const ParamSet& params) const {
  const int fixed = params.getInt("filter.passes");
  if (fixed >= 0) return fixed;
  return atrousPassesFor(params.getFloat("filter.samples"), raysPerPixel(params), kMaxPasses);
}

int AtrousFilterStage::raysPerPixel(const ParamSet& params) const {
  return config_.raysParam.empty() ? config_.raysPerPixel : params.getInt(config_.raysParam);
}

int AtrousFilterStage::iterations(const ParamSet& params) const { return std::max(passes(params), 1); }

void AtrousFilterStage::execute(StageContext& ctx) {
  Texture& source = ctx.board.texture(config_.source);
  const glm::ivec3 size = source.desc().size;
  Texture& filtered = ctx.board.ensureTexture(config_.output, imageDesc(size.x, size.y, GL_RGBA32F));
  Texture& scratch = ctx.board.ensureTexture("filter.scratch", imageDesc(size.x, size.y, GL_RGBA32F));
  const int total = passes(ctx.params);
  ctx.stats["passes"] = total;
  ctx.stats["kernel_rays"] = atrousEffectivePixels(total) * raysPerPixel(ctx.params);
  if (total == 0) {
    glCopyImageSubData(source.id(), GL_TEXTURE_2D, 0, 0, 0, 0, filtered.id(), GL_TEXTURE_2D, 0, 0, 0, 0, size.x,
                       size.y, 1);
    return;
  }
  // Each pass reads the previous result (the source for the first) and writes the output.
  if (ctx.iteration > 0)
    glCopyImageSubData(filtered.id(), GL_TEXTURE_2D, 0, 0, 0, 0, scratch.id(), GL_TEXTURE_2D, 0, 0, 0, 0, size.x,
                       size.y, 1);
  Texture& input = ctx.iteration == 0 ? source : scratch;
  GLuint program = ctx.shaders.program({"common/atrous_filter.comp.glsl"});
  setUniform(program, "u_hole", 1 << ctx.iteration);
  setUniform(program, "u_traceScale", config_.traced.scale(ctx.params));
  setUniform(program, "u_depthScale", config_.depthScale(ctx.params, ctx.scene));
  setUniform(program, "u_normalSigma", ctx.params.getFloat("filter.normal-sigma"));
  glUseProgram(program);
  glBindTextureUnit(1, ctx.board.texture("position").id());
  glBindTextureUnit(2, ctx.board.texture("normal").id());
  glBindTextureUnit(3, input.id());
  glBindImageTexture(0, filtered.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  dispatchCompute({size.x, size.y, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
}

}  // namespace voxlab
