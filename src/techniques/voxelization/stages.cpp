#include "techniques/voxelization/stages.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "common/shared.h"
#include "core/error.h"
#include "gpu/shader_library.h"
#include "reference/cpu_voxelizer.h"
#include "scene/gpu_scene.h"
#include "techniques/common/voxel_space.h"
#include "techniques/common/voxelize_stage.h"

namespace voxlab::vox {

ParamDesc methodParam() {
  return ParamDesc::choice("voxelize.method", {"fragment-parallel", "plain", "triangle-parallel", "hybrid"}, 0,
                           "how triangles become voxels: conservative raster, plain raster (holes), one compute "
                           "invocation per triangle, or by triangle size (small: compute, large: raster)");
}

ParamDesc hybridCutoffParam() {
  // Default from the llvmpipe sweep in docs/performance.md: the compute pass was the faster one on
  // every scene, huge triangles included, so every triangle goes to it (1e6 voxels^2 exceeds any
  // triangle's projected area at 512^3). On a GPU a few voxels^2 would be the place to start.
  return ParamDesc::real("voxelize.hybrid-cutoff", 1.0e6, 0.0, 1.0e6,
                         "hybrid: triangles whose area projected along the dominant axis is below this go to the "
                         "triangle-parallel pass, the rest are rasterized (default: all to compute, measured "
                         "fastest on llvmpipe)",
                         "voxels^2");
}

void checkPackableResolution(int resolution) {
  if (resolution > kMaxPackedResolution)
    throw Error("voxel.resolution " + std::to_string(resolution) + " cannot be voxelized: fragments pack voxel "
                "coordinates into 10 bits per axis, so at most " + std::to_string(kMaxPackedResolution) +
                " voxels per axis");
}

// Voxel columns one triangle-parallel invocation visits at most (see VoxelizeStage::execute).
static constexpr uint32_t kChunkColumns = 8192;

static Method methodOf(const ParamSet& params) { return Method(params.getInt("voxelize.method")); }

// --- 1. classify ----------------------------------------------------------------------------------

void ClassifyStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(methodParam());
  b.param(hybridCutoffParam());
  b.readView();
  b.write("triangle-info");
  b.write("triangle-list");
  b.write("triangle-classes");
  b.output("triangle-axes", OutputKind::Image2D, Semantic::Color,
           "triangles coloured by the axis they are projected along (x red, y green, z blue)");
  b.texture("triangle-axes", [](const ParamSet&, const ViewState& v) { return triangleAxesDesc(v); });
}

void ClassifyStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  checkPackableResolution(res);
  const Method method = methodOf(ctx.params);
  VoxelSpace space = VoxelSpace::fromScene(ctx.scene, res);
  ctx.board.setVoxelSpace(space.box());  // every later volume of the technique sits in this box
  const size_t triangles = ctx.scene.triangleCount();

  // Material index per triangle (bits 0-23); the shader adds the class bit.
  std::vector<uint32_t> info(std::max<size_t>(triangles, 1), 0u);
  for (const DrawRange& d : ctx.scene.draws)
    for (uint32_t t = d.firstIndex / 3; t < (d.firstIndex + d.indexCount) / 3; ++t) info[t] = d.material;
  Buffer& infoBuffer = ctx.board.ensureBuffer("triangle-info", info.size() * 4);
  infoBuffer.upload(info.data(), info.size() * 4);
  // Two lists (classify.comp.glsl): every compute triangle, then those with more than one chunk.
  Buffer& list = ctx.board.ensureBuffer("triangle-list", info.size() * 8);
  Buffer& counts = ctx.board.ensureBuffer("triangle-classes", 32);
  const uint32_t zero[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  counts.upload(zero, 32);

  GLuint program = ctx.shaders.program({"voxelization/classify.comp.glsl"});
  space.setUniforms(program);
  setUniform(program, "u_triangleCount", unsigned(triangles));
  setUniform(program, "u_mode", method == Method::TriangleParallel ? 1 : (method == Method::Hybrid ? 2 : 0));
  setUniform(program, "u_cutoff", ctx.params.getFloat("voxelize.hybrid-cutoff"));
  setUniform(program, "u_chunkColumns", unsigned(kChunkColumns));
  glUseProgram(program);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_SCENE_VERTICES, ctx.gpuScene.vertices().id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_SCENE_INDICES, ctx.gpuScene.indices().id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_TRIANGLE_INFO, infoBuffer.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_TRIANGLE_LIST, list.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_CLASS_COUNTS, counts.id());
  dispatchCompute({int(triangles), 1, 1}, {64, 1, 1});
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);

  uint32_t c[8];
  auto bytes = counts.download(32);
  std::memcpy(c, bytes.data(), 32);
  ctx.stats["triangles"] = double(triangles);
  ctx.stats["triangles_axis_x"] = c[0];
  ctx.stats["triangles_axis_y"] = c[1];
  ctx.stats["triangles_axis_z"] = c[2];
  ctx.stats["triangles_degenerate"] = c[3];
  ctx.stats["triangles_small_compute"] = c[4];
  ctx.stats["triangles_large_raster"] = c[5];

  renderTriangleAxes(ctx, "triangle-axes");
}

// --- 2. voxelize ----------------------------------------------------------------------------------

void VoxelizeStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(methodParam());
  b.read("triangle-info");
  b.read("triangle-list");
  b.read("triangle-classes");
  b.write("fragments.count");
  b.output("fragments", OutputKind::Buffer, Semantic::Points,
           "voxel fragments: packed voxel coordinates, albedo, normal, emission")
      .layout = voxelFragmentLayout("fragments.count");
  declareFragmentPool(b);
}

void VoxelizeStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  checkPackableResolution(res);
  const Method method = methodOf(ctx.params);
  VoxelSpace space = VoxelSpace::fromScene(ctx.scene, res);
  // The classification's counters (one readback): [4] triangles listed for the compute pass,
  // [5] triangles left to the raster pass.
  uint32_t classes[8];
  {
    auto bytes = ctx.board.buffer("triangle-classes").download(32);
    std::memcpy(classes, bytes.data(), 32);
  }
  const uint32_t listCount = classes[4], rasterCount = classes[5];
  // The compute pass splits each triangle's voxel columns into chunks, one invocation per
  // (triangle, chunk): llvmpipe ends a shader invocation's loops after 65535 iterations in all, and
  // a chunk costs at most 5 iterations per column (triangle_parallel.comp.glsl). classes[6] bounds
  // the columns of the largest listed triangle, classes[7] counts the triangles with more than one
  // chunk (listed again from entry triangleCount on).
  const int chunks = int(std::max<uint32_t>(1, (classes[6] + kChunkColumns - 1) / kChunkColumns));
  const uint32_t multiChunkCount = classes[7];
  // The hybrid skips a pass that has no triangles: an empty raster pass would still run every
  // triangle through the vertex and geometry shaders only to drop it there (single-threaded
  // stages on llvmpipe), and an empty compute pass would cost a dispatch for nothing.
  const bool raster = method != Method::TriangleParallel && (method != Method::Hybrid || rasterCount > 0);
  const bool compute = (method == Method::TriangleParallel || method == Method::Hybrid) && listCount > 0;

  GLuint rasterProgram = 0;
  if (raster) {
    rasterProgram = ctx.shaders.program(
        {"common/world.vert.glsl", "vct_grid/voxelize.geom.glsl", "vct_grid/voxelize.frag.glsl"},
        method == Method::Hybrid ? "#define VOXLAB_SKIP_SMALL_TRIANGLES 1\n" : "");
    space.setUniforms(rasterProgram);
    setUniform(rasterProgram, "u_conservative", method == Method::Plain ? 0 : 1);
  }
  GLuint computeProgram = 0;
  if (compute) {
    computeProgram = ctx.shaders.program({"voxelization/triangle_parallel.comp.glsl"});
    space.setUniforms(computeProgram);
    setUniform(computeProgram, "u_chunkColumns", unsigned(kChunkColumns));
  }

  uint32_t afterRaster = 0;
  size_t capacity = 0;
  const uint32_t produced = fillFragmentList(ctx, res, [&](uint32_t cap) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_TRIANGLE_INFO, ctx.board.buffer("triangle-info").id());
    if (raster) {
      // Fragment-parallel: the conservative raster pass of vct-grid (hybrid: large triangles only).
      setUniform(rasterProgram, "u_capacity", cap);
      rasterizeVoxelFragments(ctx, rasterProgram, res);
      afterRaster = readCounter(ctx.board.buffer("fragments.count"));
    }
    if (compute) {
      // Triangle-parallel: one invocation per listed triangle, appending to the same list.
      setUniform(computeProgram, "u_capacity", cap);
      glUseProgram(computeProgram);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_MATERIALS, ctx.gpuScene.materials().id());
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_SCENE_VERTICES, ctx.gpuScene.vertices().id());
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_SCENE_INDICES, ctx.gpuScene.indices().id());
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_TRIANGLE_LIST, ctx.board.buffer("triangle-list").id());
      // Chunk 0 of every listed triangle, then chunks 1.. of those that have more.
      setUniform(computeProgram, "u_listBase", 0u);
      setUniform(computeProgram, "u_listCount", unsigned(listCount));
      setUniform(computeProgram, "u_firstChunk", 0u);
      dispatchCompute({int(listCount), 1, 1}, {64, 1, 1});
      if (chunks > 1 && multiChunkCount > 0) {
        setUniform(computeProgram, "u_listBase", unsigned(ctx.scene.triangleCount()));
        setUniform(computeProgram, "u_listCount", unsigned(multiChunkCount));
        setUniform(computeProgram, "u_firstChunk", 1u);
        dispatchCompute({int(multiChunkCount), chunks - 1, 1}, {64, 1, 1});
      }
      glMemoryBarrier(GL_ATOMIC_COUNTER_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    }
  }, capacity);

  ctx.stats["fragments"] = produced;
  ctx.stats["fragments_raster"] = afterRaster;
  ctx.stats["fragments_compute"] = double(produced - afterRaster);
  ctx.stats["fragment_capacity"] = double(capacity);
  ctx.stats["raster_pass"] = raster ? 1.0 : 0.0;
  ctx.stats["compute_pass"] = compute ? 1.0 : 0.0;
  ctx.stats["compute_chunks"] = compute ? double(chunks) : 0.0;
  ctx.stats["voxel_size_m"] = space.voxelSize;
}

// --- 3. occupancy ---------------------------------------------------------------------------------

static TextureDesc volumeDesc(int res, GLenum format) {
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = format;
  d.size = {res, res, res};
  d.levels = 1;
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}

void OccupancyStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.read("fragments");
  b.read("fragments.count");
  b.write("occupancy.unique");
  b.output("occupancy", OutputKind::Volume3D, Semantic::Occupancy,
           "fragments per voxel (r32ui); non-zero = occupied");
  b.texture("occupancy", [](const ParamSet& p, const ViewState&) {
    return volumeDesc(p.getInt("voxel.resolution"), GL_R32UI);
  });
}

void OccupancyStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  Texture& grid = ctx.board.ensureTexture("occupancy", volumeDesc(res, GL_R32UI));
  const uint32_t zero = 0;
  glClearTexImage(grid.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  Buffer& unique = ctx.board.ensureBuffer("occupancy.unique", 4);
  unique.upload(&zero, 4);
  const Buffer& fragments = ctx.board.buffer("fragments");
  const uint32_t count = voxelFragmentCount(ctx.board);

  GLuint program = ctx.shaders.program({"voxelization/occupancy.comp.glsl"});
  setUniform(program, "u_fragmentCount", unsigned(count));
  glUseProgram(program);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, fragments.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_CLASS_COUNTS, unique.id());
  glBindImageTexture(0, grid.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
  dispatchCompute({int(count), 1, 1}, {64, 1, 1});
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT |
                  GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  glBindImageTexture(0, 0, 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
  const uint32_t voxels = readCounter(unique);
  ctx.stats["fragments"] = count;
  ctx.stats["unique_voxels"] = voxels;
  ctx.stats["duplicate_fragments"] = double(count) - double(voxels);
}

// --- 4. compare -----------------------------------------------------------------------------------

void CompareStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.read("occupancy");
  b.output("reference", OutputKind::Volume3D, Semantic::Occupancy,
           "CPU reference voxels: every voxel whose closed box a triangle overlaps (exact SAT, double)");
  b.output("difference", OutputKind::Volume3D, Semantic::Scalar,
           "0 = method and reference agree, 1 = missed by the method, 2 = added by the method");
  b.texture("reference", [](const ParamSet& p, const ViewState&) { return volumeDesc(p.getInt("voxel.resolution"), GL_R8); });
  b.texture("difference", [](const ParamSet& p, const ViewState&) {
    return volumeDesc(p.getInt("voxel.resolution"), GL_R32F);
  });
}

void CompareStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  const std::vector<uint32_t> keys = referenceVoxelSet(ctx.scene, VoxelSpace::fromScene(ctx.scene, res));
  const size_t n = size_t(res) * res * res;
  std::vector<uint8_t> reference(n, 0);
  for (uint32_t k : keys) {
    glm::ivec3 v = unpackVoxelKey(k);
    reference[(size_t(v.z) * res + v.y) * res + v.x] = 255;
  }
  std::vector<uint32_t> occupancy(n, 0);
  glGetTextureImage(ctx.board.texture("occupancy").id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT,
                    GLsizei(n * 4), occupancy.data());
  std::vector<float> difference(n, 0.0f);
  size_t missed = 0, added = 0;
  for (size_t i = 0; i < n; ++i) {
    const bool ref = reference[i] != 0, gpu = occupancy[i] != 0;
    if (ref && !gpu) { difference[i] = 1.0f; ++missed; }
    if (gpu && !ref) { difference[i] = 2.0f; ++added; }
  }
  Texture& refTex = ctx.board.ensureTexture("reference", volumeDesc(res, GL_R8));
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage3D(refTex.id(), 0, 0, 0, 0, res, res, res, GL_RED, GL_UNSIGNED_BYTE, reference.data());
  Texture& diffTex = ctx.board.ensureTexture("difference", volumeDesc(res, GL_R32F));
  glTextureSubImage3D(diffTex.id(), 0, 0, 0, 0, res, res, res, GL_RED, GL_FLOAT, difference.data());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  ctx.stats["reference_voxels"] = double(keys.size());
  ctx.stats["missed_voxels"] = double(missed);
  ctx.stats["added_voxels"] = double(added);
}

}  // namespace voxlab::vox
