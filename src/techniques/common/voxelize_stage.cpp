#include "techniques/common/voxelize_stage.h"

#include <algorithm>
#include <cstring>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "scene/gpu_scene.h"
#include "techniques/common/voxel_space.h"

namespace voxlab {

ParamDesc voxelResolutionParam() {
  return ParamDesc::integer("voxel.resolution", 128, 16, 512, "voxels along each axis of the grid", "voxels").pow2();
}

void VoxelizeStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(ParamDesc::boolean("voxelize.conservative", true,
                             "grow triangles by half a pixel and test voxels exactly, so thin and small "
                             "triangles leave no holes (off: plain rasterization)"));
  b.readView();
  b.write("fragments.count");
  b.write("voxelize.axis-counts");
  b.output("fragments", OutputKind::Buffer, Semantic::Points,
           "voxel fragments: packed voxel coordinates, albedo, normal, emission")
      .layout = voxelFragmentLayout("fragments.count");
  b.output("triangle-axes", OutputKind::Image2D, Semantic::Color,
           "triangles coloured by the axis they are projected along (x red, y green, z blue)");
}

void VoxelizeStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  const bool conservative = ctx.params.getBool("voxelize.conservative");
  VoxelSpace space = VoxelSpace::fromScene(ctx.scene, res);
  ctx.board.setVoxelSpace(space.box());  // every later volume of the technique sits in this box

  GLuint program = ctx.shaders.program(
      {"common/world.vert.glsl", "vct_grid/voxelize.geom.glsl", "vct_grid/voxelize.frag.glsl"});
  space.setUniforms(program);
  setUniform(program, "u_conservative", conservative ? 1 : 0);

  Buffer& counter = ctx.board.ensureBuffer("fragments.count", 4);
  Buffer& axisCounts = ctx.board.ensureBuffer("voxelize.axis-counts", 16);
  // Capacity guess; if the counter says more fragments were produced, grow and run again.
  size_t capacity = initialFragmentCapacity(ctx.board, res);

  GLuint fbo = 0;
  glCreateFramebuffers(1, &fbo);
  glNamedFramebufferParameteri(fbo, GL_FRAMEBUFFER_DEFAULT_WIDTH, res);
  glNamedFramebufferParameteri(fbo, GL_FRAMEBUFFER_DEFAULT_HEIGHT, res);
  uint32_t produced = 0;
  for (int attempt = 0; attempt < 2; ++attempt) {
    Buffer& fragments = ctx.board.ensureBuffer("fragments", capacity * sizeof(gpu::VoxelFragment));
    const uint32_t zero[4] = {0, 0, 0, 0};
    counter.upload(zero, 4);
    axisCounts.upload(zero, 16);
    setUniform(program, "u_capacity", unsigned(capacity));
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, res, res);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glBindBufferBase(GL_ATOMIC_COUNTER_BUFFER, VOXLAB_BINDING_FRAGMENT_COUNT, counter.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, fragments.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_AXIS_COUNTS, axisCounts.id());
    ctx.gpuScene.draw(program);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glMemoryBarrier(GL_ATOMIC_COUNTER_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    auto bytes = counter.download(4);
    std::memcpy(&produced, bytes.data(), 4);
    if (produced <= capacity) break;
    capacity = produced;
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glDeleteFramebuffers(1, &fbo);

  uint32_t axes[4];
  auto a = axisCounts.download(16);
  std::memcpy(axes, a.data(), 16);
  ctx.stats["fragments"] = produced;
  ctx.stats["fragment_capacity"] = double(capacity);
  ctx.stats["triangles"] = double(ctx.scene.triangleCount());
  ctx.stats["triangles_axis_x"] = axes[0];
  ctx.stats["triangles_axis_y"] = axes[1];
  ctx.stats["triangles_axis_z"] = axes[2];
  ctx.stats["voxel_size_m"] = space.voxelSize;

  renderTriangleAxes(ctx, "triangle-axes");
}

void renderTriangleAxes(StageContext& ctx, const std::string& resource) {
  TextureDesc color;
  color.size = {ctx.view.width, ctx.view.height, 1};
  Texture& image = ctx.board.ensureTexture(resource, color);
  TextureDesc depthDesc;
  depthDesc.format = GL_DEPTH_COMPONENT32F;
  depthDesc.size = color.size;
  Texture depth(resource + ".depth", depthDesc);
  Framebuffer fb(resource + ".fbo");
  fb.attach(GL_COLOR_ATTACHMENT0, image);
  fb.attach(GL_DEPTH_ATTACHMENT, depth);
  fb.setDrawBuffers(1);
  fb.checkComplete();
  GLuint axisProgram = ctx.shaders.program(
      {"common/camera.vert.glsl", "vct_grid/dominant_axis.geom.glsl", "vct_grid/dominant_axis.frag.glsl"});
  setUniform(axisProgram, "u_viewProj", ctx.view.viewProjection());
  setUniform(axisProgram, "u_viewDir", glm::normalize(-glm::vec3(glm::transpose(ctx.view.view)[2])));
  glBindFramebuffer(GL_FRAMEBUFFER, fb.id());
  glViewport(0, 0, ctx.view.width, ctx.view.height);
  const float black[4] = {0, 0, 0, 1};
  const float far = 1.0f;
  glClearNamedFramebufferfv(fb.id(), GL_COLOR, 0, black);
  glClearNamedFramebufferfv(fb.id(), GL_DEPTH, 0, &far);
  glEnable(GL_DEPTH_TEST);
  ctx.gpuScene.draw(axisProgram);
  glDisable(GL_DEPTH_TEST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

}  // namespace voxlab
