#include "techniques/common/triangle_voxelizer.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "scene/gpu_scene.h"
#include "techniques/common/voxelize_stage.h"

namespace voxlab {

ParamDesc voxelizeMethodParam(VoxelizeMethod defaultMethod) {
  return ParamDesc::choice("voxelize.method", {"fragment-parallel", "plain", "triangle-parallel", "hybrid"},
                           int(defaultMethod),
                           "how triangles become voxels: conservative raster, plain raster (holes), one compute "
                           "invocation per triangle, or by triangle size (small: compute, large: raster)");
}

ParamDesc hybridCutoffParam() {
  // Default from the llvmpipe sweep in docs/performance.md: a wall of the Cornell box (thousands of
  // voxels^2) rasterizes 2x faster than one compute invocation loops over its columns, while the
  // compute pass wins on small triangles; 1024 voxels^2 sits between the two on the suite.
  return ParamDesc::real("voxelize.hybrid-cutoff", 1024.0, 0.0, 1.0e6,
                         "hybrid: triangles whose area projected along the dominant axis is below this go to the "
                         "triangle-parallel pass, the rest are rasterized",
                         "voxels^2");
}

VoxelizeMethod voxelizeMethodOf(const ParamSet& params) { return VoxelizeMethod(params.getInt("voxelize.method")); }

VoxelizeScratch VoxelizeScratch::prefixed(const std::string& prefix) {
  return {prefix + ".triangle-info", prefix + ".triangle-list", prefix + ".triangle-classes", prefix + ".axis-counts"};
}

void VoxelizeScratch::declareWrites(StageBuilder& b) const {
  b.write(triangleInfo);
  b.write(triangleList);
  b.write(triangleClasses);
  b.write(axisCounts);
}

bool partHolds(const Scene& scene, TrianglePart part, size_t triangle) {
  return part == TrianglePart::All || scene.triangleMoves(triangle) == (part == TrianglePart::Dynamic);
}

// Bit 30 of a triangle's info: outside the part being voxelized (classify.comp.glsl skips it,
// voxelize.geom.glsl too when VOXLAB_SKIP_OTHER_PART is defined).
constexpr uint32_t kOtherPartBit = 0x40000000u;
// Bit 31: the classification sent the triangle to the compute pass (classify.comp.glsl).
constexpr uint32_t kComputeClassBit = 0x80000000u;

void classifyTriangles(StageContext& ctx, const VoxelSpace& space, VoxelizeMethod method, float cutoff,
                       TrianglePart part, const VoxelizeScratch& scratch) {
  const size_t triangles = ctx.scene.triangleCount();
  // Material index per triangle (bits 0-23) and the other-part bit; the shader adds the class bit.
  std::vector<uint32_t> info(std::max<size_t>(triangles, 1), 0u);
  for (const DrawRange& d : ctx.scene.draws)
    for (uint32_t t = d.firstIndex / 3; t < (d.firstIndex + d.indexCount) / 3; ++t)
      info[t] = d.material | (partHolds(ctx.scene, part, t) ? 0u : kOtherPartBit);
  Buffer& infoBuffer = ctx.board.ensureBuffer(scratch.triangleInfo, info.size() * 4);
  infoBuffer.upload(info.data(), info.size() * 4);
  // Two lists (classify.comp.glsl): every compute triangle, then those with more than one chunk.
  Buffer& list = ctx.board.ensureBuffer(scratch.triangleList, info.size() * 8);
  Buffer& counts = ctx.board.ensureBuffer(scratch.triangleClasses, 32);
  const uint32_t zero[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  counts.upload(zero, 32);

  GLuint program = ctx.shaders.program({"common/classify.comp.glsl"});
  space.setUniforms(program);
  setUniform(program, "u_triangleCount", unsigned(triangles));
  setUniform(program, "u_mode",
             method == VoxelizeMethod::TriangleParallel ? 1 : (method == VoxelizeMethod::Hybrid ? 2 : 0));
  setUniform(program, "u_cutoff", cutoff);
  setUniform(program, "u_chunkColumns", unsigned(kChunkColumns));
  glUseProgram(program);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_SCENE_VERTICES, ctx.gpuScene.vertices().id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_SCENE_INDICES, ctx.gpuScene.indices().id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_TRIANGLE_INFO, infoBuffer.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_TRIANGLE_LIST, list.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_CLASS_COUNTS, counts.id());
  dispatchCompute({int(triangles), 1, 1}, {64, 1, 1});
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

TriangleClasses readTriangleClasses(StageContext& ctx, const VoxelizeScratch& scratch) {
  uint32_t c[8];
  auto bytes = ctx.board.buffer(scratch.triangleClasses).download(32);
  std::memcpy(c, bytes.data(), 32);
  TriangleClasses k;
  k.axis[0] = c[0];
  k.axis[1] = c[1];
  k.axis[2] = c[2];
  k.degenerate = c[3];
  k.compute = c[4];
  k.raster = c[5];
  k.maxColumns = c[6];
  k.multiChunk = c[7];
  return k;
}

bool methodRasterizes(VoxelizeMethod method, const TriangleClasses& classes) {
  // The hybrid skips a pass that has no triangles: an empty raster pass would still run every
  // triangle through the vertex and geometry shaders only to drop it there (single-threaded
  // stages on llvmpipe), and an empty compute pass would cost dispatches for nothing.
  return method != VoxelizeMethod::TriangleParallel && (method != VoxelizeMethod::Hybrid || classes.raster > 0);
}

bool methodComputes(VoxelizeMethod method, const TriangleClasses& classes) {
  return (method == VoxelizeMethod::TriangleParallel || method == VoxelizeMethod::Hybrid) && classes.compute > 0;
}

// The runs of consecutive triangles, within each draw range, that the raster pass keeps: the
// class bit (compute) and the other-part bit of the classified triangle info, read back.
static std::vector<DrawRange> rasterizedRuns(StageContext& ctx, const VoxelizeScratch& scratch, bool skipSmall,
                                             bool skipOther) {
  const size_t triangles = ctx.scene.triangleCount();
  std::vector<uint32_t> info(triangles, 0u);
  if (triangles > 0) {
    auto bytes = ctx.board.buffer(scratch.triangleInfo).download(triangles * 4);
    std::memcpy(info.data(), bytes.data(), triangles * 4);
  }
  const uint32_t dropped = (skipSmall ? kComputeClassBit : 0u) | (skipOther ? kOtherPartBit : 0u);
  std::vector<DrawRange> runs;
  for (const DrawRange& d : ctx.scene.draws) {
    const uint32_t first = d.firstIndex / 3, end = (d.firstIndex + d.indexCount) / 3;
    for (uint32_t t = first; t < end;) {
      if (info[t] & dropped) {
        ++t;
        continue;
      }
      uint32_t runEnd = t + 1;
      while (runEnd < end && !(info[runEnd] & dropped)) ++runEnd;
      runs.push_back({t * 3, (runEnd - t) * 3, d.material});
      t = runEnd;
    }
  }
  return runs;
}

void voxelizeTrianglesRaster(StageContext& ctx, const VoxelSpace& space, VoxelizeMethod method, uint32_t capacity,
                             TrianglePart part, const VoxelizeScratch& scratch) {
  // The hybrid's raster pass skips the compute pass's triangles and writes the records that pass
  // would (voxelize.frag.glsl), so routing changes no fragment.
  std::string defines =
      method == VoxelizeMethod::Hybrid ? "#define VOXLAB_SKIP_SMALL_TRIANGLES 1\n#define VOXLAB_RECORDS_AS_COMPUTE 1\n" : "";
  if (part != TrianglePart::All) defines += "#define VOXLAB_SKIP_OTHER_PART 1\n";
  // A program per material kind (GpuScene::materialKindDefines): a material without textures or
  // alpha mask runs none of their code.
  const auto programFor = [&](const std::string& kind) {
    GLuint program = ctx.shaders.program(
        {"common/world.vert.glsl", "common/voxelize.geom.glsl", "common/voxelize.frag.glsl"}, defines + kind);
    space.setUniforms(program);
    setUniform(program, "u_conservative", method == VoxelizeMethod::Plain ? 0 : 1);
    setUniform(program, "u_capacity", capacity);
    return program;
  };
  if (ctx.board.hasBuffer(scratch.triangleInfo))
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_TRIANGLE_INFO, ctx.board.buffer(scratch.triangleInfo).id());
  // Where the geometry shader would drop triangles (the hybrid's small ones, the other part's),
  // only the runs of triangles it keeps are drawn: the vertex and geometry stages run on one
  // thread on llvmpipe, so drawing all of Sponza to keep its few large triangles cost more than
  // voxelizing those in the compute pass.
  const bool skipSmall = method == VoxelizeMethod::Hybrid, skipOther = part != TrianglePart::All;
  if ((skipSmall || skipOther) && ctx.board.hasBuffer(scratch.triangleInfo)) {
    const std::vector<DrawRange> kept = rasterizedRuns(ctx, scratch, skipSmall, skipOther);
    rasterizeVoxelFragments(ctx, programFor, space.resolution, &kept);
    return;
  }
  rasterizeVoxelFragments(ctx, programFor, space.resolution);
}

void voxelizeTrianglesCompute(StageContext& ctx, const VoxelSpace& space, const TriangleClasses& classes,
                              uint32_t capacity, const VoxelizeScratch& scratch) {
  // A program per material kind (GpuScene::materialKindDefines), made current with the range's
  // material and its textures.
  const auto useMaterial = [&](uint32_t material) {
    GLuint program = ctx.shaders.program({"common/triangle_parallel.comp.glsl"}, ctx.gpuScene.materialKindDefines(material));
    space.setUniforms(program);
    setUniform(program, "u_chunkColumns", unsigned(kChunkColumns));
    setUniform(program, "u_capacity", capacity);
    setUniform(program, "u_materialIndex", int(material));
    glUseProgram(program);
    ctx.gpuScene.bindMaterialTextures(material);
    return program;
  };
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_MATERIALS, ctx.gpuScene.materials().id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_SCENE_VERTICES, ctx.gpuScene.vertices().id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_SCENE_INDICES, ctx.gpuScene.indices().id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_TRIANGLE_INFO, ctx.board.buffer(scratch.triangleInfo).id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_TRIANGLE_LIST, ctx.board.buffer(scratch.triangleList).id());
  ctx.gpuScene.bindCoverage();
  // Chunk 0 of every compute triangle, one dispatch per draw range (one material, its textures).
  for (const DrawRange& d : ctx.scene.draws) {
    if (d.indexCount < 3) continue;
    GLuint program = useMaterial(d.material);
    setUniform(program, "u_directRange", 1);
    setUniform(program, "u_firstChunk", 0u);
    setUniform(program, "u_listBase", unsigned(d.firstIndex / 3));
    setUniform(program, "u_listCount", unsigned(d.indexCount / 3));
    dispatchCompute({int(d.indexCount / 3), 1, 1}, {64, 1, 1});
  }
  // Chunks 1.. of the few triangles that have them (listed from entry triangleCount on), once
  // per material present.
  const int chunks = classes.chunks();
  if (chunks > 1 && classes.multiChunk > 0) {
    std::vector<bool> done(ctx.scene.materials.size(), false);
    for (const DrawRange& d : ctx.scene.draws) {
      if (d.material >= done.size() || done[d.material]) continue;
      done[d.material] = true;
      GLuint program = useMaterial(d.material);
      setUniform(program, "u_directRange", 0);
      setUniform(program, "u_listBase", unsigned(ctx.scene.triangleCount()));
      setUniform(program, "u_listCount", unsigned(classes.multiChunk));
      setUniform(program, "u_firstChunk", 1u);
      dispatchCompute({int(classes.multiChunk), chunks - 1, 1}, {64, 1, 1});
    }
  }
  glMemoryBarrier(GL_ATOMIC_COUNTER_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

uint32_t voxelizeTriangles(StageContext& ctx, const VoxelSpace& space, VoxelizeMethod method,
                           const TriangleClasses& classes, uint32_t capacity, TrianglePart part,
                           const VoxelizeScratch& scratch, const std::string& countResource) {
  const bool raster = methodRasterizes(method, classes), compute = methodComputes(method, classes);
  uint32_t afterRaster = 0;
  if (raster) {
    voxelizeTrianglesRaster(ctx, space, method, capacity, part, scratch);
    afterRaster = readCounter(ctx.board.buffer(countResource));
  }
  if (compute) voxelizeTrianglesCompute(ctx, space, classes, capacity, scratch);
  return afterRaster;
}

}  // namespace voxlab
