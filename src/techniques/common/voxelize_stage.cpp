#include "techniques/common/voxelize_stage.h"

#include <algorithm>
#include <cstring>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "graph/scene_inputs.h"
#include "graph/technique.h"
#include "scene/gpu_scene.h"
#include "techniques/common/triangle_voxelizer.h"
#include "techniques/common/voxel_space.h"

namespace voxlab {

ParamDesc voxelResolutionParam() {
  return ParamDesc::integer("voxel.resolution", 128, 16, 512, "voxels along each axis of the grid", "voxels").pow2();
}

namespace {

// The static part's totals, for the voxelize stage's statistics: records, then triangles per
// projection axis.
constexpr const char* kStaticSummary = "fragments.static.summary";
const VoxelizeScratch& staticScratch() {
  static const VoxelizeScratch scratch = VoxelizeScratch::prefixed("voxelize-static");
  return scratch;
}

void declareVoxelizeParams(StageBuilder& b) {
  b.param(voxelResolutionParam());
  // The exact methods give the same voxels. By triangle size (docs/performance.md): the compute
  // pass was measured 10x faster than the raster pass on Sponza's small triangles at 128^3 with
  // llvmpipe, the raster pass 2x faster on the Cornell box's walls.
  b.param(voxelizeMethodParam(VoxelizeMethod::Hybrid));
  b.param(hybridCutoffParam());
}

struct PartResult {
  uint32_t records = 0;  // the list's records after the passes (prefix included)
  size_t capacity = 0;
  uint32_t axes[3] = {0, 0, 0};  // triangles of the part per projection axis
};

// Classifies and voxelizes the triangles of 'part' into 'list'; a part without triangles runs no
// pass (the list then holds its prefix alone).
PartResult voxelizePart(StageContext& ctx, const VoxelSpace& space, TrianglePart part, size_t triangles,
                        const FragmentList& list, const VoxelizeScratch& scratch) {
  const VoxelizeMethod method = voxelizeMethodOf(ctx.params);
  const int res = space.resolution;
  PartResult r;
  if (triangles == 0) {
    r.records = fillFragmentList(ctx, res, [](uint32_t) {}, r.capacity, list, scratch);
    return r;
  }
  classifyTriangles(ctx, space, method, float(ctx.params.getFloat("voxelize.hybrid-cutoff")), part, scratch);
  const TriangleClasses classes = readTriangleClasses(ctx, scratch);
  r.records = fillFragmentList(ctx, res, [&](uint32_t cap) {
    voxelizeTriangles(ctx, space, method, classes, cap, part, scratch, list.count);
  }, r.capacity, list, scratch);
  // Triangles per projection axis: counted by the raster pass's geometry shader, else by the
  // classification (the same dominant axis).
  for (int a = 0; a < 3; ++a) r.axes[a] = classes.axis[a];
  if (methodRasterizes(method, classes) && !methodComputes(method, classes))
    for (int a = 0; a < 3; ++a) r.axes[a] = readCounter(ctx.board.buffer(scratch.axisCounts), size_t(a) * 4);
  return r;
}

size_t staticTriangleCount(const Scene& scene) { return scene.triangleCount() - scene.movingTriangleCount(); }

}  // namespace

void addVoxelizeStages(Technique& technique) {
  technique.add<VoxelizeStaticStage>();
  technique.add<VoxelizeStage>();
  technique.add<TriangleAxesStage>();
}

void VoxelizeStaticStage::declare(StageBuilder& b) const {
  b.read(kSceneStaticGeometryInput);  // voxelizes the triangles no animation moves
  declareVoxelizeParams(b);
  b.write("fragments.static");
  b.write("fragments.static.count");
  b.write(kStaticSummary);
  staticScratch().declareWrites(b);
  declareFragmentPool(b, "fragments.static");
}

void VoxelizeStaticStage::execute(StageContext& ctx) {
  const VoxelSpace space = VoxelSpace::fromScene(ctx.scene, ctx.params.getInt("voxel.resolution"));
  ctx.board.setVoxelSpace(space.box());  // every later volume of the technique sits in this box
  const size_t triangles = staticTriangleCount(ctx.scene);
  const PartResult r = voxelizePart(ctx, space, TrianglePart::Static, triangles,
                                    FragmentList{"fragments.static", "fragments.static.count", nullptr, 0},
                                    staticScratch());
  const uint32_t summary[4] = {std::min<uint32_t>(r.records, uint32_t(r.capacity)), r.axes[0], r.axes[1], r.axes[2]};
  ctx.board.ensureBuffer(kStaticSummary, sizeof(summary)).upload(summary, sizeof(summary));
  ctx.stats["fragments"] = summary[0];
  ctx.stats["triangles"] = double(triangles);
}

void VoxelizeStage::declare(StageBuilder& b) const {
  b.read(kSceneDynamicGeometryInput);  // voxelizes the triangles animations move
  b.read("fragments.static");
  b.read(kStaticSummary);
  declareVoxelizeParams(b);
  b.write("fragments.count");
  VoxelizeScratch().declareWrites(b);
  b.output("fragments", OutputKind::Buffer, Semantic::Points,
           "voxel fragments: packed voxel coordinates, albedo, normal, emission")
      .layout = voxelFragmentLayout("fragments.count");
  declareFragmentPool(b, "fragments", kMergedFragmentsStart);
}

void VoxelizeStage::execute(StageContext& ctx) {
  const VoxelSpace space = VoxelSpace::fromScene(ctx.scene, ctx.params.getInt("voxel.resolution"));
  ctx.board.setVoxelSpace(space.box());
  uint32_t statics[4];
  auto bytes = ctx.board.buffer(kStaticSummary).download(sizeof(statics));
  std::memcpy(statics, bytes.data(), sizeof(statics));
  const size_t moving = ctx.scene.movingTriangleCount();
  FragmentList list;
  list.prefix = &ctx.board.buffer("fragments.static");
  list.prefixCount = statics[0];
  // The still triangles' records and a share of the whole scene's estimate for the moving ones
  // (the list grows and the passes run again when that is too small).
  const size_t movingGuess =
      moving ? estimateFragments(ctx.scene, space) * moving / std::max<size_t>(1, ctx.scene.triangleCount()) : 0;
  list.firstCapacity = std::max(kMergedFragmentsStart, size_t(statics[0]) + movingGuess + 1);
  const PartResult r = voxelizePart(ctx, space, TrianglePart::Dynamic, moving, list, VoxelizeScratch());

  ctx.stats["fragments"] = r.records;
  ctx.stats["fragments_static"] = statics[0];
  ctx.stats["fragments_dynamic"] = double(r.records) - double(statics[0]);
  ctx.stats["fragment_capacity"] = double(r.capacity);
  ctx.stats["triangles"] = double(ctx.scene.triangleCount());
  ctx.stats["triangles_dynamic"] = double(moving);
  ctx.stats["triangles_axis_x"] = statics[1] + r.axes[0];
  ctx.stats["triangles_axis_y"] = statics[2] + r.axes[1];
  ctx.stats["triangles_axis_z"] = statics[3] + r.axes[2];
  ctx.stats["voxel_size_m"] = space.voxelSize;
}

void TriangleAxesStage::declare(StageBuilder& b) const {
  b.read(kSceneGeometryInput);  // draws every triangle
  b.readView();
  b.output("triangle-axes", OutputKind::Image2D, Semantic::Color,
           "triangles coloured by the axis they are projected along (x red, y green, z blue)").alongside = true;
  b.texture("triangle-axes", [](const ParamSet&, const ViewState& v) { return triangleAxesDesc(v); });
}

void TriangleAxesStage::execute(StageContext& ctx) { renderTriangleAxes(ctx, "triangle-axes"); }

void declareFragmentPool(StageBuilder& b, const std::string& records, size_t startRecords) {
  b.buffer(records, [startRecords](const ParamSet& p, const ViewState&) {
    return (startRecords ? startRecords : fragmentPoolStart(p.getInt("voxel.resolution"))) * sizeof(gpu::VoxelFragment);
  }, /*pool=*/true);
}

TextureDesc triangleAxesDesc(const ViewState& view) {
  TextureDesc color;
  color.size = {view.width, view.height, 1};
  return color;
}

uint32_t readCounter(const Buffer& buffer, size_t offset) {
  uint32_t v = 0;
  auto bytes = buffer.download(4, offset);
  std::memcpy(&v, bytes.data(), 4);
  return v;
}

uint32_t fillFragmentList(StageContext& ctx, int resolution, const std::function<void(uint32_t)>& passes,
                          size_t& capacity, const FragmentList& list, const VoxelizeScratch& scratch) {
  Buffer& counter = ctx.board.ensureBuffer(list.count, 4);
  Buffer& axisCounts = ctx.board.ensureBuffer(scratch.axisCounts, 16);
  // A guess; grown below if too small.
  capacity = list.firstCapacity ? list.firstCapacity
                                : initialFragmentCapacity(ctx.board, ctx.scene, resolution, list.records);
  capacity = std::max<size_t>(capacity, size_t(list.prefixCount) + 1);
  if (ctx.board.hasBuffer(list.records))  // a list already larger is kept as it is
    capacity = std::max(capacity, ctx.board.buffer(list.records).size() / sizeof(gpu::VoxelFragment));
  uint32_t produced = 0;
  for (int attempt = 0; attempt < 2; ++attempt) {
    Buffer& fragments = ctx.board.ensureBuffer(list.records, capacity * sizeof(gpu::VoxelFragment));
    if (list.prefix && list.prefixCount > 0)
      glCopyNamedBufferSubData(list.prefix->id(), fragments.id(), 0, 0,
                               GLsizeiptr(size_t(list.prefixCount) * sizeof(gpu::VoxelFragment)));
    const uint32_t zero[4] = {0, 0, 0, 0};
    counter.upload(&list.prefixCount, 4);
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

void rasterizeVoxelFragments(StageContext& ctx, const GpuScene::ProgramForKind& programFor, int resolution,
                             const std::vector<DrawRange>* ranges) {
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
  ctx.gpuScene.draw(programFor, ranges ? *ranges : ctx.scene.draws);
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
