#include "techniques/common/voxelize_stage.h"
#include "graph/scene_inputs.h"

#include <algorithm>
#include <cstring>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "scene/gpu_scene.h"
#include "techniques/common/triangle_voxelizer.h"
#include "techniques/common/voxel_space.h"

namespace voxlab {

ParamDesc voxelResolutionParam() {
  return ParamDesc::integer("voxel.resolution", 128, 16, 512, "voxels along each axis of the grid", "voxels").pow2();
}

void VoxelizeStage::declare(StageBuilder& b) const {
  b.read(kSceneGeometryInput);  // rasterizes the scene's triangles
  b.param(voxelResolutionParam());
  // The exact methods give the same voxels; triangle-parallel was measured 10x faster than the
  // geometry-shader raster pass on Sponza at 128^3 with llvmpipe (docs/performance.md).
  b.param(voxelizeMethodParam(VoxelizeMethod::TriangleParallel));
  b.param(hybridCutoffParam());
  b.readView();
  b.write("fragments.count");
  b.write("voxelize.axis-counts");
  b.write("triangle-info");
  b.write("triangle-list");
  b.write("triangle-classes");
  b.output("fragments", OutputKind::Buffer, Semantic::Points,
           "voxel fragments: packed voxel coordinates, albedo, normal, emission")
      .layout = voxelFragmentLayout("fragments.count");
  b.output("triangle-axes", OutputKind::Image2D, Semantic::Color,
           "triangles coloured by the axis they are projected along (x red, y green, z blue)").alongside = true;
  declareFragmentPool(b);
  b.texture("triangle-axes", [](const ParamSet&, const ViewState& v) { return triangleAxesDesc(v); });
}

void declareFragmentPool(StageBuilder& b) {
  b.buffer("fragments", [](const ParamSet& p, const ViewState&) {
    return fragmentPoolStart(p.getInt("voxel.resolution")) * sizeof(gpu::VoxelFragment);
  }, /*pool=*/true);
}

TextureDesc triangleAxesDesc(const ViewState& view) {
  TextureDesc color;
  color.size = {view.width, view.height, 1};
  return color;
}

void VoxelizeStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  const VoxelizeMethod method = voxelizeMethodOf(ctx.params);
  VoxelSpace space = VoxelSpace::fromScene(ctx.scene, res);
  ctx.board.setVoxelSpace(space.box());  // every later volume of the technique sits in this box

  // The passes the voxelization technique compares (techniques/common/triangle_voxelizer.h).
  classifyTriangles(ctx, space, method, float(ctx.params.getFloat("voxelize.hybrid-cutoff")));
  const TriangleClasses classes = readTriangleClasses(ctx);
  size_t capacity = 0;
  const uint32_t produced = fillFragmentList(ctx, res, [&](uint32_t cap) {
    voxelizeTriangles(ctx, space, method, classes, cap);
  }, capacity);

  // Triangles per projection axis: counted by the raster pass's geometry shader, else by the
  // classification (the same dominant axis).
  const Buffer& axisCounts = ctx.board.buffer("voxelize.axis-counts");
  uint32_t axes[3] = {classes.axis[0], classes.axis[1], classes.axis[2]};
  if (methodRasterizes(method, classes) && !methodComputes(method, classes))
    for (int a = 0; a < 3; ++a) axes[a] = readCounter(axisCounts, size_t(a) * 4);
  ctx.stats["fragments"] = produced;
  ctx.stats["fragment_capacity"] = double(capacity);
  ctx.stats["triangles"] = double(ctx.scene.triangleCount());
  ctx.stats["triangles_axis_x"] = axes[0];
  ctx.stats["triangles_axis_y"] = axes[1];
  ctx.stats["triangles_axis_z"] = axes[2];
  ctx.stats["voxel_size_m"] = space.voxelSize;

  renderTriangleAxes(ctx, "triangle-axes");
}

uint32_t readCounter(const Buffer& buffer, size_t offset) {
  uint32_t v = 0;
  auto bytes = buffer.download(4, offset);
  std::memcpy(&v, bytes.data(), 4);
  return v;
}

uint32_t fillFragmentList(StageContext& ctx, int resolution, const std::function<void(uint32_t)>& passes,
                          size_t& capacity) {
  Buffer& counter = ctx.board.ensureBuffer("fragments.count", 4);
  Buffer& axisCounts = ctx.board.ensureBuffer("voxelize.axis-counts", 16);
  capacity = initialFragmentCapacity(ctx.board, ctx.scene, resolution);  // a guess; grown below if too small
  uint32_t produced = 0;
  for (int attempt = 0; attempt < 2; ++attempt) {
    Buffer& fragments = ctx.board.ensureBuffer("fragments", capacity * sizeof(gpu::VoxelFragment));
    const uint32_t zero[4] = {0, 0, 0, 0};
    counter.upload(zero, 4);
    axisCounts.upload(zero, 16);
    glBindBufferBase(GL_ATOMIC_COUNTER_BUFFER, VOXLAB_BINDING_FRAGMENT_COUNT, counter.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, fragments.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_AXIS_COUNTS, axisCounts.id());
    passes(uint32_t(capacity));
    produced = readCounter(counter);
    if (produced <= capacity) break;
    capacity = produced;
  }
  return produced;
}

void rasterizeVoxelFragments(StageContext& ctx, GLuint program, int resolution) {
  GLuint fbo = 0;
  glCreateFramebuffers(1, &fbo);
  glObjectLabel(GL_FRAMEBUFFER, fbo, -1, "voxelize.fbo");
  glNamedFramebufferParameteri(fbo, GL_FRAMEBUFFER_DEFAULT_WIDTH, resolution);
  glNamedFramebufferParameteri(fbo, GL_FRAMEBUFFER_DEFAULT_HEIGHT, resolution);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, resolution, resolution);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  ctx.gpuScene.draw(program);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glDeleteFramebuffers(1, &fbo);
  glMemoryBarrier(GL_ATOMIC_COUNTER_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

void renderTriangleAxes(StageContext& ctx, const std::string& resource) {
  TextureDesc color = triangleAxesDesc(ctx.view);
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
      {"common/camera.vert.glsl", "common/dominant_axis.geom.glsl", "common/dominant_axis.frag.glsl"});
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
