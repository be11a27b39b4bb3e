// Light injection and the occlusion fix (seed 000 section 4.2.1).
#include <algorithm>
#include <cstring>
#include <string>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "techniques/common/voxel_space.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/vct_grid/stages.h"

namespace voxlab::vct {

static TextureDesc radianceGridDesc(int res, int levels) {
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = GL_RGBA8;
  d.size = {res, res, res};
  d.levels = levels;
  d.minFilter = levels == 1 ? GL_LINEAR : GL_LINEAR_MIPMAP_LINEAR;
  return d;
}

void InjectStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(ParamDesc::choice("inject.mode", {"direct-light", "uniform"}, 0,
                            "what voxels hold: the scene's direct light, or one uniform radiance (a furnace test)"));
  b.param(ParamDesc::real("inject.uniform-radiance", 0.5, 0.0, 1.0,
                          "radiance every voxel gets in uniform mode", "W/(m^2 sr)"));
  b.read("fragments");
  b.read("fragments.count");
  b.read("shadow-map");
  b.read("light");
  b.output("radiance-injected", OutputKind::Volume3D, Semantic::Color,
           "averaged outgoing radiance per voxel; alpha = fragments averaged / 255");
  b.texture("radiance-injected", [](const ParamSet& p, const ViewState&) {
    return radianceGridDesc(p.getInt("voxel.resolution"), 1);
  });
}

void InjectStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  VoxelSpace space = VoxelSpace::fromScene(ctx.scene, res);
  Texture& grid = ctx.board.ensureTexture("radiance-injected", radianceGridDesc(res, 1));
  const uint8_t zero[4] = {0, 0, 0, 0};
  glClearTexImage(grid.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, zero);

  // An r32ui view of the RGBA8 grid: image atomics work on 32-bit integers only.
  GLuint view = 0;
  glGenTextures(1, &view);
  glTextureView(view, GL_TEXTURE_3D, grid.id(), GL_R32UI, 0, 1, 0, 1);
  glObjectLabel(GL_TEXTURE, view, -1, "radiance-injected.r32ui-view");

  uint32_t count = voxelFragmentCount(ctx.board);

  GLuint program = ctx.shaders.program({"vct_grid/inject.comp.glsl"});
  space.setUniforms(program);
  setUniform(program, "u_fragmentCount", unsigned(count));
  setUniform(program, "u_mode", ctx.params.getInt("inject.mode"));
  setUniform(program, "u_uniformRadiance", glm::vec3(ctx.params.getFloat("inject.uniform-radiance")));
  glUseProgram(program);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, ctx.board.buffer("fragments").id());
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  glBindTextureUnit(2, ctx.board.texture("shadow-map").id());
  glBindImageTexture(0, view, 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
  dispatchCompute({int(count), 1, 1}, {64, 1, 1});
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
  glBindImageTexture(0, 0, 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
  glDeleteTextures(1, &view);
  ctx.stats["fragments_injected"] = count;
}

void OcclusionFixStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.read("radiance-injected");
  b.read("fragments");
  b.read("fragments.count");
  b.output("radiance-opaque", OutputKind::Volume3D, Semantic::Color,
           "radiance per voxel with alpha 1 in every occupied voxel");
  b.texture("radiance-opaque", [](const ParamSet& p, const ViewState&) {
    return radianceGridDesc(p.getInt("voxel.resolution"), 1);
  });
}

void OcclusionFixStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  Texture& src = ctx.board.texture("radiance-injected");
  Texture& dst = ctx.board.ensureTexture("radiance-opaque", radianceGridDesc(res, 1));
  const uint8_t zero[4] = {0, 0, 0, 0};
  glClearTexImage(dst.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, zero);
  // Only voxels that received fragments can be non-empty: visit those instead of the whole grid.
  uint32_t count = voxelFragmentCount(ctx.board);
  GLuint program = ctx.shaders.program({"vct_grid/occlusion_fix.comp.glsl"});
  setUniform(program, "u_fragmentCount", unsigned(count));
  glUseProgram(program);
  glBindTextureUnit(0, src.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, ctx.board.buffer("fragments").id());
  glBindImageTexture(0, dst.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA8);
  dispatchCompute({int(count), 1, 1}, {64, 1, 1});
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
}

const char* const kDirectionalVolumes[6] = {"radiance-dir+x", "radiance-dir-x", "radiance-dir+y",
                                           "radiance-dir-y", "radiance-dir+z", "radiance-dir-z"};

ParamDesc mipmapModeParam() {
  return ParamDesc::choice("mipmap.mode", {"isotropic", "anisotropic"}, 0,
                           "isotropic: one average per 2x2x2 block; anisotropic: six volumes, one per travel direction, "
                           "compositing front to back before averaging (Crassin et al.)");
}

// Edge of the six directional volumes: half the grid with anisotropic mips, one voxel without.
static int directionalSize(const ParamSet& p) {
  return p.getChoice("mipmap.mode") == "anisotropic" ? std::max(p.getInt("voxel.resolution") / 2, 1) : 1;
}

void MipmapStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(mipmapModeParam());
  b.read("radiance-opaque");
  b.output("radiance", OutputKind::Volume3D, Semantic::Color,
           "the prefiltered radiance grid: level 0 = the voxels, each further level averages 2x2x2");
  b.output("opacity", OutputKind::Volume3D, Semantic::Opacity, "alpha of the prefiltered grid per level")
      .resource = "radiance";
  const std::string prefix = "radiance-dir";  // every directional volume's name is prefix + "+x" etc.
  for (const char* name : kDirectionalVolumes)
    b.output(name, OutputKind::Volume3D, Semantic::Color,
             "anisotropic levels 1.. as seen by a cone travelling along " + std::string(name).substr(prefix.size()) +
                 " (one voxel, empty, when mipmap.mode is isotropic)")
        .placeholderUnless = "mipmap.mode=anisotropic";
  b.texture("radiance", [](const ParamSet& p, const ViewState&) {
    return radianceGridDesc(p.getInt("voxel.resolution"), 0);
  });
  for (const char* name : kDirectionalVolumes)
    b.texture(name, [](const ParamSet& p, const ViewState&) { return radianceGridDesc(directionalSize(p), 0); });
}

// One iteration per level: iteration k builds level k+1 of the grid from level k (and, with
// anisotropic mips, level k of the six directional volumes, whose level 0 is level 1 of the
// hierarchy). Iteration 0 also copies the voxels into level 0 and clears the coarser levels, so a
// stepped run shows exactly the levels built so far.
int MipmapStage::iterations(const ParamSet& params) const {
  int res = params.getInt("voxel.resolution"), levels = 0;
  while (res > 1) res >>= 1, ++levels;
  return std::max(levels, 1);
}

void MipmapStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  const bool anisotropic = ctx.params.getChoice("mipmap.mode") == "anisotropic";
  const int half = directionalSize(ctx.params);
  const int k = ctx.iteration;
  const uint8_t zero[4] = {0, 0, 0, 0};
  Texture& src = ctx.board.texture("radiance-opaque");
  Texture& grid = ctx.board.ensureTexture("radiance", radianceGridDesc(res, 0));
  Texture* dirs[6];
  for (int d = 0; d < 6; ++d) dirs[d] = &ctx.board.ensureTexture(kDirectionalVolumes[d], radianceGridDesc(half, 0));
  if (k == 0) {
    glCopyImageSubData(src.id(), GL_TEXTURE_3D, 0, 0, 0, 0, grid.id(), GL_TEXTURE_3D, 0, 0, 0, 0, res, res, res);
    for (int level = 1; level < grid.levels(); ++level)
      glClearTexImage(grid.id(), level, GL_RGBA, GL_UNSIGNED_BYTE, zero);
    // In isotropic mode the directional volumes are one empty voxel each: the outputs exist but
    // cost nothing.
    for (int d = 0; d < 6; ++d)
      for (int level = 0; level < dirs[d]->levels(); ++level)
        glClearTexImage(dirs[d]->id(), level, GL_RGBA, GL_UNSIGNED_BYTE, zero);
  }

  if (k + 1 < grid.levels()) {
    GLuint program = ctx.shaders.program({"vct_grid/mipmap.comp.glsl"});
    glUseProgram(program);
    glBindTextureUnit(0, grid.id());
    setUniform(program, "u_sourceLevel", k);
    glBindImageTexture(0, grid.id(), k + 1, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA8);
    dispatchCompute(grid.levelSize(k + 1), {4, 4, 4});
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
  }
  if (anisotropic && k < dirs[0]->levels()) {
    GLuint aniso = ctx.shaders.program({"vct_grid/mipmap_anisotropic.comp.glsl"});
    glUseProgram(aniso);
    glBindTextureUnit(0, src.id());
    for (int d = 0; d < 6; ++d) glBindTextureUnit(1 + d, dirs[d]->id());
    setUniform(aniso, "u_fromIsotropic", k == 0 ? 1 : 0);
    setUniform(aniso, "u_sourceLevel", std::max(k - 1, 0));
    for (int d = 0; d < 6; ++d) glBindImageTexture(d, dirs[d]->id(), k, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA8);
    dispatchCompute(dirs[0]->levelSize(k), {4, 4, 4});
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
  }
  double bytes = double(grid.byteSize());
  for (auto* d : dirs) bytes += double(d->byteSize());
  ctx.stats["levels"] = grid.levels();
  ctx.stats["levels_built"] = std::min(k + 2, grid.levels());
  ctx.stats["anisotropic"] = anisotropic ? 1 : 0;
  ctx.stats["bytes"] = bytes;
}

}  // namespace voxlab::vct
