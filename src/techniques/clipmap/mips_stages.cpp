// The stages that read the updated levels: mips of the coarsest level and the covered-cell
// comparison (see clipmap.cpp for the overview).
#include "techniques/clipmap/stages.h"
#include "graph/scene_inputs.h"
#include "techniques/clipmap/stage_helpers.h"

#include <algorithm>
#include <cstring>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "scene/scene.h"

namespace voxlab::clipmap {

static TextureDesc mipsDesc(const ParamSet& params) {
  const int n = params.getInt("clipmap.resolution");
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = atlasFormat(params);
  d.size = {facesOf(params) * n, n, n};  // the faces side by side along x
  d.levels = mipCount(n) + 1;
  d.minFilter = GL_LINEAR_MIPMAP_LINEAR;
  return d;
}
static TextureDesc logicalDesc(const ParamSet& params) {
  const int n = params.getInt("clipmap.resolution");
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = atlasFormat(params);
  d.size = {n, n * params.getInt("clipmap.levels"), n};
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}

// --- Mips -----------------------------------------------------------------------------------------

void MipsStage::declare(StageBuilder& b) const {
  for (const auto& p : layoutParams()) b.param(p);
  b.param(atlasFormatParam());
  for (const auto& p : pathParams()) b.param(p);
  b.readView();
  b.read("clip-atlas");
  b.output("clip-mips", OutputKind::Volume3D, Semantic::Color,
           "the coarsest level in logical order (mip 0: texel j = cell o_{L-1} + j) and its mips down to 4^3, each "
           "covering the same volume; with six faces, the faces side by side along x (isotropic, +x -x +y -y +z -z)");
  b.output("clip-logical", OutputKind::Volume3D, Semantic::Color,
           "every level's isotropic values unrolled into logical order, levels along y: texel (x, k N + y, z) = cell "
           "o_k + (x, y, z) of level k (compare with clip-atlas: the same data, cut at the physical seam)")
      .onDemand = true;  // a view for the viewer: the cones read the atlas
  b.texture("clip-mips", [](const ParamSet& p, const ViewState&) { return mipsDesc(p); });
  b.texture("clip-logical", [](const ParamSet& p, const ViewState&) { return logicalDesc(p); });
}

void MipsStage::execute(StageContext& ctx) {
  const Layout layout = layoutOf(ctx.params, ctx.scene);
  const auto path = cameraPath(ctx.params, ctx.scene, ctx.view);
  const auto& origins = path.back().origins;
  Texture& atlas = ctx.board.texture("clip-atlas");
  Texture& mips = ctx.board.ensureTexture("clip-mips", mipsDesc(ctx.params));
  const int last = layout.levels - 1;
  const double s = layout.voxelSize(last);
  const Cell& o = origins[size_t(last)];
  ctx.board.place("clip-mips", WorldBox{glm::vec3(glm::dvec3(o) * s), glm::vec3(glm::dvec3(o + Cell(layout.n)) * s)});
  // Mip 0 copies the coarsest clip level, the others reduce the mip below: a program each.
  GLuint programs[2];
  for (int copy = 0; copy < 2; ++copy) {
    programs[copy] = ctx.shaders.program({"clipmap/mips.comp.glsl"},
                                         atlasFormatDefines(ctx.params) + "#define CLIPMAP_MIP_COPY " + std::to_string(copy) + "\n");
    setClipUniforms(programs[copy], layout, origins);
  }
  glBindImageTexture(0, atlas.id(), 0, GL_TRUE, 0, GL_READ_ONLY, atlasFormat(ctx.params));
  for (int m = 0; m < mips.levels(); ++m) {
    glUseProgram(programs[m == 0 ? 1 : 0]);
    glBindImageTexture(1, mips.id(), std::max(m - 1, 0), GL_TRUE, 0, GL_READ_ONLY, atlasFormat(ctx.params));
    glBindImageTexture(2, mips.id(), m, GL_TRUE, 0, GL_WRITE_ONLY, atlasFormat(ctx.params));
    dispatchCompute(mips.levelSize(m), {4, 4, 4});
    glMemoryBarrier(kAllShaderWrites);
  }
  double bytes = double(mips.byteSize());
  if (ctx.wants("clip-logical")) {
    Texture& logical = ctx.board.ensureTexture("clip-logical", logicalDesc(ctx.params));
    GLuint unroll = ctx.shaders.program({"clipmap/unroll.comp.glsl"}, atlasFormatDefines(ctx.params));
    setClipUniforms(unroll, layout, origins);
    setUniform(unroll, "u_face", 0);
    glUseProgram(unroll);
    glBindImageTexture(0, atlas.id(), 0, GL_TRUE, 0, GL_READ_ONLY, atlasFormat(ctx.params));
    glBindImageTexture(1, logical.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, atlasFormat(ctx.params));
    dispatchCompute(logical.desc().size, {4, 4, 4});
    glMemoryBarrier(kAllShaderWrites);
    bytes += double(logical.byteSize());
  }
  for (int unit = 0; unit < 3; ++unit) glBindImageTexture(GLuint(unit), 0, 0, GL_TRUE, 0, GL_READ_ONLY, atlasFormat(ctx.params));
  ctx.stats["mips"] = mips.levels() - 1;
  ctx.stats["bytes"] = bytes;
}

// --- Covered cells: direct versus filtered ----------------------------------------------------------

static bool compareOn(const ParamSet& p) { return p.getChoice("clipmap.compare-covered") == "on"; }

static TextureDesc compareDesc(const ParamSet& p) {
  if (!compareOn(p)) {  // a placeholder texel
    TextureDesc d;
    d.target = GL_TEXTURE_3D;
    d.size = {1, 1, 1};
    return d;
  }
  return logicalDesc(p);
}

void CoveredCompareStage::declare(StageBuilder& b) const {
  b.read(kSceneGeometryInput);  // voxelizes the scene's triangles
  for (const auto& p : layoutParams()) b.param(p);
  for (const auto& p : pathParams()) b.param(p);
  for (const auto& p : injectParams()) b.param(p);
  b.param(fixedPointParam());
  b.param(atlasFormatParam());
  b.param(ParamDesc::choice("clipmap.compare-covered", {"off", "on"}, 0,
                            "on: voxelize the covered blocks directly as well, to compare with their filtered content"));
  b.readView();
  b.read("clip-atlas");
  b.read("shadow-map");
  b.read("light");
  b.write("covered-accumulators");
  b.write("covered-counters");
  b.write("covered-triangle-visit");
  b.output("covered-direct", OutputKind::Volume3D, Semantic::Color,
           "covered cells' own voxelization Direct_k in logical order (levels along y, as clip-logical); 0 elsewhere")
      .placeholderUnless = "clipmap.compare-covered=on";
  b.output("covered-difference", OutputKind::Volume3D, Semantic::Color,
           "|Direct_k - F(level k-1)| per covered cell: the change when the cell leaves the covered block (popping)")
      .placeholderUnless = "clipmap.compare-covered=on";
  b.texture("covered-direct", [](const ParamSet& p, const ViewState&) { return compareDesc(p); });
  b.texture("covered-difference", [](const ParamSet& p, const ViewState&) { return compareDesc(p); });
  b.buffer("covered-accumulators", [](const ParamSet& p, const ViewState&) {
    return compareOn(p) ? accumulatorBytes(p, p.getInt("clipmap.levels")) : size_t(16);
  });
  b.buffer("covered-counters", [](const ParamSet& p, const ViewState&) { return countersBytes(p.getInt("clipmap.levels")); });
  b.buffer("covered-triangle-visit", [](const ParamSet&, const ViewState&) { return size_t(4); }, /*pool=*/true);
}

void CoveredCompareStage::execute(StageContext& ctx) {
  Texture& direct = ctx.board.ensureTexture("covered-direct", compareDesc(ctx.params));
  Texture& difference = ctx.board.ensureTexture("covered-difference", compareDesc(ctx.params));
  Buffer& counters = ctx.board.ensureBuffer("covered-counters", countersBytes(ctx.params.getInt("clipmap.levels")));
  const bool on = compareOn(ctx.params);
  Buffer& accum = ctx.board.ensureBuffer("covered-accumulators", on ? accumulatorBytes(ctx.params, ctx.params.getInt("clipmap.levels")) : size_t(16));
  ctx.board.ensureBuffer("covered-triangle-visit", 4);  // grown by voxelizeEntries
  if (!on) {
    const uint8_t zero[4] = {0, 0, 0, 0};
    glClearTexImage(direct.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, zero);
    glClearTexImage(difference.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, zero);
    return;
  }
  const Layout layout = layoutOf(ctx.params, ctx.scene);
  const auto origins = cameraPath(ctx.params, ctx.scene, ctx.view).back().origins;
  std::vector<uint32_t> zero(countersBytes(layout.levels) / 4, 0);
  counters.upload(zero.data(), zero.size() * 4);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 12, accum.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 13, counters.id());
  std::vector<Entry> entries;
  std::vector<glm::ivec3> lo(kMaxLevels, glm::ivec3(0)), hi(kMaxLevels, glm::ivec3(0));
  GLuint clear = ctx.shaders.program({"clipmap/clear.comp.glsl"}, atlasFormatDefines(ctx.params));
  setClipUniforms(clear, layout, origins);
  setAccumulatorUniforms(clear, ctx.params, layout.levels);
  setUniform(clear, "u_skipLo", glm::ivec3(0));
  setUniform(clear, "u_skipHi", glm::ivec3(0));
  glUseProgram(clear);
  int64_t cells = 0;
  for (int k = 1; k < layout.levels; ++k) {
    const Box covered = coveredBlock(origins, k, layout.n);
    lo[size_t(k)] = glm::ivec3(covered.lo), hi[size_t(k)] = glm::ivec3(covered.hi);
    if (covered.empty()) continue;
    setUniform(clear, "u_level", k);
    dispatchBox(clear, covered);
    entries.push_back({k, covered, Box{}});
    cells += covered.volume();
  }
  glMemoryBarrier(kAllShaderWrites);
  int reached = 0, triangles = 0;
  voxelizeEntries(ctx, layout, origins, entries, layout.levels, order_.get(ctx.scene), "covered-triangle-visit", reached,
                  triangles);
  GLuint program = ctx.shaders.program({"clipmap/covered_compare.comp.glsl"}, atlasFormatDefines(ctx.params));
  setClipUniforms(program, layout, origins);
  glProgramUniform3iv(program, glGetUniformLocation(program, "u_coveredLo"), kMaxLevels, &lo[0].x);
  glProgramUniform3iv(program, glGetUniformLocation(program, "u_coveredHi"), kMaxLevels, &hi[0].x);
  setAccumulatorUniforms(program, ctx.params, layout.levels);
  glUseProgram(program);
  glBindImageTexture(0, ctx.board.texture("clip-atlas").id(), 0, GL_TRUE, 0, GL_READ_ONLY, atlasFormat(ctx.params));
  glBindImageTexture(1, direct.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, atlasFormat(ctx.params));
  glBindImageTexture(2, difference.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, atlasFormat(ctx.params));
  dispatchCompute(direct.desc().size, {4, 4, 4});
  glMemoryBarrier(kAllShaderWrites);
  for (int unit = 0; unit < 3; ++unit) glBindImageTexture(GLuint(unit), 0, 0, GL_TRUE, 0, GL_READ_ONLY, atlasFormat(ctx.params));
  ctx.stats["covered_cells"] = double(cells);
  std::vector<uint32_t> counted(zero.size());
  auto bytes = counters.download(counted.size() * 4);
  std::memcpy(counted.data(), bytes.data(), counted.size() * 4);
  reportOverflow(ctx, "covered-compare", counted.back());
}

}  // namespace voxlab::clipmap
