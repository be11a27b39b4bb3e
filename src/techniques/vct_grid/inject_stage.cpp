// Light injection and the occlusion fix (seed 000 section 4.2.1).
#include <algorithm>
#include <cstring>
#include <string>

#include "common/shared.h"
#include "core/error.h"
#include "gpu/shader_library.h"
#include "techniques/common/facing.h"
#include "techniques/common/fragment_light.h"
#include "techniques/common/light_stage.h"
#include "techniques/common/voxel_space.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/vct_grid/stages.h"

namespace voxlab::vct {

TextureDesc radianceGridDesc(int res, int levels, GLenum format) {
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = format;
  d.size = {res, res, res};
  d.levels = levels;
  d.minFilter = levels == 1 ? GL_LINEAR : GL_LINEAR_MIPMAP_LINEAR;
  return d;
}

ParamDesc voxelFormatParam() {
  return ParamDesc::choice("voxel.format", {"rgba8", "rgba16f"}, 1,
                           "what the radiance grids store: rgba16f keeps up to 64 W/(m^2 sr) in half floats (HDR "
                           "voxels; needs inject.average=exact-sum); rgba8 clamps radiance to [0,1] (8 bits per "
                           "channel, half the memory: the voxels by a lamp or in the sun lose most of their light)");
}
GLenum gridFormat(const ParamSet& p) { return p.getChoice("voxel.format") == "rgba16f" ? GL_RGBA16F : GL_RGBA8; }
std::string gridFormatDefines(const ParamSet& p) {
  return gridFormat(p) == GL_RGBA16F ? "#define VOXLAB_GRID_FORMAT rgba16f\n" : "";
}
float gridMaxRadiance(const ParamSet& p) { return gridFormat(p) == GL_RGBA16F ? kHdrMaxRadiance : 1.0f; }

static bool exactSums(const ParamSet& p) { return p.getChoice("inject.average") == "exact-sum"; }

// Exact-sum averaging (shaders/vct_grid/voxel_sums.glsl): per voxel the slot its first fragment
// claimed (an R32UI volume; one texel when inject.average is compare-and-swap), and per slot three
// fixed-point channel sums, a fragment count and a facing code (a buffer of one slot per fragment).
static const char* const kVoxelOwner = "voxel-owner";
static const char* const kVoxelSums = "voxel-sums";
static const char* const kVoxelList = "voxel-list";  // a count, then the occupied voxels' slots
static constexpr size_t kVoxelSumsBytes = 5 * 4;  // VoxelSums: five uints
static TextureDesc voxelOwnerDesc(const ParamSet& p) {
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = GL_R32UI;
  d.size = glm::ivec3(exactSums(p) ? p.getInt("voxel.resolution") : 1);
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}

// Per voxel, the facing code of its surfaces (shaders/common/facing.glsl): what a cone travelling
// along each axis direction sees of their fronts; the anisotropic mips' leaves.
static TextureDesc voxelFacingDesc(const ParamSet& p) {
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = GL_R32UI;
  d.size = glm::ivec3(p.getInt("voxel.resolution"));
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}

void InjectStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  declareFragmentLightParams(b);
  b.param(ParamDesc::choice("inject.average", {"exact-sum", "compare-and-swap"}, 0,
                            "how a voxel's fragments are averaged: exact-sum adds fixed-point sums and a count with "
                            "integer atomics (order-independent), compare-and-swap keeps a running RGBA8 average "
                            "(seed 000: truncates, saturates at 255 fragments, depends on the order)"));
  b.param(voxelFormatParam());
  b.read("fragments");
  b.read("fragments.count");
  b.read("shadow-map");
  b.read("light");
  b.write(kVoxelOwner);
  b.texture(kVoxelOwner, [](const ParamSet& p, const ViewState&) { return voxelOwnerDesc(p); });
  b.write(kVoxelSums);
  b.buffer(kVoxelSums, [](const ParamSet& p, const ViewState&) {
    return exactSums(p) ? fragmentPoolStart(p.getInt("voxel.resolution")) * kVoxelSumsBytes : kVoxelSumsBytes;
  }, /*pool=*/true);
  b.write(kVoxelList);
  b.buffer(kVoxelList, [](const ParamSet& p, const ViewState&) {
    return 4 + (exactSums(p) ? fragmentPoolStart(p.getInt("voxel.resolution")) * 4 : 0);
  }, /*pool=*/true);
  // With exact sums the occlusion fix takes each voxel's mean from its slot, so nothing later reads
  // this grid: it is written only where a view, a test or compare-and-swap averaging wants it.
  b.output("radiance-injected", OutputKind::Volume3D, Semantic::Color,
           "averaged outgoing radiance per voxel; alpha = min(fragments averaged, 255) / 255")
      .onDemand = true;
  b.texture("radiance-injected", [](const ParamSet& p, const ViewState&) {
    return radianceGridDesc(p.getInt("voxel.resolution"), 1, gridFormat(p));
  });
  // The facing codes after the radiance: a stage's first output is its picture (the viewer's default).
  b.output(kVoxelFacing, OutputKind::Volume3D, kVoxelFacingSemantic,
           "per voxel (r32ui), what a cone travelling along each axis direction sees of its surfaces' fronts: 6 fields "
           "of 5 bits, +x -x +y -y +z -z, each a thermometer code of the largest front weight (shaders/common/facing.glsl)");
  b.texture(kVoxelFacing, [](const ParamSet& p, const ViewState&) { return voxelFacingDesc(p); });
}

void InjectStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  VoxelSpace space = VoxelSpace::fromScene(ctx.scene, res);
  const bool exact = exactSums(ctx.params);
  const GLenum format = gridFormat(ctx.params);
  if (!exact && format != GL_RGBA8)
    throw Error("inject.average=compare-and-swap needs voxel.format=rgba8 (its running average lives in the RGBA8 "
                "voxel); use inject.average=exact-sum with voxel.format=rgba16f");
  // Compare-and-swap averages in the grid itself (the occlusion fix reads it then).
  const bool wantGrid = !exact || ctx.wants("radiance-injected");
  Texture* grid = nullptr;
  if (wantGrid) {
    grid = &ctx.board.ensureTexture("radiance-injected", radianceGridDesc(res, 1, format));
    const uint8_t zero[4] = {0, 0, 0, 0};
    glClearTexImage(grid->id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, zero);
  }

  const uint32_t count = voxelFragmentCount(ctx.board);
  Texture& facing = ctx.board.ensureTexture(kVoxelFacing, voxelFacingDesc(ctx.params));
  const uint32_t noSurface = 0;
  glClearTexImage(facing.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &noSurface);
  GLuint program = ctx.shaders.program({"vct_grid/inject.comp.glsl"},
                                       lightKindDefines(ctx.scene) +
                                           (exact ? "" : "#define VOXLAB_INJECT_COMPARE_AND_SWAP\n"));
  space.setUniforms(program);
  setUniform(program, "u_fragmentCount", unsigned(count));
  setUniform(program, "u_maxRadiance", gridMaxRadiance(ctx.params));
  setFragmentLightUniforms(program, ctx.params, space);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, ctx.board.buffer("fragments").id());
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  glBindTextureUnit(2, ctx.board.texture("shadow-map").id());

  if (!exact) {
    // An r32ui view of the RGBA8 grid: image atomics work on 32-bit integers only.
    GLuint view = 0;
    glGenTextures(1, &view);
    glTextureView(view, GL_TEXTURE_3D, grid->id(), GL_R32UI, 0, 1, 0, 1);
    glObjectLabel(GL_TEXTURE, view, -1, "radiance-injected.r32ui-view");
    glUseProgram(program);
    glBindImageTexture(0, view, 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
    glBindImageTexture(5, facing.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
    dispatchCompute({int(count), 1, 1}, {64, 1, 1});
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
    glBindImageTexture(0, 0, 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
    glBindImageTexture(5, 0, 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
    glDeleteTextures(1, &view);
    // The exact sums' scratch exists at the size it declares (one texel, one slot).
    ctx.board.ensureTexture(kVoxelOwner, voxelOwnerDesc(ctx.params));
    ctx.board.ensureBuffer(kVoxelSums, kVoxelSumsBytes);
    ctx.board.ensureBuffer(kVoxelList, 4);
    ctx.stats["fragments_injected"] = count;
    return;
  }

  // Exact sums: no voxel claimed, every slot a fragment can claim zero.
  Texture& owner = ctx.board.ensureTexture(kVoxelOwner, voxelOwnerDesc(ctx.params));
  const uint32_t noOwner = 0xffffffffu;
  glClearTexImage(owner.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &noOwner);
  // Both pools start at the size they declare and grow with the fragments.
  const size_t slots = std::max<size_t>(fragmentPoolStart(res), count);
  Buffer& sums = ctx.board.ensureBuffer(kVoxelSums, slots * kVoxelSumsBytes);
  const uint32_t emptySum = 0;
  glClearNamedBufferSubData(sums.id(), GL_R32UI, 0, GLsizeiptr(std::max<size_t>(count, 1) * kVoxelSumsBytes),
                            GL_RED_INTEGER, GL_UNSIGNED_INT, &emptySum);
  Buffer& voxels = ctx.board.ensureBuffer(kVoxelList, 4 + slots * 4);
  glClearNamedBufferSubData(voxels.id(), GL_R32UI, 0, 4, GL_RED_INTEGER, GL_UNSIGNED_INT, &emptySum);
  glUseProgram(program);
  glBindImageTexture(1, owner.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_VOXEL_SUMS, sums.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_VOXEL_LIST, voxels.id());
  dispatchCompute({int(count), 1, 1}, {64, 1, 1});
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  const uint32_t occupied = readCounter(voxels);

  GLuint resolve = ctx.shaders.program({"vct_grid/inject_resolve.comp.glsl"},
                                       gridFormatDefines(ctx.params) +
                                           (wantGrid ? "" : "#define VOXLAB_RESOLVE_FACING_ONLY\n"));
  setUniform(resolve, "u_voxelCount", unsigned(occupied));
  glUseProgram(resolve);
  if (grid) glBindImageTexture(0, grid->id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, format);
  glBindImageTexture(5, facing.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32UI);
  dispatchCompute({int(occupied), 1, 1}, {64, 1, 1});
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
  glBindImageTexture(0, 0, 0, GL_TRUE, 0, GL_WRITE_ONLY, format);
  glBindImageTexture(1, 0, 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32UI);
  glBindImageTexture(5, 0, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32UI);
  ctx.stats["voxels_occupied"] = occupied;
  ctx.stats["fragments_injected"] = count;
}

void OcclusionFixStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(voxelFormatParam());
  // Compare-and-swap averaging only: with exact sums the voxels' means come from their slots.
  b.readWhen("radiance-injected", "inject.average=compare-and-swap");
  b.read("fragments");
  b.read("fragments.count");
  b.read(kVoxelSums);
  b.read(kVoxelList);
  b.output("radiance-opaque", OutputKind::Volume3D, Semantic::Color,
           "radiance per voxel with alpha 1 in every occupied voxel");
  b.texture("radiance-opaque", [](const ParamSet& p, const ViewState&) {
    return radianceGridDesc(p.getInt("voxel.resolution"), 1, gridFormat(p));
  });
}

void OcclusionFixStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  Texture& dst = ctx.board.ensureTexture("radiance-opaque", radianceGridDesc(res, 1, gridFormat(ctx.params)));
  const uint8_t zero[4] = {0, 0, 0, 0};
  glClearTexImage(dst.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, zero);
  // Only voxels that received fragments can be non-empty: visit those instead of the whole grid
  // (with exact sums the inject stage's list of them, else the fragments).
  const bool exact = exactSums(ctx.params);
  const uint32_t items = exact ? readCounter(ctx.board.buffer(kVoxelList)) : voxelFragmentCount(ctx.board);
  GLuint program = ctx.shaders.program({"vct_grid/occlusion_fix.comp.glsl"},
                                       gridFormatDefines(ctx.params) + (exact ? "" : "#define VOXLAB_OCCLUSION_FROM_GRID\n"));
  setUniform(program, "u_itemCount", unsigned(items));
  glUseProgram(program);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, ctx.board.buffer("fragments").id());
  if (exact) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_VOXEL_SUMS, ctx.board.buffer(kVoxelSums).id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_VOXEL_LIST, ctx.board.buffer(kVoxelList).id());
  } else {
    glBindTextureUnit(0, ctx.board.texture("radiance-injected").id());
  }
  glBindImageTexture(0, dst.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, dst.desc().format);
  dispatchCompute({int(items), 1, 1}, {64, 1, 1});
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
}

const char* const kDirectionalVolumes[6] = {"radiance-dir+x", "radiance-dir-x", "radiance-dir+y",
                                           "radiance-dir-y", "radiance-dir+z", "radiance-dir-z"};

ParamDesc mipmapModeParam() {
  return ParamDesc::choice("mipmap.mode", {"isotropic", "anisotropic", "max-opacity"}, 1,
                           "isotropic: one average per 2x2x2 block; anisotropic: six volumes, one per travel direction, "
                           "compositing front to back before averaging (Crassin et al.); max-opacity: the isotropic "
                           "colour with the opacity of the block's most opaque axis (thin walls stay opaque)");
}

ParamDesc mipmapFrontsParam() {
  return ParamDesc::boolean("mipmap.fronts", true,
                            "anisotropic mips show a voxel's light only to the directions that see its surfaces' "
                            "fronts, its opacity kept apart as a solid cube's (false: Crassin's classic reduction, "
                            "every voxel seen from all sides)");
}

// Edge of the six directional volumes: half the grid with anisotropic mips, one voxel without.
int directionalSize(const ParamSet& p) {
  return p.getChoice("mipmap.mode") == "anisotropic" ? std::max(p.getInt("voxel.resolution") / 2, 1) : 1;
}

// The mip passes visit only the texels that can be non-empty (shaders/vct_grid/mip_blocks.glsl):
// per level a list of them, in two halves of one buffer (a level's list is built from the one
// below, the fragment list's voxels for the first), each as long as the first level's list can be.
static const char* const kMipBlocks = "mip-blocks";
static const char* const kMipBlockCount = "mip-blocks.count";
static const char* const kMipBlocksOccupied = "mip-blocks.occupied";  // r32ui, a bit per listed texel
static uint32_t mipBlocksPerList(int res, uint32_t fragments) {
  const uint32_t half = uint32_t(std::max(res / 2, 1));
  return std::min(fragments, half * half * half);
}
static size_t mipBlocksBytes(int res, uint32_t fragments) { return 2 * size_t(mipBlocksPerList(res, fragments)) * 4; }
static TextureDesc mipBlocksOccupiedDesc(int res) {
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = GL_R32UI;
  d.size = glm::ivec3(std::max(res / 2, 1));
  d.levels = 0;
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}

// Lists the texels of level k + 1 of 'grid' (level k of the directional volumes) that have an
// occupied child, in half k % 2 of the list buffer; returns how many and where they start.
static std::pair<uint32_t, uint32_t> listMipBlocks(StageContext& ctx, int res, int k) {
  const uint32_t fragments = voxelFragmentCount(ctx.board);
  const uint32_t perList = std::max(mipBlocksPerList(res, fragments), mipBlocksPerList(res, uint32_t(fragmentPoolStart(res))));
  Buffer& blocks = ctx.board.ensureBuffer(kMipBlocks, 2 * size_t(perList) * 4);
  Buffer& appended = ctx.board.ensureBuffer(kMipBlockCount, 32);
  Texture& occupied = ctx.board.ensureTexture(kMipBlocksOccupied, mipBlocksOccupiedDesc(res));
  const uint32_t zero = 0;
  if (k == 0)
    for (int level = 0; level < occupied.levels(); ++level)
      glClearTexImage(occupied.id(), level, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  if (k >= occupied.levels()) return {0, 0};
  // Slot k % 2 of the count buffer counts list k; the other still holds the length of list k - 1.
  // (Slots 16 bytes apart: a storage buffer range starts at a multiple of 16 on llvmpipe.)
  const uint32_t sourceCount = k == 0 ? fragments : readCounter(appended, size_t((k + 1) % 2) * 16);
  glNamedBufferSubData(appended.id(), GLintptr((k % 2) * 16), 4, &zero);
  GLuint program = ctx.shaders.program({"vct_grid/mip_blocks.comp.glsl"}, k == 0 ? "#define VOXLAB_BLOCKS_FROM_FRAGMENTS\n" : "");
  setUniform(program, "u_sourceCount", sourceCount);
  setUniform(program, "u_sourceOffset", unsigned(((k + 1) % 2) * perList));
  setUniform(program, "u_targetOffset", unsigned((k % 2) * perList));
  glUseProgram(program);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, ctx.board.buffer("fragments").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_MIP_BLOCKS, blocks.id());
  glBindBufferRange(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_MIP_BLOCK_COUNT, appended.id(), GLintptr((k % 2) * 16), 4);
  glBindImageTexture(0, occupied.id(), k, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
  dispatchCompute({int(sourceCount), 1, 1}, {64, 1, 1});
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  glBindImageTexture(0, 0, 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
  return {readCounter(appended, size_t(k % 2) * 16), unsigned((k % 2) * perList)};
}

void MipmapStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(voxelFormatParam());
  b.param(mipmapModeParam());
  b.param(mipmapFrontsParam());
  b.read("radiance-opaque");
  b.read(kVoxelFacing);
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
  b.output(kSolidOpacity, OutputKind::Volume3D, Semantic::Color,
           "anisotropic levels 1..: the opacity of the voxels as solid cubes seen by a cone travelling along x, y, z "
           "in red, green, blue, either way (opacity alone composited front to back does not depend on the order; "
           "the directional volumes' alpha is the coverage of the surfaces' fronts only)")
      .placeholderUnless = "mipmap.mode=anisotropic";
  b.texture("radiance", [](const ParamSet& p, const ViewState&) {
    return radianceGridDesc(p.getInt("voxel.resolution"), 0, gridFormat(p));
  });
  b.texture(kSolidOpacity, [](const ParamSet& p, const ViewState&) { return radianceGridDesc(directionalSize(p), 0, GL_RGBA8); });
  for (const char* name : kDirectionalVolumes)
    b.texture(name, [](const ParamSet& p, const ViewState&) {
      return radianceGridDesc(directionalSize(p), 0, gridFormat(p));
    });
  b.read("fragments");
  b.read("fragments.count");
  b.write(kMipBlocks);
  b.buffer(kMipBlocks, [](const ParamSet& p, const ViewState&) {
    return mipBlocksBytes(p.getInt("voxel.resolution"), uint32_t(fragmentPoolStart(p.getInt("voxel.resolution"))));
  }, /*pool=*/true);
  b.write(kMipBlockCount);
  b.buffer(kMipBlockCount, [](const ParamSet&, const ViewState&) { return size_t(32); });
  b.write(kMipBlocksOccupied);
  b.texture(kMipBlocksOccupied, [](const ParamSet& p, const ViewState&) { return mipBlocksOccupiedDesc(p.getInt("voxel.resolution")); });
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
  const int half = directionalSize(ctx.params);
  Texture& src = ctx.board.texture("radiance-opaque");
  const GLenum format = gridFormat(ctx.params);
  Texture& grid = ctx.board.ensureTexture("radiance", radianceGridDesc(res, 0, format));
  Texture* dirs[6];
  for (int d = 0; d < 6; ++d)
    dirs[d] = &ctx.board.ensureTexture(kDirectionalVolumes[d], radianceGridDesc(half, 0, format));
  ctx.board.ensureTexture(kSolidOpacity, radianceGridDesc(half, 0, GL_RGBA8));
  buildMipLevel(ctx, src, grid, dirs, ctx.iteration, true);
  double bytes = double(grid.byteSize());
  for (auto* d : dirs) bytes += double(d->byteSize());
  bytes += double(ctx.board.texture(kSolidOpacity).byteSize());
  ctx.stats["levels"] = grid.levels();
  ctx.stats["levels_built"] = std::min(ctx.iteration + 2, grid.levels());
  ctx.stats["anisotropic"] = ctx.params.getChoice("mipmap.mode") == "anisotropic" ? 1 : 0;
  ctx.stats["bytes"] = bytes;
}

void buildMipLevel(StageContext& ctx, Texture& src, Texture& grid, Texture* const dirs[6], int k, bool writeOpacity) {
  const int res = grid.desc().size.x;
  const bool anisotropic = ctx.params.getChoice("mipmap.mode") == "anisotropic";
  const uint8_t zero[4] = {0, 0, 0, 0};
  if (k == 0) {
    if (&src != &grid)
      glCopyImageSubData(src.id(), GL_TEXTURE_3D, 0, 0, 0, 0, grid.id(), GL_TEXTURE_3D, 0, 0, 0, 0, res, res, res);
    for (int level = 1; level < grid.levels(); ++level)
      glClearTexImage(grid.id(), level, GL_RGBA, GL_UNSIGNED_BYTE, zero);
    // In isotropic mode the directional volumes are one empty voxel each: the outputs exist but
    // cost nothing.
    for (int d = 0; d < 6; ++d)
      for (int level = 0; level < dirs[d]->levels(); ++level)
        glClearTexImage(dirs[d]->id(), level, GL_RGBA, GL_UNSIGNED_BYTE, zero);
    // The anisotropic pass writes alpha 1 into every opacity texel it visits; those it skips (no
    // occupied voxel under them, mip_blocks.glsl) get that alpha from the clear.
    const uint8_t noOpacity[4] = {0, 0, 0, uint8_t(anisotropic ? 255 : 0)};
    if (writeOpacity)
      for (int level = 0; level < ctx.board.texture(kSolidOpacity).levels(); ++level)
        glClearTexImage(ctx.board.texture(kSolidOpacity).id(), level, GL_RGBA, GL_UNSIGNED_BYTE, noOpacity);
  }

  const auto [blockCount, blockOffset] = listMipBlocks(ctx, res, k);
  // With anisotropic mips, level 1 of the grid comes out of the directional pass from the voxels,
  // which fetches the same children (mipmap_anisotropic.comp.glsl).
  const bool levelOneFromVoxels = anisotropic && k == 0 && k < dirs[0]->levels() && k + 1 < grid.levels();
  if (k + 1 < grid.levels() && !levelOneFromVoxels) {
    GLuint program = ctx.shaders.program({"vct_grid/mipmap.comp.glsl"}, gridFormatDefines(ctx.params));
    glUseProgram(program);
    glBindTextureUnit(0, grid.id());
    setUniform(program, "u_sourceLevel", k);
    setUniform(program, "u_opacityRule", ctx.params.getChoice("mipmap.mode") == "max-opacity" ? 1 : 0);
    setUniform(program, "u_blockOffset", blockOffset);
    setUniform(program, "u_blockCount", blockCount);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_MIP_BLOCKS, ctx.board.buffer(kMipBlocks).id());
    glBindImageTexture(0, grid.id(), k + 1, GL_TRUE, 0, GL_WRITE_ONLY, grid.desc().format);
    dispatchCompute({int(blockCount), 1, 1}, {64, 1, 1});
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
  }
  if (anisotropic && k < dirs[0]->levels()) {
    // Level 0 is built from the voxels, the others from the level below: two programs, so that
    // neither runs the other's fetches (llvmpipe runs both sides of a branch).
    const std::string fromVoxels = k == 0 ? "#define VOXLAB_MIP_FROM_VOXELS\n" : "";
    GLuint aniso = ctx.shaders.program({"vct_grid/mipmap_anisotropic.comp.glsl"}, gridFormatDefines(ctx.params) + fromVoxels);
    glUseProgram(aniso);
    glBindTextureUnit(0, src.id());
    for (int d = 0; d < 6; ++d) glBindTextureUnit(1 + d, dirs[d]->id());
    glBindTextureUnit(7, ctx.board.texture(kVoxelFacing).id());
    Texture& solidOpacity = ctx.board.texture(kSolidOpacity);
    glBindTextureUnit(8, solidOpacity.id());
    setUniform(aniso, "u_sourceLevel", std::max(k - 1, 0));
    setUniform(aniso, "u_writeOpacity", writeOpacity ? 1 : 0);
    setUniform(aniso, "u_classicDirectional", ctx.params.getBool("mipmap.fronts") ? 0 : 1);
    for (int d = 0; d < 6; ++d) glBindImageTexture(d, dirs[d]->id(), k, GL_TRUE, 0, GL_WRITE_ONLY, dirs[d]->desc().format);
    // Level k of the solid opacity: written only with u_writeOpacity (a bounce's re-mip reads it).
    glBindImageTexture(6, solidOpacity.id(), k, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA8);
    if (levelOneFromVoxels) glBindImageTexture(8, grid.id(), 1, GL_TRUE, 0, GL_WRITE_ONLY, grid.desc().format);
    setUniform(aniso, "u_blockOffset", blockOffset);
    setUniform(aniso, "u_blockCount", blockCount);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_MIP_BLOCKS, ctx.board.buffer(kMipBlocks).id());
    dispatchCompute({int(blockCount), 1, 1}, {64, 1, 1});
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
    if (levelOneFromVoxels) glBindImageTexture(8, 0, 0, GL_TRUE, 0, GL_WRITE_ONLY, grid.desc().format);
  }
}

}  // namespace voxlab::vct
