#include "techniques/common/binary_voxels_stage.h"

#include <bitset>

#include "common/shared.h"
#include "core/error.h"
#include "gpu/shader_library.h"
#include "techniques/common/voxel_space.h"
#include "techniques/common/voxelize_stage.h"

namespace voxlab {

int popcount(const BitColumn& c) {
  return int(std::bitset<32>(c[0]).count() + std::bitset<32>(c[1]).count() + std::bitset<32>(c[2]).count() +
             std::bitset<32>(c[3]).count());
}

void slicesOfVoxel(int z, int res, int& first, int& last) {
  if (res <= kBinarySlices) {
    first = z * (kBinarySlices / res);
    last = first + kBinarySlices / res - 1;
  } else {
    first = last = z / (res / kBinarySlices);
  }
}

std::vector<BitColumn> binaryGridFromVoxelKeys(const std::vector<uint32_t>& keys, int res) {
  std::vector<BitColumn> grid(size_t(res) * res, BitColumn{0, 0, 0, 0});
  for (uint32_t key : keys) {
    int x = int(key & 1023u), y = int((key >> 10) & 1023u), z = int((key >> 20) & 1023u);
    if (x >= res || y >= res || z >= res) continue;
    int first, last;
    slicesOfVoxel(z, res, first, last);
    for (int k = first; k <= last; ++k) setSlice(grid[size_t(y) * res + x], k);
  }
  return grid;
}

std::vector<BitColumn> readBitColumns(GLuint texture, int level, int width, int height) {
  std::vector<BitColumn> out(size_t(width) * height);
  glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTextureImage(texture, level, GL_RGBA_INTEGER, GL_UNSIGNED_INT, GLsizei(out.size() * 16), out.data());
  return out;
}

// The three images, sized from the resolution: 4 words per column (scratch), one RGBA32UI texel
// per column, one R32UI popcount per column. Used by declare() and execute().
static TextureDesc binaryWordsDesc(int res) {
  TextureDesc words;
  words.format = GL_R32UI;
  words.size = {4 * res, res, 1};
  words.minFilter = words.magFilter = GL_NEAREST;
  return words;
}
static TextureDesc binaryColumnsDesc(int res) {
  TextureDesc cols = binaryWordsDesc(res);
  cols.format = GL_RGBA32UI;
  cols.size = {res, res, 1};
  return cols;
}
static TextureDesc binaryPopcountDesc(int res) {
  TextureDesc count = binaryWordsDesc(res);
  count.size = {res, res, 1};
  return count;
}

void BinaryVoxelsStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.read("fragments");
  b.read("fragments.count");
  b.write("binary-voxels.words");
  auto& grid = b.output("binary-voxels", OutputKind::Image2D, kBitmaskColumns,
                        "128-bit columns (RGBA32UI): bit 31-(k&31) of channel k>>5 = slice k along z; "
                        "shown white where a column holds any voxel");
  grid.tier = CaptureTier::Exact;
  auto& count = b.output("binary-popcount", OutputKind::Image2D, Semantic::Scalar,
                         "voxels set per column (popcount of its 128 bits)");
  count.tier = CaptureTier::Exact;
  b.texture("binary-voxels.words", [](const ParamSet& p, const ViewState&) {
    return binaryWordsDesc(p.getInt("voxel.resolution"));
  });
  b.texture("binary-voxels", [](const ParamSet& p, const ViewState&) {
    return binaryColumnsDesc(p.getInt("voxel.resolution"));
  });
  b.texture("binary-popcount", [](const ParamSet& p, const ViewState&) {
    return binaryPopcountDesc(p.getInt("voxel.resolution"));
  });
}

void BinaryVoxelsStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  if (res > 1024) throw Error("binary-voxels: voxel.resolution " + std::to_string(res) + " exceeds 1024 (10-bit keys)");
  Texture& scratch = ctx.board.ensureTexture("binary-voxels.words", binaryWordsDesc(res));
  Texture& grid = ctx.board.ensureTexture("binary-voxels", binaryColumnsDesc(res));
  Texture& popcountTex = ctx.board.ensureTexture("binary-popcount", binaryPopcountDesc(res));
  // The columns' place in the world, so their views give each slice's depth interval in metres.
  ctx.board.place("binary-voxels", VoxelSpace::fromScene(ctx.scene, res).box());
  const uint32_t zero = 0;
  glClearTexImage(scratch.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);

  const uint32_t fragments = voxelFragmentCount(ctx.board);
  GLuint orProgram = ctx.shaders.program({"common/binary_voxels_or.comp.glsl"});
  setUniform(orProgram, "u_resolution", res);
  setUniform(orProgram, "u_fragmentCount", fragments);
  glUseProgram(orProgram);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, ctx.board.buffer("fragments").id());
  glBindImageTexture(0, scratch.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
  if (fragments > 0) dispatchCompute({int(fragments), 1, 1}, {64, 1, 1});
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);

  GLuint packProgram = ctx.shaders.program({"common/binary_voxels_pack.comp.glsl"});
  setUniform(packProgram, "u_resolution", res);
  glUseProgram(packProgram);
  glBindImageTexture(0, scratch.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
  glBindImageTexture(1, grid.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32UI);
  glBindImageTexture(2, popcountTex.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32UI);
  dispatchCompute({res, res, 1}, {8, 8, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);

  ctx.stats["fragments_read"] = fragments;
  ctx.stats["columns"] = double(res) * res;
  ctx.stats["slices"] = kBinarySlices;
  ctx.stats["grid_bytes"] = double(res) * res * 16;
}

}  // namespace voxlab
