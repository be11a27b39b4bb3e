// The lpv propagate stage: SH flux from cell to cell, one step per iteration (see lpv.cpp for the
// overview).
#include "techniques/lpv/stages.h"
#include "techniques/lpv/stage_helpers.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "scene/scene.h"
#include "techniques/common/voxel_space.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/lpv/reference.h"
#include "techniques/lpv/sh.h"

namespace voxlab::lpv {

static ParamDesc probeCascadeParam() {
  return ParamDesc::choice("probe.cascade", {"fine", "coarse"}, 0, "cascade of the picked cell");
}
static std::string occlusionBuffer(int cascade) { return std::string("occlusion-") + kCascadeNames[cascade]; }
static size_t occlusionBytes(const ParamSet& p) { return sizeof(gpu::LpvOcclusion) * cellCount(p); }
static size_t stateBytes(const ParamSet& p) { return 6 * cellCount(p) * 16; }  // six sections of RGBA32F
static size_t energyBytes(const ParamSet& p) {
  return sizeof(gpu::LpvEnergy) * kCascades * size_t(propagationSteps(p) + 1);
}
// propagate.comp.glsl runs one invocation per column of cells along x, in work groups of 8 x 4
// columns (y, z), and writes two vec4 of partial energy sums per column (per invocation of the
// dispatch, the padding of the last work groups included).
static const glm::ivec3 kPropagateColumns(8, 4, 1);
static glm::ivec2 propagateInvocations(glm::ivec3 box) {
  return glm::ivec2((box.y + kPropagateColumns.x - 1) / kPropagateColumns.x * kPropagateColumns.x,
                    (box.z + kPropagateColumns.y - 1) / kPropagateColumns.y * kPropagateColumns.y);
}
static size_t energyPartialsBytes(const ParamSet& p) {
  const glm::ivec2 n = propagateInvocations(glm::ivec3(p.getInt("lpv.resolution")));
  return 32 * size_t(n.x) * n.y;
}
static std::string stateBuffer(int p, int cascade) {
  return "propagate.state" + std::to_string(p) + "-" + kCascadeNames[cascade];
}

// --- propagate -----------------------------------------------------------------------------------

static ParamDesc schemeParam() {
  return ParamDesc::choice("lpv.scheme", {"wavefront", "thesis"}, 0,
                           "wavefront (Kaplanyan-Dachsbacher): each step propagates only the last step's light and the "
                           "lookup sums all steps; thesis: each step propagates everything so far (energy grows "
                           "geometrically, near light counted many times)");
}

void PropagateStage::declare(StageBuilder& b) const {
  b.param(resolutionParam());
  b.param(stepsParam());
  b.param(fineExtentParam());
  b.param(schemeParam());
  b.param(ParamDesc::choice("lpv.weighting", {"flux-consistent", "thesis"}, 0,
                            "face weight: solid angle / pi (a face of flux F re-emits F / pi times a cosine lobe), or "
                            "solid angle / 4 pi times lpv.flux-amplifier as the thesis"));
  b.param(ParamDesc::real("lpv.flux-amplifier", 1.75, 0.0, 8.0,
                          "thesis weighting only: the factor GPU Pro 4 multiplies solid angle / 4 pi by (1.75)"));
  b.param(ParamDesc::boolean("lpv.clamp-faces", true,
                             "clamp each face's evaluated intensity at 0 (off: the linear operator, which conserves "
                             "flux exactly; on: negative back lobes are dropped, about +14 % on a first step)"));
  b.param(ParamDesc::boolean("lpv.clamp-conserves", false,
                             "with lpv.clamp-faces: scale each neighbour's clamped faces so they carry the flux of "
                             "its unclamped five (the clamp keeps intensities non-negative without adding flux)"));
  b.param(ParamDesc::choice("lpv.reprojection", {"face-axis", "travel", "beam"}, 0,
                            "the lobe a face's flux re-enters as: along the face's axis (Kaplanyan-Dachsbacher; the "
                            "light keeps 37 % of its direction per step, a random walk), or along the direction it "
                            "crossed the face in (keeps 2/3)"));
  b.param(ParamDesc::choice("lpv.occlusion", {"two-sided", "thesis", "none", "front"}, 0,
                            "blocking by the source cell's voxel: a surface blocks both ways, as the thesis (only light "
                            "travelling along its stored normal), not at all, or only light arriving at its front "
                            "(not the light it sends)"));
  b.param(ParamDesc::real("lpv.occlusion-amplifier", 1.0, 0.0, 4.0,
                          "blocked fraction = amplifier * (0.25 + 0.5 n.d), clamped to 1: 1 lets 25 % through head "
                          "on, 4/3 blocks all"));
  b.param(ParamDesc::boolean("lpv.first-step-unoccluded", true,
                             "the first step ignores occlusion, so a VPL's own voxel does not block its light"));
  b.param(probeParam("x"));
  b.param(probeParam("y"));
  b.param(probeParam("z"));
  b.param(probeCascadeParam());
  // A click on a cell of any volume shown in the viewer picks it (the cascade stays probe.cascade).
  b.probe(ProbeDesc::volume("probe.cell-x", "probe.cell-y", "probe.cell-z"));
  for (int c = 0; c < kCascades; ++c) {
    b.read(voxelBuffer(c));
    for (int ch = 0; ch < 3; ++ch) b.read(shVolume("vpl", c, ch));
  }
  b.write("energy.count");
  for (int c = 0; c < kCascades; ++c)
    for (int ch = 0; ch < 3; ++ch)
      b.output(shVolume("light", c, ch), OutputKind::Volume3D, kShL1,
               std::string("sh-l1: intensity (W/sr) the lookup reads, ") + kChannelNames[ch] + " channel, " +
                   kCascadeNames[c] + " cascade, after the steps so far; shown as log c00, |b|/c00 or lobes");
  for (int c = 0; c < kCascades; ++c)
    for (int ch = 0; ch < 3; ++ch)
      b.output(shVolume("wavefront", c, ch), OutputKind::Volume3D, kShL1,
               std::string("sh-l1: light that moved in the last step, ") + kChannelNames[ch] + ", " + kCascadeNames[c] +
                   " (the L1 diamond); shown as log c00, |b|/c00 or lobes")
          .alongside = true;  // the propagation's own state
  BufferLayout energy;
  energy.stride = sizeof(gpu::LpvEnergy);
  energy.fields = {{"wavefront", FieldType::Vec4, 0, FieldRole::Other}, {"total", FieldType::Vec4, 16, FieldRole::Other}};
  energy.countResource = "energy.count";
  b.output("energy", OutputKind::Buffer, kLpvEnergy,
           "per step (0 = injected) and cascade: flux of the wavefront (rgb, step) and of the grid (rgb, cascade), W")
      .layout = energy;
  b.alongside({"energy"});
  BufferLayout probe;
  probe.stride = sizeof(gpu::LpvProbe);
  probe.fields = {{"cell", FieldType::I32, 0}, {"cell-y", FieldType::I32, 4}, {"cell-z", FieldType::I32, 8},
                  {"cascade", FieldType::I32, 12}};
  const char* rgb[3] = {"r", "g", "b"};
  for (int ch = 0; ch < 3; ++ch) probe.fields.push_back({std::string("light-") + rgb[ch], FieldType::Vec4, uint32_t(16 + 16 * ch)});
  for (int ch = 0; ch < 3; ++ch) probe.fields.push_back({std::string("wavefront-") + rgb[ch], FieldType::Vec4, uint32_t(64 + 16 * ch)});
  probe.fields.push_back({"color-occlusion", FieldType::U32, 112});
  probe.fields.push_back({"fragments", FieldType::U32, 116});
  probe.fields.push_back({"step", FieldType::U32, 120});
  for (int k = 0; k < 4; ++k) probe.fields.push_back({"normal-" + std::to_string(k), FieldType::U32, uint32_t(128 + 4 * k)});
  const char* dirs[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  for (int i = 0; i < 6; ++i) probe.fields.push_back({std::string("from") + dirs[i], FieldType::Vec4, uint32_t(144 + 16 * i)});
  for (int part = 0; part < 2; ++part)
    for (int f = 0; f < 30; ++f) {
      const int i = f / 5, k = f % 5, j = k < i ? k : k + 1;
      probe.fields.push_back({std::string(part == 0 ? "intensity" : "flux") + dirs[i] + "-face" + dirs[j],
                              FieldType::Vec4, uint32_t(240 + 480 * part + 16 * f)});
    }
  probe.fields.push_back({"weight", FieldType::F32, 1200});
  OutputDesc& cellRecord = b.output("probe-cell", OutputKind::Buffer, kLpvProbe,
           "the picked cell (probe.cell-x/y/z, probe.cascade) after the current step: SH per channel, its voxel's "
           "words, c00 gained from each neighbour (a: mean face transmission), and per neighbour its five face "
           "evaluations (intensity towards the face, solid angle, transmission, flux) that sum to it");
  cellRecord.alongside = true;
  cellRecord.layout = probe;
  cellRecord.probeRecord = true;  // checked and drawn by src/inspect/visualisers/lpv_probe.cpp
  BufferLayout occ;
  occ.stride = sizeof(gpu::LpvOcclusion);
  occ.fields = {{"cell", FieldType::Packed10_10_10, 0, FieldRole::Position},
                {"occupied", FieldType::U32, 4, FieldRole::Other},
                {"plus", FieldType::Vec4, 16, FieldRole::Other},
                {"minus", FieldType::Vec4, 32, FieldRole::Other}};
  for (int c = 0; c < kCascades; ++c) {
    b.output(occlusionBuffer(c), OutputKind::Buffer, kLpvOcclusion,
             std::string("per cell of the ") + kCascadeNames[c] +
                 " cascade: transmission of light leaving it head on along +x,+y,+z (plus.xyz) and -x,-y,-z "
                 "(minus.xyz), least (plus.w) and mean (minus.w) of the six, by lpv.occlusion and "
                 "lpv.occlusion-amplifier from step 1 on")
        .layout = occ;
    b.alongside({occlusionBuffer(c)});  // the propagation reads it as it goes
    b.buffer(occlusionBuffer(c), [](const ParamSet& p, const ViewState&) { return occlusionBytes(p); });
  }
  for (int c = 0; c < kCascades; ++c)
    for (const char* prefix : {"light", "wavefront"})
      for (int ch = 0; ch < 3; ++ch)
        b.texture(shVolume(prefix, c, ch), [](const ParamSet& p, const ViewState&) { return shDesc(p.getInt("lpv.resolution")); });
  for (int c = 0; c < kCascades; ++c)
    for (int s = 0; s < 2; ++s) b.buffer(stateBuffer(s, c), [](const ParamSet& p, const ViewState&) { return stateBytes(p); });
  b.buffer("energy", [](const ParamSet& p, const ViewState&) { return energyBytes(p); });
  b.buffer("energy.count", [](const ParamSet&, const ViewState&) { return size_t(4); });
  b.buffer("probe-cell", [](const ParamSet&, const ViewState&) { return sizeof(gpu::LpvProbe); });
  b.buffer("propagate.energy-partials", [](const ParamSet& p, const ViewState&) { return energyPartialsBytes(p); });
  b.buffer("propagate.active-boxes", [](const ParamSet&, const ViewState&) { return 2 * kCascades * sizeof(glm::ivec4); });
}

int PropagateStage::iterations(const ParamSet& params) const { return propagationSteps(params); }

// The occlusion view (outputs occlusion-fine/coarse): per cell and direction of travel the
// transmission the propagation applies to light leaving the cell head on, from the CPU reference's
// faceTransmission (the same maths as propagate.comp.glsl, tested against it), at step 1.
static void writeOcclusionView(StageContext& ctx, int occlusion) {
  PropagationSettings s;
  s.occlusion = occlusion == 0 ? Occlusion::TwoSided : occlusion == 1 ? Occlusion::Thesis : occlusion == 2 ? Occlusion::None : Occlusion::Front;
  s.occlusionAmplifier = ctx.params.getFloat("lpv.occlusion-amplifier");
  double least = 1.0, occupied = 0, blocking = 0;
  for (int c = 0; c < kCascades; ++c) {
    auto bytes = ctx.board.buffer(voxelBuffer(c)).download(voxelBufferBytes(ctx.params));
    const size_t cells = bytes.size() / sizeof(gpu::LpvVoxel);
    std::vector<gpu::LpvOcclusion> view(cells);
    for (size_t i = 0; i < cells; ++i) {
      gpu::LpvVoxel v;
      std::memcpy(&v, &bytes[i * sizeof v], sizeof v);
      gpu::LpvOcclusion& o = view[i];
      o = gpu::LpvOcclusion{};
      o.cell = v.cell;
      o.occupied = decodeOccupied(v.colorOcclusion) ? 1u : 0u;
      float t[6], lo = 1.0f, mean = 0.0f;
      for (int f = 0; f < 6; ++f) {
        glm::vec3 travel = faceOffset(f);
        t[f] = faceTransmission(&v, travel, travel, s, 1);
        lo = std::min(lo, t[f]);
        mean += t[f] / 6.0f;
      }
      o.plus = glm::vec4(t[0], t[2], t[4], lo);
      o.minus = glm::vec4(t[1], t[3], t[5], mean);
      if (c == 0 && o.occupied) {
        ++occupied;
        blocking += lo < 1.0f;
        least = std::min(least, double(lo));
      }
    }
    ctx.board.ensureBuffer(occlusionBuffer(c), occlusionBytes(ctx.params)).upload(view.data(), view.size() * sizeof(view[0]));
  }
  ctx.stats["occupied_cells_fine"] = occupied;
  ctx.stats["blocking_cells_fine"] = blocking;
  ctx.stats["least_transmission_fine"] = least;
}

// Energy record (step, cascade) from sums of c00 per channel: flux = c00 * 2 sqrt(pi).
static void writeEnergy(Buffer& energy, int cascade, int step, glm::dvec3 lightC00, glm::dvec3 waveC00) {
  gpu::LpvEnergy record;
  record.wavefront = glm::vec4(glm::vec3(waveC00 * double(kFluxPerC00)), float(step));
  record.total = glm::vec4(glm::vec3(lightC00 * double(kFluxPerC00)), float(cascade));
  glNamedBufferSubData(energy.id(), GLintptr(sizeof record) * (step * kCascades + cascade), sizeof record, &record);
}

void PropagateStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("lpv.resolution");
  const int k = ctx.iteration;
  const bool thesisScheme = ctx.params.getChoice("lpv.scheme") == "thesis";
  const double pi = kPi;
  const float weightScale = ctx.params.getChoice("lpv.weighting") == "thesis"
                                ? float(ctx.params.getFloat("lpv.flux-amplifier") / (4.0 * pi))
                                : float(1.0 / pi);
  const int occlusion = ctx.params.getInt("lpv.occlusion");  // 0 two-sided, 1 thesis, 2 none
  Buffer& energy = ctx.board.ensureBuffer("energy", energyBytes(ctx.params));
  Buffer& energyCount = ctx.board.ensureBuffer("energy.count", 4);
  Buffer& probe = ctx.board.ensureBuffer("probe-cell", sizeof(gpu::LpvProbe));
  const int probeCascade = ctx.params.getInt("probe.cascade");

  // The propagation's choices are program defines (propagate.comp.glsl: llvmpipe runs both sides
  // of a branch on a uniform).
  const auto define = [](const char* name, int value) { return std::string("#define ") + name + " " + std::to_string(value) + "\n"; };
  const std::string choices = define("LPV_THESIS_SCHEME", thesisScheme ? 1 : 0) +
                              define("LPV_CLAMP_FACES", ctx.params.getBool("lpv.clamp-faces") ? 1 : 0) +
                              define("LPV_CLAMP_CONSERVES", ctx.params.getBool("lpv.clamp-conserves") ? 1 : 0) +
                              define("LPV_OCCLUSION", occlusion) +
                              define("LPV_FIRST_STEP_UNOCCLUDED", ctx.params.getBool("lpv.first-step-unoccluded") ? 1 : 0) +
                              define("LPV_REPROJECTION", ctx.params.getInt("lpv.reprojection"));
  GLuint prop = ctx.shaders.program({"lpv/propagate.comp.glsl"}, choices);
  // The picked cell's record comes from the same shader built with the recording (one invocation).
  GLuint recorder = ctx.shaders.program({"lpv/propagate.comp.glsl"}, choices + "#define LPV_PROBE 1\n");
  if (k == 0) writeOcclusionView(ctx, occlusion);
  // Per cascade the lowest and highest cell holding injected light (none: lo > hi), found at step 0.
  std::array<glm::ivec4, 2 * kCascades> activeBoxes;
  if (k > 0) {
    auto bytes = ctx.board.buffer("propagate.active-boxes").download(sizeof(activeBoxes));
    std::memcpy(activeBoxes.data(), bytes.data(), sizeof(activeBoxes));
  }
  double updated = 0;
  for (int c = 0; c < kCascades; ++c) {
    // Step k reads the state step k-1 wrote (step 0: the injected VPLs, packed into state 0) and
    // writes the other state, then copies it into the output volumes (buffer -> texture copies).
    const size_t cells = size_t(res) * res * res, section = cells * 16;
    Buffer* state[2];
    for (int p = 0; p < 2; ++p)
      state[p] = &ctx.board.ensureBuffer(stateBuffer(p, c), stateBytes(ctx.params));
    Buffer& in = *state[k % 2];
    Buffer& out = *state[(k + 1) % 2];
    Texture *light[3], *wave[3];
    for (int ch = 0; ch < 3; ++ch) {
      light[ch] = &ctx.board.ensureTexture(shVolume("light", c, ch), shDesc(res));
      wave[ch] = &ctx.board.ensureTexture(shVolume("wavefront", c, ch), shDesc(res));
    }
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    if (k == 0) {
      glBindBuffer(GL_PIXEL_PACK_BUFFER, in.id());
      for (int ch = 0; ch < 3; ++ch)
        for (int part = 0; part < 2; ++part)
          glGetTextureImage(ctx.board.texture(shVolume("vpl", c, ch)).id(), 0, GL_RGBA, GL_FLOAT, GLsizei(section),
                            reinterpret_cast<void*>((part * 3 + ch) * section));
      glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
      barrier();
      // The box of cells holding injected light (cells outside it in the other state are never
      // written), and record 0 of the cascade: the injected flux (wavefront = grid), summed in cell
      // order.
      glClearNamedBufferData(out.id(), GL_R32F, GL_RED, GL_FLOAT, nullptr);
      auto injected = in.download(3 * section);
      glm::ivec4 lo(res, res, res, 0), hi(-1, -1, -1, 0);
      glm::dvec3 injectedSum(0.0);
      for (int ch = 0; ch < 3; ++ch) {
        const float* v = reinterpret_cast<const float*>(injected.data() + ch * section);
        for (size_t i = 0; i < cells; ++i) {
          injectedSum[ch] += v[4 * i];
          if (v[4 * i] == 0.0f && v[4 * i + 1] == 0.0f && v[4 * i + 2] == 0.0f && v[4 * i + 3] == 0.0f) continue;
          const glm::ivec3 cell(int(i % res), int(i / res % res), int(i / (size_t(res) * res)));
          lo = glm::ivec4(glm::min(glm::ivec3(lo), cell), 0);
          hi = glm::ivec4(glm::max(glm::ivec3(hi), cell), 0);
        }
      }
      activeBoxes[2 * c] = lo;
      activeBoxes[2 * c + 1] = hi;
      writeEnergy(energy, c, 0, injectedSum, injectedSum);
      ctx.board.ensureBuffer("propagate.active-boxes", sizeof(activeBoxes)).upload(activeBoxes.data(), sizeof(activeBoxes));
    }
    // Light moves at most one cell per step (locality), so after step k only cells within k + 1
    // cells of an injected one can hold any: the step runs over that box alone. Every cell outside
    // it would gather exactly 0 from dark neighbours and keep its 0, which both states hold there.
    const glm::ivec3 boxLo = glm::max(glm::ivec3(activeBoxes[2 * c]) - (k + 1), glm::ivec3(0));
    const glm::ivec3 boxHi = glm::min(glm::ivec3(activeBoxes[2 * c + 1]) + (k + 1), glm::ivec3(res - 1));
    const glm::ivec3 boxSize = glm::max(boxHi - boxLo + 1, glm::ivec3(0));
    for (int j = 0; j <= k; ++j) {  // the cells steps 0..k updated (statistic)
      const glm::ivec3 lo = glm::max(glm::ivec3(activeBoxes[2 * c]) - (j + 1), glm::ivec3(0));
      const glm::ivec3 hi = glm::min(glm::ivec3(activeBoxes[2 * c + 1]) + (j + 1), glm::ivec3(res - 1));
      const glm::ivec3 n = glm::max(hi - lo + 1, glm::ivec3(0));
      updated += double(n.x) * n.y * n.z;
    }
    auto bindCommon = [&](GLuint program) {
      setUniform(program, "u_gridRes", res);
      setUniform(program, "u_step", k);
      setUniform(program, "u_weightScale", weightScale);
      setUniform(program, "u_occlusionAmplifier", ctx.params.getFloat("lpv.occlusion-amplifier"));
      glUseProgram(program);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_STATE_IN, in.id());
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_STATE_OUT, out.id());
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_VOXELS, ctx.board.buffer(voxelBuffer(c)).id());
    };
    bindCommon(prop);
    setUniform(prop, "u_boxLo", boxLo);
    setUniform(prop, "u_boxHi", boxHi);
    glUseProgram(prop);
    Buffer& partials = ctx.board.ensureBuffer("propagate.energy-partials", energyPartialsBytes(ctx.params));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_ENERGY_PARTIALS, partials.id());
    const glm::ivec2 invocations = propagateInvocations(boxSize);
    const size_t columns = boxSize.x > 0 ? size_t(invocations.x) * invocations.y : 0;
    if (columns > 0) dispatchCompute({boxSize.y, boxSize.z, 1}, kPropagateColumns);
    barrier();
    // The step's energy record: the columns' partial sums added in column order (deterministic
    // whatever the thread count; cells outside the box hold 0 and add nothing).
    {
      glm::dvec3 lightSum(0.0), waveSum(0.0);
      if (columns > 0) {
        auto bytes = partials.download(32 * columns);
        const float* v = reinterpret_cast<const float*>(bytes.data());
        for (size_t i = 0; i < columns; ++i) {
          lightSum += glm::dvec3(v[8 * i], v[8 * i + 1], v[8 * i + 2]);
          waveSum += glm::dvec3(v[8 * i + 4], v[8 * i + 5], v[8 * i + 6]);
        }
      }
      writeEnergy(energy, c, k + 1, lightSum, waveSum);
    }
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, out.id());
    for (int ch = 0; ch < 3; ++ch) {
      glTextureSubImage3D(light[ch]->id(), 0, 0, 0, 0, res, res, res, GL_RGBA, GL_FLOAT, reinterpret_cast<void*>(ch * section));
      glTextureSubImage3D(wave[ch]->id(), 0, 0, 0, 0, res, res, res, GL_RGBA, GL_FLOAT, reinterpret_cast<void*>((3 + ch) * section));
    }
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    barrier();
    if (c == probeCascade) {
      setUniform(recorder, "u_probeCell", probeCell(ctx.params));
      setUniform(recorder, "u_cascade", c);
      bindCommon(recorder);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_BINDING_PROBE, probe.id());
      dispatchCompute({1, 1, 1}, kPropagateColumns);  // one work group; its first invocation records
      barrier();
    }
  }
  uint32_t records = uint32_t((k + 2) * kCascades);
  energyCount.upload(&records, 4);
  ctx.stats["steps_done"] = k + 1;
  // Of all cells of both cascades over the steps so far, the fraction the steps ran over.
  ctx.stats["cells_updated_fraction"] = updated / (double(kCascades) * (k + 1) * res * res * res);
  // Per cascade: VPL, light and wavefront volumes (3 channels each) and two states of 6 sections.
  ctx.stats["bytes_sh_per_cascade"] = double(res) * res * res * 16.0 * (9 + 12);
}

}  // namespace voxlab::lpv
