// Light injection and the occlusion fix (seed 000 section 4.2.1).
#include <cstring>

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

  uint32_t count = 0;
  auto bytes = ctx.board.buffer("fragments.count").download(4);
  std::memcpy(&count, bytes.data(), 4);
  uint32_t capacity = uint32_t(ctx.board.buffer("fragments").size() / sizeof(gpu::VoxelFragment));
  count = std::min(count, capacity);

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
  b.output("radiance-opaque", OutputKind::Volume3D, Semantic::Color,
           "radiance per voxel with alpha 1 in every occupied voxel");
}

void OcclusionFixStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  Texture& src = ctx.board.texture("radiance-injected");
  Texture& dst = ctx.board.ensureTexture("radiance-opaque", radianceGridDesc(res, 1));
  GLuint program = ctx.shaders.program({"vct_grid/occlusion_fix.comp.glsl"});
  glUseProgram(program);
  glBindTextureUnit(0, src.id());
  glBindImageTexture(0, dst.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA8);
  dispatchCompute({res, res, res}, {4, 4, 4});
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
}

void MipmapStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.read("radiance-opaque");
  b.output("radiance", OutputKind::Volume3D, Semantic::Color,
           "the prefiltered radiance grid: level 0 = the voxels, each further level averages 2x2x2");
  b.output("opacity", OutputKind::Volume3D, Semantic::Opacity, "alpha of the prefiltered grid per level")
      .resource = "radiance";
}

void MipmapStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  Texture& src = ctx.board.texture("radiance-opaque");
  Texture& grid = ctx.board.ensureTexture("radiance", radianceGridDesc(res, 0));
  glCopyImageSubData(src.id(), GL_TEXTURE_3D, 0, 0, 0, 0, grid.id(), GL_TEXTURE_3D, 0, 0, 0, 0, res, res, res);
  GLuint program = ctx.shaders.program({"vct_grid/mipmap.comp.glsl"});
  glUseProgram(program);
  glBindTextureUnit(0, grid.id());
  for (int level = 1; level < grid.levels(); ++level) {
    setUniform(program, "u_sourceLevel", level - 1);
    glBindImageTexture(0, grid.id(), level, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA8);
    dispatchCompute(grid.levelSize(level), {4, 4, 4});
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
  }
  glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
  ctx.stats["levels"] = grid.levels();
  ctx.stats["bytes"] = double(grid.byteSize());
}

}  // namespace voxlab::vct
