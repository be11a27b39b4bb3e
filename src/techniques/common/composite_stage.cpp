// The composite stage shared by every technique (composite_stage.h).
#include "techniques/common/composite_stage.h"

#include <algorithm>
#include <utility>

#include "common/shared.h"
#include "core/error.h"
#include "gpu/shader_library.h"
#include "graph/scene_inputs.h"
#include "techniques/common/light_stage.h"
#include "techniques/common/sky.h"

namespace voxlab {

static const std::pair<const char*, GLenum> kCompositeImages[] = {
    {"direct", GL_RGBA16F}, {"combined", GL_RGBA16F}, {"final", GL_RGBA8}};

ParamDesc compositeExposureParam() {
  return ParamDesc::real("composite.exposure", 1.0, 0.01, 64.0, "scale applied before tonemapping");
}

ParamDesc compositeSpecularParam() {
  return ParamDesc::real("composite.specular", 0.0, 0.0, 1.0,
                         "weight of the indirect specular term: 0, the scenes' materials are Lambertian (as the "
                         "reference's), so the specular cone is traced only when its image is shown; 0.04 is a "
                         "dielectric's reflectance at normal incidence");
}

CompositeStage::CompositeStage(CompositeTerms terms) : terms_(std::move(terms)) {
  if (terms_.indirect.size() > size_t(kMaxCompositeTerms))
    throw Error("composite: " + std::to_string(terms_.indirect.size()) + " terms, at most " +
                std::to_string(kMaxCompositeTerms));
}

namespace {

constexpr const char* kRadiance = " [W/m^2/sr]";
constexpr size_t kProbeChainBytes = size_t(PROBE_CHAIN_SLOTS) * 16;

// The probe chain's fields: one per step of the composite's sum at the probed pixel, in the
// order the shader builds it (PROBE_CHAIN_* slots in shaders/common/shared.h), each named
// "section: label [unit]".
BufferLayout probeChainLayout(const CompositeTerms& terms) {
  BufferLayout l;
  l.stride = uint32_t(kProbeChainBytes);
  auto add = [&](const std::string& name, FieldType type, int slot, int component = 0,
                 FieldRole role = FieldRole::Other) {
    l.fields.push_back({name, type, uint32_t(16 * slot + 4 * component), role});
  };
  add("surface: pixel (x, y from the top)", FieldType::Vec2, PROBE_CHAIN_PIXEL);
  add("surface: seen (1 a surface, 0 the sky)", FieldType::F32, PROBE_CHAIN_PIXEL, 2);
  add("surface: position [m]", FieldType::Vec3, PROBE_CHAIN_POSITION);
  add("surface: normal", FieldType::Vec3, PROBE_CHAIN_NORMAL);
  add("surface: albedo", FieldType::Vec3, PROBE_CHAIN_ALBEDO);
  add(std::string("surface: emission") + kRadiance, FieldType::Vec3, PROBE_CHAIN_EMISSION);
  add("direct: direction to the light", FieldType::Vec3, PROBE_CHAIN_TO_LIGHT);
  add("direct: distance to the light [m]", FieldType::F32, PROBE_CHAIN_TO_LIGHT, 3);
  add("direct: irradiance facing the light [W/m^2]", FieldType::Vec3, PROBE_CHAIN_IRRADIANCE);
  add("direct: n.l", FieldType::F32, PROBE_CHAIN_IRRADIANCE, 3);
  add("direct: shadow receiver depth (map depth units, -1 map not used)", FieldType::F32, PROBE_CHAIN_SHADOW, 0);
  add("direct: shadow map depth at the centre tap", FieldType::F32, PROBE_CHAIN_SHADOW, 1);
  add("direct: shadow taps that see the light (of 9)", FieldType::F32, PROBE_CHAIN_SHADOW, 2);
  add(std::string("direct: visibility used") +
          (terms.visibility ? " (" + terms.visibility->image + " when " + terms.visibility->param + "=" +
                                  terms.visibility->tracedOption + ")"
                            : std::string()),
      FieldType::F32, PROBE_CHAIN_SHADOW, 3);
  add(std::string("direct: reflected = albedo/pi * irradiance * n.l * visibility (the sky where no surface)") + kRadiance,
      FieldType::Vec3, PROBE_CHAIN_REFLECTED, 0, FieldRole::Addend);
  add(std::string("direct: emission") + kRadiance, FieldType::Vec3, PROBE_CHAIN_EMISSION, 0, FieldRole::Addend);
  for (size_t i = 0; i < terms.indirect.size(); ++i) {
    const CompositeTerm& t = terms.indirect[i];
    const int slot = PROBE_CHAIN_TERMS + 2 * int(i);
    add("indirect: " + t.image + kRadiance, FieldType::Vec3, slot);
    add("indirect: " + t.weight + " (weight of " + t.image + ")", FieldType::F32, slot, 3);
    add("indirect: " + t.weight + " * " + t.image + kRadiance, FieldType::Vec3, slot + 1, 0, FieldRole::Addend);
  }
  add(std::string("composite: combined = the sum of the above") + kRadiance, FieldType::Vec3, PROBE_CHAIN_COMBINED,
      0, FieldRole::Sum);
  add("composite: composite.exposure", FieldType::F32, PROBE_CHAIN_COMBINED, 3);
  add("composite: exposed = exposure * combined", FieldType::Vec3, PROBE_CHAIN_EXPOSED);
  add("composite: tone mapped = x / (1 + x)", FieldType::Vec3, PROBE_CHAIN_TONEMAPPED);
  add("composite: final, as stored (8 bits per channel, linear)", FieldType::Vec3, PROBE_CHAIN_STORED, 0,
      FieldRole::Displayed);
  return l;
}

}  // namespace

void CompositeStage::declare(StageBuilder& b) const {
  for (const ParamDesc& p : terms_.params) b.param(p);
  if (terms_.sky) declareSky(b);  // the background: pixels that see no surface show the sky
  b.param(ParamDesc::real("probe.x", 0.5, 0.0, 1.0, "horizontal position of the probed pixel (0 left, 1 right)"));
  b.param(ParamDesc::real("probe.y", terms_.probeDefaultY, 0.0, 1.0,
                          "vertical position of the probed pixel (0 top, 1 bottom)"));
  b.probe(ProbeDesc::screen("probe.x", "probe.y"));  // a click on a camera image picks the explained pixel
  for (const char* gbuffer : {"position", "normal", "albedo", "emission"}) b.read(gbuffer);
  // A term of weight 0 adds nothing: its image is not read, so outputs on demand leave it out.
  for (const CompositeTerm& term : terms_.indirect) b.readWhen(term.image, term.weight + ">0");
  if (terms_.visibility) b.readWhen(terms_.visibility->image, terms_.visibility->param + "=" + terms_.visibility->tracedOption);
  b.read("shadow-map");
  b.read("light");
  b.read(kSceneLightsInput);  // the light's type: the program is built for it (lightKindDefines)
  b.output("direct", OutputKind::Image2D, Semantic::RadianceHDR, "direct light plus emission").referenceMode = "direct";
  b.alongside({"direct"});
  b.output("combined", OutputKind::Image2D, Semantic::RadianceHDR, terms_.combinedHelp).referenceMode = "full";
  b.alongside({"combined"});
  b.output("final", OutputKind::Image2D, Semantic::Color, "the tonemapped image: x / (1 + x) of exposure * combined");
  auto& chain = b.output("probe-chain", OutputKind::Buffer, Semantic::ProbeChain,
                         "the probed pixel explained: surface, direct light with its shadow test, each indirect term "
                         "and its weight, the sum, exposure, tone map and the stored value");
  chain.alongside = true;
  chain.layout = probeChainLayout(terms_);
  chain.probeRecord = true;
  // No golden: every value is a texel of an image above (the G-buffer, the terms, the composite's
  // images, all compared with goldens) at one pixel; expect-probe-chain checks how they combine.
  chain.tier = CaptureTier::None;
  for (const auto& [name, format] : kCompositeImages)
    b.texture(name, [format = format](const ParamSet&, const ViewState& v) { return viewImageDesc(v, format); });
  b.buffer("probe-chain", [](const ParamSet&, const ViewState&) { return kProbeChainBytes; });
}

void CompositeStage::execute(StageContext& ctx) {
  Texture* images[3];
  for (int i = 0; i < 3; ++i)
    images[i] = &ctx.board.ensureTexture(kCompositeImages[i].first, viewImageDesc(ctx.view, kCompositeImages[i].second));
  const int traceScale = terms_.traced ? terms_.traced->scale(ctx.params) : 1;
  const bool tracedVisibility =
      terms_.visibility && ctx.params.getChoice(terms_.visibility->param) == terms_.visibility->tracedOption;
  const int termCount = int(terms_.indirect.size());
  // The visibility and the term count are the program's defines (composite.comp.glsl).
  GLuint program = ctx.shaders.program(
      {"common/composite.comp.glsl"},
      lightKindDefines(ctx.scene) + "#define COMPOSITE_TRACED_VISIBILITY " + (tracedVisibility ? "1" : "0") +
          "\n#define COMPOSITE_TERMS " + std::to_string(termCount) + "\n");
  setUniform(program, "u_traceScale", traceScale);
  setUniform(program, "u_planeDistance", terms_.planeDistance ? terms_.planeDistance(ctx.params, ctx.scene) : 0.0f);
  setUniform(program, "u_exposure", ctx.params.getFloat("composite.exposure"));
  float weights[kMaxCompositeTerms] = {};
  int scales[kMaxCompositeTerms] = {1, 1, 1, 1};
  for (int i = 0; i < termCount; ++i) {
    weights[i] = ctx.params.getFloat(terms_.indirect[size_t(i)].weight);
    scales[i] = terms_.indirect[size_t(i)].traced ? traceScale : 1;
  }
  // probe.y counts from the top of the image; GL rows count from the bottom.
  const int probeX = std::min(int(ctx.params.getFloat("probe.x") * float(ctx.view.width)), ctx.view.width - 1);
  const int probeY = std::min(int((1.0f - ctx.params.getFloat("probe.y")) * float(ctx.view.height)), ctx.view.height - 1);
  glProgramUniform2i(program, glGetUniformLocation(program, "u_probePixel"), probeX, probeY);
  Buffer& chain = ctx.board.ensureBuffer("probe-chain", kProbeChainBytes);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_PROBE_CHAIN, chain.id());
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
  // The traced visibility image exists only when it is the chosen visibility (outputs on demand).
  glBindTextureUnit(6, tracedVisibility ? ctx.board.texture(terms_.visibility->image).id() : 0);
  // A term of weight 0 whose image was not computed reads nothing (weight 0 times the unit's zeros).
  for (int i = 0; i < termCount; ++i) {
    const std::string& image = terms_.indirect[size_t(i)].image;
    glBindTextureUnit(GLuint(7 + i), weights[i] > 0.0f || ctx.board.hasTexture(image) ? ctx.board.texture(image).id() : 0);
  }
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  for (int i = 0; i < 3; ++i)
    glBindImageTexture(GLuint(i), images[i]->id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, kCompositeImages[i].second);
  dispatchCompute({ctx.view.width, ctx.view.height, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
}

}  // namespace voxlab
