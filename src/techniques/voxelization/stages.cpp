#include "techniques/voxelization/stages.h"
#include "graph/scene_inputs.h"

#include <algorithm>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "common/shared.h"
#include "core/error.h"
#include "gpu/shader_library.h"
#include "reference/cpu_voxelizer.h"
#include "scene/gpu_scene.h"
#include "techniques/common/voxel_space.h"
#include "techniques/common/triangle_voxelizer.h"
#include "techniques/common/voxelize_stage.h"

namespace voxlab::vox {

ParamDesc methodParam() { return voxelizeMethodParam(VoxelizeMethod::FragmentParallel); }

void checkPackableResolution(int resolution) {
  if (resolution > kMaxPackedResolution)
    throw Error("voxel.resolution " + std::to_string(resolution) + " cannot be voxelized: fragments pack voxel "
                "coordinates into 10 bits per axis, so at most " + std::to_string(kMaxPackedResolution) +
                " voxels per axis");
}

// --- 1. classify ----------------------------------------------------------------------------------

void ClassifyStage::declare(StageBuilder& b) const {
  b.read(kSceneGeometryInput);  // classifies the scene's triangles
  b.param(voxelResolutionParam());
  b.param(methodParam());
  b.param(hybridCutoffParam());
  b.readView();
  b.write("triangle-info");
  b.write("triangle-list");
  b.write("triangle-classes");
  b.output("triangle-axes", OutputKind::Image2D, Semantic::Color,
           "triangles coloured by the axis they are projected along (x red, y green, z blue)").alongside = true;
  b.texture("triangle-axes", [](const ParamSet&, const ViewState& v) { return triangleAxesDesc(v); });
}

void ClassifyStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  checkPackableResolution(res);
  VoxelSpace space = VoxelSpace::fromScene(ctx.scene, res);
  ctx.board.setVoxelSpace(space.box());  // every later volume of the technique sits in this box
  classifyTriangles(ctx, space, voxelizeMethodOf(ctx.params), float(ctx.params.getFloat("voxelize.hybrid-cutoff")));
  const TriangleClasses c = readTriangleClasses(ctx);
  ctx.stats["triangles"] = double(ctx.scene.triangleCount());
  ctx.stats["triangles_axis_x"] = c.axis[0];
  ctx.stats["triangles_axis_y"] = c.axis[1];
  ctx.stats["triangles_axis_z"] = c.axis[2];
  ctx.stats["triangles_degenerate"] = c.degenerate;
  ctx.stats["triangles_small_compute"] = c.compute;
  ctx.stats["triangles_large_raster"] = c.raster;

  renderTriangleAxes(ctx, "triangle-axes");
}

// --- 2. voxelize ----------------------------------------------------------------------------------

void VoxelizeStage::declare(StageBuilder& b) const {
  b.read(kSceneGeometryInput);  // rasterizes the scene's triangles
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
  const VoxelizeMethod method = voxelizeMethodOf(ctx.params);
  VoxelSpace space = VoxelSpace::fromScene(ctx.scene, res);
  const TriangleClasses classes = readTriangleClasses(ctx);
  uint32_t afterRaster = 0;
  size_t capacity = 0;
  const uint32_t produced = fillFragmentList(ctx, res, [&](uint32_t cap) {
    afterRaster = voxelizeTriangles(ctx, space, method, classes, cap);
  }, capacity);
  const bool raster = methodRasterizes(method, classes), compute = methodComputes(method, classes);
  ctx.stats["fragments"] = produced;
  ctx.stats["fragments_raster"] = afterRaster;
  ctx.stats["fragments_compute"] = double(produced - afterRaster);
  ctx.stats["fragment_capacity"] = double(capacity);
  ctx.stats["raster_pass"] = raster ? 1.0 : 0.0;
  ctx.stats["compute_pass"] = compute ? 1.0 : 0.0;
  ctx.stats["compute_chunks"] = compute ? double(classes.chunks()) : 0.0;
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
  b.read(kSceneGeometryInput);  // voxelizes the scene's triangles on the CPU
  b.param(voxelResolutionParam());
  b.read("occupancy");
  b.output("reference", OutputKind::Volume3D, Semantic::Occupancy,
           "CPU reference voxels: every voxel whose half-open cell a triangle meets (exact SAT, double; "
           "alphaMode MASK triangles only where their alpha coverage is opaque)");
  b.output("difference", OutputKind::Volume3D, Semantic::Scalar,
           "0 = method and reference agree, 1 = missed by the method, 2 = added by the method");
  b.alongside({"reference"});  // the difference is computed from it
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
  // Both arrays are written whole below (read back, then one value per voxel): not zeroed first.
  std::unique_ptr<uint32_t[]> occupancy(new uint32_t[n]);
  glGetTextureImage(ctx.board.texture("occupancy").id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT,
                    GLsizei(n * 4), occupancy.get());
  std::unique_ptr<float[]> difference(new float[n]);
  size_t missed = 0, added = 0;
  for (size_t i = 0; i < n; ++i) {
    const bool ref = reference[i] != 0, gpu = occupancy[i] != 0;
    missed += ref && !gpu;
    added += gpu && !ref;
    difference[i] = ref == gpu ? 0.0f : (ref ? 1.0f : 2.0f);
  }
  Texture& refTex = ctx.board.ensureTexture("reference", volumeDesc(res, GL_R8));
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage3D(refTex.id(), 0, 0, 0, 0, res, res, res, GL_RED, GL_UNSIGNED_BYTE, reference.data());
  Texture& diffTex = ctx.board.ensureTexture("difference", volumeDesc(res, GL_R32F));
  glTextureSubImage3D(diffTex.id(), 0, 0, 0, 0, res, res, res, GL_RED, GL_FLOAT, difference.get());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  ctx.stats["reference_voxels"] = double(keys.size());
  ctx.stats["missed_voxels"] = double(missed);
  ctx.stats["added_voxels"] = double(added);
}

}  // namespace voxlab::vox
