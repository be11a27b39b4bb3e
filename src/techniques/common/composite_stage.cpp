// The composite stage shared by every technique (composite_stage.h).
#include "techniques/common/composite_stage.h"

#include <utility>

#include "common/shared.h"
#include "core/error.h"
#include "gpu/shader_library.h"
#include "techniques/common/sky.h"

namespace voxlab {

static const std::pair<const char*, GLenum> kCompositeImages[] = {
    {"direct", GL_RGBA16F}, {"combined", GL_RGBA16F}, {"final", GL_RGBA8}};

ParamDesc compositeExposureParam() {
  return ParamDesc::real("composite.exposure", 1.0, 0.01, 64.0, "scale applied before tonemapping");
}

CompositeStage::CompositeStage(CompositeTerms terms) : terms_(std::move(terms)) {
  if (terms_.indirect.size() > size_t(kMaxCompositeTerms))
    throw Error("composite: " + std::to_string(terms_.indirect.size()) + " terms, at most " +
                std::to_string(kMaxCompositeTerms));
}

void CompositeStage::declare(StageBuilder& b) const {
  for (const ParamDesc& p : terms_.params) b.param(p);
  if (terms_.sky) declareSky(b);  // the background: pixels that see no surface show the sky
  for (const char* gbuffer : {"position", "normal", "albedo", "emission"}) b.read(gbuffer);
  for (const CompositeTerm& term : terms_.indirect) b.read(term.image);
  if (terms_.visibility) b.read(terms_.visibility->image);
  b.read("shadow-map");
  b.read("light");
  b.output("direct", OutputKind::Image2D, Semantic::RadianceHDR, "direct light plus emission").referenceMode = "direct";
  b.output("combined", OutputKind::Image2D, Semantic::RadianceHDR, terms_.combinedHelp).referenceMode = "full";
  b.output("final", OutputKind::Image2D, Semantic::Color, "the tonemapped image: x / (1 + x) of exposure * combined");
  for (const auto& [name, format] : kCompositeImages)
    b.texture(name, [format = format](const ParamSet&, const ViewState& v) { return viewImageDesc(v, format); });
}

void CompositeStage::execute(StageContext& ctx) {
  Texture* images[3];
  for (int i = 0; i < 3; ++i)
    images[i] = &ctx.board.ensureTexture(kCompositeImages[i].first, viewImageDesc(ctx.view, kCompositeImages[i].second));
  GLuint program = ctx.shaders.program({"common/composite.comp.glsl"});
  const int traceScale = terms_.traced ? terms_.traced->scale(ctx.params) : 1;
  const bool tracedVisibility =
      terms_.visibility && ctx.params.getChoice(terms_.visibility->param) == terms_.visibility->tracedOption;
  setUniform(program, "u_traceScale", traceScale);
  setUniform(program, "u_planeDistance", terms_.planeDistance ? terms_.planeDistance(ctx.params, ctx.scene) : 0.0f);
  setUniform(program, "u_tracedVisibility", tracedVisibility ? 1 : 0);
  setUniform(program, "u_exposure", ctx.params.getFloat("composite.exposure"));
  float weights[kMaxCompositeTerms] = {};
  int scales[kMaxCompositeTerms] = {1, 1, 1, 1};
  const int termCount = int(terms_.indirect.size());
  for (int i = 0; i < termCount; ++i) {
    weights[i] = ctx.params.getFloat(terms_.indirect[size_t(i)].weight);
    scales[i] = terms_.indirect[size_t(i)].traced ? traceScale : 1;
  }
  setUniform(program, "u_termCount", termCount);
  glProgramUniform1fv(program, glGetUniformLocation(program, "u_termWeight"), kMaxCompositeTerms, weights);
  glProgramUniform1iv(program, glGetUniformLocation(program, "u_termScale"), kMaxCompositeTerms, scales);
  // The program is shared by every technique. One that gathers no sky light (no sky.radiance
  // parameter) still shows the scene's own sky where a pixel sees no surface: the camera ray that
  // misses sees it in the reference too.
  if (terms_.sky) setSkyUniforms(program, ctx.params, ctx.scene);
  else setUniform(program, "u_skyRadiance", glm::vec3(ctx.scene.skyRadiance));
  glUseProgram(program);
  const char* gbuffer[] = {"position", "normal", "albedo", "emission"};
  for (int i = 0; i < 4; ++i) glBindTextureUnit(GLuint(1 + i), ctx.board.texture(gbuffer[i]).id());
  glBindTextureUnit(5, ctx.board.texture("shadow-map").id());
  glBindTextureUnit(6, terms_.visibility ? ctx.board.texture(terms_.visibility->image).id() : 0);
  for (int i = 0; i < termCount; ++i)
    glBindTextureUnit(GLuint(7 + i), ctx.board.texture(terms_.indirect[size_t(i)].image).id());
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  for (int i = 0; i < 3; ++i)
    glBindImageTexture(GLuint(i), images[i]->id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, kCompositeImages[i].second);
  dispatchCompute({ctx.view.width, ctx.view.height, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
}

}  // namespace voxlab
