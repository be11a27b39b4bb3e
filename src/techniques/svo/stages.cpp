// The octree stages of svo (overview and references in svo.cpp).
#include "techniques/svo/stages.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "common/shared.h"
#include "core/error.h"
#include "gpu/shader_library.h"
#include "techniques/common/cone_layout.h"
#include "techniques/common/cone_setup.h"
#include "techniques/common/fragment_light.h"
#include "techniques/common/light_stage.h"
#include "techniques/common/probe_recorder.h"
#include "techniques/common/sky.h"
#include "techniques/common/traced_image.h"
#include "techniques/common/voxel_space.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/vct_grid/stages.h"

namespace voxlab::svo {

static constexpr float kDegrees = 3.14159265358979f / 180.0f;
// Nodes of sentinel words kept after the node pool's capacity: a pass that wrote past the end
// would change them (tests/unit/test_svo.cpp checks they survive an overflow).
static constexpr uint32_t kGuardNodes = 8;
static constexpr uint32_t kGuardWord = 0xA5A5A5A5u;

int octreeDepth(const ParamSet& params) {
  int res = params.getInt("voxel.resolution"), depth = 0;
  while ((1 << depth) < res) ++depth;
  return depth;
}

std::vector<SvoLevel> readLevels(Blackboard& board) {
  const Buffer& b = board.buffer("svo-levels");
  std::vector<uint8_t> bytes = b.download();
  std::vector<SvoLevel> levels(bytes.size() / sizeof(SvoLevel));
  std::memcpy(levels.data(), bytes.data(), levels.size() * sizeof(SvoLevel));
  return levels;
}

uint32_t nodeCount(const std::vector<SvoLevel>& levels) {
  uint32_t end = 0;
  for (const auto& l : levels) end = std::max(end, l.start + l.count);
  return end;
}

static std::vector<uint32_t> readCounters(Blackboard& board) {
  std::vector<uint8_t> bytes = board.buffer("svo-counters").download(SVO_COUNTER_WORDS * 4);
  std::vector<uint32_t> c(SVO_COUNTER_WORDS);
  std::memcpy(c.data(), bytes.data(), c.size() * 4);
  return c;
}

// The fraction of its exactly counted size a pool gets: 1 = exact; below 1 only to see the overflow
// check fail. One per pool, so that the brick pool can be undersized behind an exact node pool.
static ParamDesc nodePoolFractionParam() {
  return ParamDesc::real("svo.node-pool-fraction", 1.0, 0.01, 1.0,
                         "fraction of the exactly counted size the node pool gets (1 = exact; below 1 only to "
                         "see svo-build's overflow check fail)");
}
static ParamDesc brickPoolFractionParam() {
  return ParamDesc::real("svo.brick-pool-fraction", 1.0, 0.01, 1.0,
                         "fraction of the exactly counted size the brick pool gets (1 = exact; below 1 only to "
                         "see svo-bricks' overflow check fail)");
}
static ParamDesc dilateParam() {
  return ParamDesc::boolean("svo.dilate", false,
                            "also subdivide the 26 neighbours of every non-empty node, so the octree equals the "
                            "dense grid everywhere (off: Basgier's octree, with quad-like artefacts at its borders)");
}

static ParamDesc layoutParam() {
  return ParamDesc::choice("svo.layout", {"node", "tile"}, 0,
                           "node (Basgier, Layout N): a 3x3x3 node-centred brick per non-empty node, leaves included, "
                           "exactly vct-grid's mip levels; tile (Crassin/Gomes, Layout T): one brick per subdivided node "
                           "at its children's corners, none for leaves (about a fifth of the memory, the finest level "
                           "blurred by [1 2 1] / 4 per axis)");
}
static bool tileLayout(const ParamSet& p) { return p.getChoice("svo.layout") == "tile"; }
// vct-grid's parameter name, so that one --set mipmap.mode=... picks the same mips in both.
static ParamDesc mipmapModeParam() {
  return ParamDesc::choice("mipmap.mode", {"isotropic", "anisotropic"}, 1,
                           "isotropic: one brick per node, the average of its children (vct-grid's isotropic mips "
                           "exactly); anisotropic: above the voxels six more bricks per node, one per travel "
                           "direction, compositing the children front to back before averaging (Crassin et al., "
                           "vct-grid's default); the cones read the three facing the cone, weighted dir^2. Layout N "
                           "only: svo.layout=tile stays isotropic");
}
// Directional bricks are built and read: anisotropic mips with Layout N.
static bool anisotropicBricks(const ParamSet& p) {
  return p.getChoice("mipmap.mode") == "anisotropic" && !tileLayout(p);
}
static size_t directionalValueBytes(uint32_t nodes) {
  return size_t(std::max(1u, (nodes - 1) / 8)) * SVO_DIRECTIONAL_RECORD * 16;
}
// vct-grid's parameter names and defaults, so that one --set picks the same rule in both.
static ParamDesc frontsParam() {
  return ParamDesc::boolean("mipmap.fronts", true,
                            "directional bricks show a voxel's light only to the directions that see its surfaces' "
                            "fronts, its opacity kept apart as a solid cube's in one more RGBA8 brick per node (vct-grid's "
                            "rule; false: Crassin's classic reduction, every voxel seen from all sides)");
}
// The fronts rule is in use: directional bricks whose alpha is the fronts' coverage, and the solid
// opacity bricks beside them.
static bool frontsBricks(const ParamSet& p) { return anisotropicBricks(p) && p.getBool("mipmap.fronts"); }

static ParamDesc voxelFormatParam() {
  return ParamDesc::choice("voxel.format", {"rgba8", "rgba16f"}, 1,
                           "what the bricks store: rgba16f keeps radiance up to 64 W/(m^2 sr) in half floats (HDR, "
                           "vct-grid's default); rgba8 clamps each fragment's radiance to [0,1] (half the brick "
                           "memory: the voxels by a lamp or in the sun lose most of their light)");
}
static bool hdrBricks(const ParamSet& p) { return p.getChoice("voxel.format") == "rgba16f"; }
// HDR bricks of Layout N are RGBA8 with one scale per brick and part (the largest radiance
// channel of its 27 texels; shared-exponent blocks): a sample never filters across two bricks, so
// the scaled texels filter exactly, and llvmpipe filters RGBA8 on a faster path than half floats
// (a 512x512 Cornell run 0.6 s less CPU). Layout T's Gaussian pass filters across bricks: half floats.
static bool scaledBricks(const ParamSet& p) { return hdrBricks(p) && !tileLayout(p); }
static GLenum brickFormat(const ParamSet& p) { return hdrBricks(p) && !scaledBricks(p) ? GL_RGBA16F : GL_RGBA8; }
// The dense view holds the node values as they are: half floats when HDR.
static GLenum denseFormat(const ParamSet& p) { return hdrBricks(p) ? GL_RGBA16F : GL_RGBA8; }
static std::string denseFormatDefines(const ParamSet& p) {
  return hdrBricks(p) ? "#define VOXLAB_GRID_FORMAT rgba16f\n" : "";
}
// Scales per brick number: the isotropic brick's, then the six directional bricks' (+x -x +y -y +z -z), one unused.
static constexpr size_t kBrickScaleFloats = 8;
// What a leaf can hold: vct-grid's limits (64 in half floats, 1 in RGBA8).
static float maxLeafRadiance(const ParamSet& p) { return hdrBricks(p) ? vct::kHdrMaxRadiance : 1.0f; }
static std::string brickFormatDefines(const ParamSet& p) {
  if (scaledBricks(p)) return "#define SVO_SCALED_BRICKS 1\n";
  return hdrBricks(p) ? "#define VOXLAB_GRID_FORMAT rgba16f\n" : "";
}
// The cone trace's switches as defines (svo/cone_trace.comp.glsl): a parameter picks another
// program, so the reads of the modes not chosen are not compiled in (on llvmpipe a branch on a
// uniform still runs both sides).
// traceShadow, traceSpecular: every pixel traces the soft-shadow or specular cone (its image is wanted).
static std::string coneTraceDefines(const ParamSet& p, bool traceShadow, bool traceSpecular) {
  auto flag = [](const char* name, bool on) { return std::string("#define ") + name + (on ? " 1\n" : " 0\n"); };
  // With dilation every voxel next to a filled one has its brick: the halo reads would add 0.
  const bool voxelHalo = p.getBool("svo.voxel-halo") && !p.getBool("svo.dilate") && !tileLayout(p);
  return flag("SVO_DILATED", p.getBool("svo.dilate")) + flag("SVO_LAYOUT_TILE", tileLayout(p)) +
         flag("SVO_ANISOTROPIC", anisotropicBricks(p)) + flag("SVO_FRONTS", frontsBricks(p)) +
         flag("SVO_VOXEL_HALO", voxelHalo) + flag("SVO_AO_CONES", p.getChoice("ao.cones") != "diffuse") +
         flag("SVO_SHADOW_CONE", traceShadow) + flag("SVO_SPECULAR_CONE", traceSpecular) + (scaledBricks(p) ? "#define SVO_SCALED_BRICKS 1\n" : "");
}
static ParamDesc filterParam() {
  return ParamDesc::choice("svo.filter", {"box", "gaussian"}, 0,
                           "bricks above the finest level with svo.layout=tile: box (vertex means of the box-filtered "
                           "nodes) or Crassin/Gomes' Gaussian 1/8-1/16-1/32-1/64 of the level below's bricks; with "
                           "the node layout the Gaussian collapses to the box (the note) and is not applied");
}

static void barrierAll() { glMemoryBarrier(GL_ALL_BARRIER_BITS); }

// The voxel-resolution 3D views (declared and allocated from the same descs).
static TextureDesc structureDesc(const ParamSet& p) {
  const int res = p.getInt("voxel.resolution");
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = GL_R8;
  d.size = {res, res, res};
  d.levels = 0;
  d.minFilter = GL_NEAREST_MIPMAP_NEAREST;
  d.magFilter = GL_NEAREST;
  return d;
}
static TextureDesc denseDesc(const ParamSet& p) {
  const int res = p.getInt("voxel.resolution");
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = denseFormat(p);
  d.size = {res, res, res};
  d.levels = 0;
  d.minFilter = GL_LINEAR_MIPMAP_LINEAR;
  return d;
}
// Per-node buffers are sized from the node count at run time: declared as pools starting at the
// root alone (the least any octree has).
static size_t perNodeStart(size_t bytesPerNode) { return bytesPerNode; }
static size_t levelsBytes(const ParamSet& p) { return sizeof(SvoLevel) * size_t(octreeDepth(p) + 1); }
static constexpr size_t kCounterBytes = SVO_COUNTER_WORDS * 4;

// "svo-groups": one zeroed counter per work group of 64 items.
static Buffer& zeroGroups(Blackboard& board, uint32_t items) {
  const uint32_t groups = std::max(1u, (items + 63) / 64);
  Buffer& b = board.ensureBuffer("svo-groups", size_t(groups) * 4);
  std::vector<uint32_t> zero(groups, 0u);
  b.upload(zero.data(), zero.size() * 4);
  return b;
}
// Turns the per-group counts into exclusive prefix sums (in place).
static void scanGroups(Buffer& b, uint32_t items) {
  const uint32_t groups = std::max(1u, (items + 63) / 64);
  std::vector<uint8_t> bytes = b.download(size_t(groups) * 4);
  std::vector<uint32_t> v(groups);
  std::memcpy(v.data(), bytes.data(), v.size() * 4);
  uint32_t sum = 0;
  for (auto& x : v) {
    uint32_t c = x;
    x = sum;
    sum += c;
  }
  b.upload(v.data(), v.size() * 4);
}

// The node pool "svo-nodes" with room for 'capacity' nodes plus the guard, keeping its first
// 'used' nodes when it has to grow.
static Buffer& ensureNodePool(Blackboard& board, uint32_t used, uint32_t capacity) {
  const size_t bytes = size_t(capacity + kGuardNodes) * sizeof(SvoNode);
  if (!board.hasBuffer("svo-nodes") || board.buffer("svo-nodes").size() < bytes) {
    const size_t keep = size_t(used) * sizeof(SvoNode);
    Buffer copy;
    if (keep && board.hasBuffer("svo-nodes")) {
      copy = Buffer("svo-nodes.grow", keep);
      glCopyNamedBufferSubData(board.buffer("svo-nodes").id(), copy.id(), 0, 0, GLsizeiptr(keep));
    }
    Buffer& pool = board.ensureBuffer("svo-nodes", bytes);
    if (copy.id()) glCopyNamedBufferSubData(copy.id(), pool.id(), 0, 0, GLsizeiptr(keep));
  }
  Buffer& pool = board.buffer("svo-nodes");
  std::vector<uint32_t> guard(kGuardNodes * 4, kGuardWord);
  pool.upload(guard.data(), guard.size() * 4, size_t(capacity) * sizeof(SvoNode));
  return pool;
}

// --- svo-build -------------------------------------------------------------------------------------

void BuildStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(dilateParam());
  b.param(nodePoolFractionParam());
  b.read("fragments");
  b.read("fragments.count");
  b.write("svo-groups");
  BufferLayout nodes;
  nodes.stride = sizeof(SvoNode);
  nodes.fields = {{"word", FieldType::U32, 0}, {"coords", FieldType::Packed10_10_10, 4},
                  {"level", FieldType::U32, 8}, {"parent", FieldType::U32, 12}};
  nodes.countResource = "svo-counters";
  nodes.countOffset = 4 * 6;  // SVO_COUNTER_WORDS slot 6: nodes written (set by the stage)
  b.output("svo-nodes", OutputKind::Buffer, kOctreeNodes,
           "the node pool: flags (31 tag, 30 non-empty) + first child, cell at its level, level, parent; levels "
           "contiguous, root = node 0")
      .layout = nodes;
  BufferLayout levels;
  levels.stride = sizeof(SvoLevel);
  levels.fields = {{"start", FieldType::U32, 0}, {"count", FieldType::U32, 4}, {"non_empty", FieldType::U32, 8},
                   {"tagged", FieldType::U32, 12}};
  b.output("svo-levels", OutputKind::Buffer, kOctreeLevels,
           "per level: first node, nodes, non-empty nodes (distinct occupied cells), tagged (subdivided / with a brick)")
      .layout = levels;
  b.output("svo-structure", OutputKind::Volume3D, Semantic::Fraction,
           "the octree's nodes as a volume: mip m shows level D - m (1 non-empty, 0.6 dilated, 0.3 empty sibling, "
           "0 no node); overlay a level on the camera images to see its node boxes in the scene")
      .onDemand = true;  // a view: the octree is the node pool
  b.output("svo-counters", OutputKind::Buffer, Semantic::Scalar,
           "counters: tiles, overflow flag, level non-empty, level tagged, -, -, nodes written")
      .layout = BufferLayout{4, {{"value", FieldType::U32, 0}}, "", 0, 1.0f};
  b.texture("svo-structure", [](const ParamSet& p, const ViewState&) { return structureDesc(p); });
  b.buffer("svo-counters", [](const ParamSet&, const ViewState&) { return kCounterBytes; });
  b.buffer("svo-levels", [](const ParamSet& p, const ViewState&) { return levelsBytes(p); });
  // Grows level by level from the root (+ the guard) to what the scene's fragments need.
  b.buffer("svo-nodes", [](const ParamSet&, const ViewState&) { return size_t(1 + kGuardNodes) * sizeof(SvoNode); },
           /*pool=*/true);
  b.buffer("svo-groups", [](const ParamSet&, const ViewState&) { return size_t(4); }, /*pool=*/true);
}

void BuildStage::execute(StageContext& ctx) {
  const int depth = octreeDepth(ctx.params);
  const int level = ctx.iteration;
  const bool dilate = ctx.params.getBool("svo.dilate");
  const double fraction = ctx.params.getFloat("svo.node-pool-fraction");
  Buffer& counters = ctx.board.ensureBuffer("svo-counters", kCounterBytes);
  Buffer& levelBuffer = ctx.board.ensureBuffer("svo-levels", levelsBytes(ctx.params));
  std::vector<SvoLevel> levels(depth + 1, SvoLevel{0, 0, 0, 0});
  if (level == 0) {
    // svo-init: the root alone, every counter 0.
    std::vector<uint32_t> zero(SVO_COUNTER_WORDS, 0u);
    counters.upload(zero.data(), zero.size() * 4);
    levels[0] = {0, 1, 0, 0};
    levelBuffer.upload(levels.data(), levels.size() * sizeof(SvoLevel));
    Buffer& pool = ensureNodePool(ctx.board, 0, 1);
    SvoNode root{0, 0, 0, 0};
    pool.upload(&root, sizeof root);
  } else {
    levels = readLevels(ctx.board);
  }
  const SvoLevel current = levels[level];
  const uint32_t fragments = voxelFragmentCount(ctx.board);
  Buffer* pool = &ctx.board.buffer("svo-nodes");

  Buffer& groups = zeroGroups(ctx.board, current.count);
  auto bindAll = [&](GLuint program) {
    glUseProgram(program);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_GROUPS, groups.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, ctx.board.buffer("fragments").id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_NODES, pool->id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_COUNTERS, counters.id());
  };
  // 1. flag: the nodes of this level holding fragments.
  GLuint flag = ctx.shaders.program({"svo/flag.comp.glsl"});
  setUniform(flag, "u_fragmentCount", unsigned(fragments));
  setUniform(flag, "u_depth", depth);
  setUniform(flag, "u_level", level);
  bindAll(flag);
  if (fragments) dispatchCompute({int(fragments), 1, 1}, {64, 1, 1});
  barrierAll();

  // A program per pass (svo/level_pass.comp.glsl): dilate, count, allocate.
  GLuint passes[3];
  for (int which = 0; which < 3; ++which) {
    const GLuint pass =
        ctx.shaders.program({"svo/level_pass.comp.glsl"}, "#define SVO_LEVEL_PASS " + std::to_string(which) + "\n");
    setUniform(pass, "u_start", unsigned(current.start));
    setUniform(pass, "u_count", unsigned(current.count));
    setUniform(pass, "u_depth", depth);
    setUniform(pass, "u_level", level);
    passes[which] = pass;
  }
  auto runPass = [&](int which, uint32_t capacity) {
    const GLuint pass = passes[which];
    setUniform(pass, "u_capacity", unsigned(capacity));
    bindAll(pass);
    dispatchCompute({int(current.count), 1, 1}, {64, 1, 1});
    barrierAll();
  };
  // 2. dilate (optional): their neighbours too.
  if (dilate) runPass(0, 0);
  // 3. count: non-empty and tagged nodes of the level.
  const uint32_t zeros[2] = {0, 0};
  counters.upload(zeros, 8, SVO_COUNTER_NON_EMPTY * 4);
  runPass(1, 0);
  std::vector<uint32_t> c = readCounters(ctx.board);
  scanGroups(groups, current.count);
  levels[level].nonEmpty = c[SVO_COUNTER_NON_EMPTY];
  levels[level].tagged = c[SVO_COUNTER_TAGGED];
  const uint32_t used = current.start + current.count;
  // 4. allocate + init: the next level, in a pool sized from the count just made.
  if (level < depth) {
    const uint32_t needed = used + 8u * levels[level].tagged;
    const uint32_t capacity = fraction >= 1.0 ? needed : std::max(used, uint32_t(std::floor(needed * fraction)));
    pool = &ensureNodePool(ctx.board, used, capacity);
    setUniform(passes[2], "u_tilesBefore", unsigned((used - 1) / 8));
    runPass(2, capacity);
    const uint32_t tiles = (used - 1) / 8 + levels[level].tagged;
    counters.upload(&tiles, 4, SVO_COUNTER_TILES * 4);
    c = readCounters(ctx.board);
    if (c[SVO_COUNTER_OVERFLOW])
      throw Error("svo-build: node pool overflow at level " + std::to_string(level + 1) + ": it holds " +
                  std::to_string(capacity) + " nodes, the level needs " + std::to_string(1 + 8 * c[SVO_COUNTER_TILES]) +
                  " (svo.node-pool-fraction=" + ctx.params.desc("svo.node-pool-fraction").format(fraction) +
                  "; 1 sizes the pool exactly)");
    levels[level + 1] = {used, 8u * levels[level].tagged, 0, 0};
  }
  levelBuffer.upload(levels.data(), levels.size() * sizeof(SvoLevel));
  // The structure view of this level (mip D - level), now that its flags are final.
  if (ctx.wants("svo-structure")) {
    Texture& structure = ctx.board.ensureTexture("svo-structure", structureDesc(ctx.params));
    if (level == 0) {
      const uint8_t zero = 0;
      for (int m = 0; m < structure.levels(); ++m) glClearTexImage(structure.id(), m, GL_RED, GL_UNSIGNED_BYTE, &zero);
    }
    GLuint view = ctx.shaders.program({"svo/structure.comp.glsl"});
    setUniform(view, "u_start", unsigned(current.start));
    setUniform(view, "u_count", unsigned(current.count));
    glUseProgram(view);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_NODES, pool->id());
    glBindImageTexture(0, structure.id(), depth - level, GL_TRUE, 0, GL_WRITE_ONLY, GL_R8);
    dispatchCompute({int(current.count), 1, 1}, {64, 1, 1});
    barrierAll();
  }
  const uint32_t total = nodeCount(levels);
  counters.upload(&total, 4, 6 * 4);
  barrierAll();

  ctx.stats["depth"] = depth;
  ctx.stats["level"] = level;
  ctx.stats["level_nodes"] = current.count;
  ctx.stats["level_non_empty"] = levels[level].nonEmpty;
  ctx.stats["level_tagged"] = levels[level].tagged;
  ctx.stats["nodes"] = total;
  ctx.stats["node_pool_bytes"] = double(total) * sizeof(SvoNode);
  for (int l = 0; l <= level; ++l)
    ctx.stats["non_empty_level_" + std::to_string(l)] = levels[l].nonEmpty;
}

// --- svo-neighbours --------------------------------------------------------------------------------

void NeighboursStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.read("svo-nodes");
  b.read("svo-levels");
  b.read("svo-counters");
  BufferLayout links;
  links.stride = 6 * sizeof(uint32_t);
  const char* names[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  for (uint32_t d = 0; d < 6; ++d) links.fields.push_back({names[d], FieldType::U32, 4 * d});
  links.countResource = "svo-counters";
  links.countOffset = 4 * 6;  // nodes written
  b.output("svo-neighbour-links", OutputKind::Buffer, Semantic::Scalar,
           "per node: the same-level node across each face (+x, -x, +y, -y, +z, -z), 4294967295 = none")
      .layout = links;
  b.buffer("svo-neighbour-links", [](const ParamSet&, const ViewState&) { return perNodeStart(24); }, /*pool=*/true);
}

void NeighboursStage::execute(StageContext& ctx) {
  std::vector<SvoLevel> levels = readLevels(ctx.board);
  const uint32_t nodes = nodeCount(levels);
  Buffer& links = ctx.board.ensureBuffer("svo-neighbour-links", size_t(nodes) * 24);
  GLuint program = ctx.shaders.program({"svo/neighbours.comp.glsl"});
  setUniform(program, "u_nodeCount", unsigned(nodes));
  setUniform(program, "u_depth", octreeDepth(ctx.params));
  glUseProgram(program);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_NODES, ctx.board.buffer("svo-nodes").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_NEIGHBOURS, links.id());
  dispatchCompute({int(nodes), 1, 1}, {64, 1, 1});
  barrierAll();
  std::vector<uint8_t> bytes = links.download(size_t(nodes) * 24);
  size_t found = 0;
  for (size_t i = 0; i < size_t(nodes) * 6; ++i) {
    uint32_t v;
    std::memcpy(&v, &bytes[i * 4], 4);
    found += v != SVO_ABSENT;
  }
  ctx.stats["nodes"] = nodes;
  ctx.stats["links"] = double(found);
}

// --- svo-leaves ------------------------------------------------------------------------------------

static BufferLayout valueLayout() {
  BufferLayout v;
  v.stride = 16;
  v.fields = {{"value", FieldType::Vec4, 0, FieldRole::Color}};
  v.countResource = "svo-counters";
  v.countOffset = 4 * 6;
  return v;
}

void LeavesStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(voxelFormatParam());
  declareFragmentLightParams(b);
  b.read("fragments");
  b.read("fragments.count");
  b.read("svo-nodes");
  b.read("svo-levels");
  b.read("svo-counters");
  b.read("shadow-map");
  b.read("light");
  b.write("svo-leaf-sums");
  b.output("svo-leaf-values", OutputKind::Buffer, Semantic::Color,
           "per node: its leaf's mean outgoing radiance (premultiplied) and opacity 1; 0 for inner nodes")
      .layout = valueLayout();
  BufferLayout facing{4, {{"facing", FieldType::U32, 0}}, "svo-counters", 4 * 6, 1.0f};
  b.output("svo-leaf-facing", OutputKind::Buffer, Semantic::Scalar,
           "per node: its leaf's facing code, the OR of its fragments' (common/facing.glsl: per travel direction of a "
           "cone, how much of the leaf's surfaces' fronts it sees, 5 bits each); 0 for inner nodes")
      .layout = facing;
  b.buffer("svo-leaf-facing", [](const ParamSet&, const ViewState&) { return perNodeStart(4); }, /*pool=*/true);
  b.buffer("svo-leaf-sums", [](const ParamSet&, const ViewState&) { return perNodeStart(16); }, /*pool=*/true);
  b.buffer("svo-leaf-values", [](const ParamSet&, const ViewState&) { return perNodeStart(16); }, /*pool=*/true);
}

void LeavesStage::execute(StageContext& ctx) {
  const int depth = octreeDepth(ctx.params);
  VoxelSpace space = VoxelSpace::fromScene(ctx.scene, ctx.params.getInt("voxel.resolution"));
  std::vector<SvoLevel> levels = readLevels(ctx.board);
  const uint32_t nodes = nodeCount(levels);
  Buffer& sums = ctx.board.ensureBuffer("svo-leaf-sums", size_t(nodes) * 16);
  Buffer& values = ctx.board.ensureBuffer("svo-leaf-values", size_t(nodes) * 16);
  Buffer& facing = ctx.board.ensureBuffer("svo-leaf-facing", size_t(nodes) * 4);
  glClearNamedBufferData(facing.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
  glClearNamedBufferData(sums.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
  glClearNamedBufferData(values.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
  const uint32_t fragments = voxelFragmentCount(ctx.board);
  // A program per pass (svo/leaves.comp.glsl): the fragments' lighting, then the leaves' means.
  const GLuint lighting =
      ctx.shaders.program({"svo/leaves.comp.glsl"}, lightKindDefines(ctx.scene) + "#define SVO_LEAVES_PASS 0\n");
  const GLuint means = ctx.shaders.program({"svo/leaves.comp.glsl"}, lightKindDefines(ctx.scene) + "#define SVO_LEAVES_PASS 1\n");
  for (GLuint program : {lighting, means}) {
    space.setUniforms(program);
    setUniform(program, "u_fragmentCount", unsigned(fragments));
    setUniform(program, "u_depth", depth);
    setUniform(program, "u_start", unsigned(levels[depth].start));
    setUniform(program, "u_count", unsigned(levels[depth].count));
    setUniform(program, "u_maxRadiance", maxLeafRadiance(ctx.params));
    setFragmentLightUniforms(program, ctx.params, space);
  }
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, ctx.board.buffer("fragments").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_NODES, ctx.board.buffer("svo-nodes").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_LEAF_SUMS, sums.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_VALUES, values.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_LEAF_FACING, facing.id());
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  glBindTextureUnit(2, ctx.board.texture("shadow-map").id());
  glUseProgram(lighting);
  if (fragments) dispatchCompute({int(fragments), 1, 1}, {64, 1, 1});
  barrierAll();
  glUseProgram(means);
  dispatchCompute({int(levels[depth].count), 1, 1}, {64, 1, 1});
  barrierAll();
  ctx.stats["fragments"] = fragments;
  ctx.stats["leaves"] = levels[depth].nonEmpty;
}

// --- svo-mipmap ------------------------------------------------------------------------------------

void MipmapStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(layoutParam());
  b.param(mipmapModeParam());
  b.param(frontsParam());
  b.param(voxelFormatParam());
  b.read("svo-nodes");
  b.read("svo-levels");
  b.read("svo-counters");
  b.read("svo-leaf-values");
  b.read("svo-leaf-facing");
  b.output("svo-values", OutputKind::Buffer, Semantic::Color,
           "per node: the filtered premultiplied radiance and opacity at its centre (leaves: svo-leaf-values)")
      .layout = valueLayout();
  b.output("svo-dense", OutputKind::Volume3D, Semantic::Color,
           "the octree resampled into a dense view: mip m holds the node values of level D - m (0 where no node), "
           "so it can be set beside vct-grid's radiance; alpha = opacity (the viewer's channel a)")
      .onDemand = true;  // a view for the viewer and the tests: nothing later reads it
  BufferLayout directional;
  directional.stride = SVO_DIRECTIONAL_RECORD * 16;
  const char* names[SVO_DIRECTIONAL_RECORD] = {"+x", "-x", "+y", "-y", "+z", "-z", "solid x y z"};
  for (uint32_t d = 0; d < SVO_DIRECTIONAL_RECORD; ++d)
    directional.fields.push_back({names[d], FieldType::Vec4, 16 * d, FieldRole::Color});
  b.output("svo-directional-values", OutputKind::Buffer, Semantic::Color,
           "per node with children, in the order of their tiles: the node as seen by a cone travelling along +x, -x, "
           "+y, -y, +z, -z (anisotropic mips; with mipmap.fronts the fronts only), then its solid opacity seen "
           "along x, y, z (rgb, the same travelling either way; mipmap.fronts); one empty record with "
           "mipmap.mode=isotropic")
      .layout = directional;
  b.buffer("svo-values", [](const ParamSet&, const ViewState&) { return perNodeStart(16); }, /*pool=*/true);
  b.buffer("svo-directional-values", [](const ParamSet&, const ViewState&) { return directionalValueBytes(1); },
           /*pool=*/true);
  b.texture("svo-dense", [](const ParamSet& p, const ViewState&) { return denseDesc(p); });
}

void MipmapStage::execute(StageContext& ctx) {
  const int depth = octreeDepth(ctx.params);
  const int k = ctx.iteration;
  std::vector<SvoLevel> levels = readLevels(ctx.board);
  const uint32_t nodes = nodeCount(levels);
  Buffer& values = ctx.board.ensureBuffer("svo-values", size_t(nodes) * 16);
  const bool anisotropic = anisotropicBricks(ctx.params);
  Buffer& directional =
      ctx.board.ensureBuffer("svo-directional-values", directionalValueBytes(anisotropic ? nodes : 1));
  Texture* dense = ctx.wants("svo-dense") ? &ctx.board.ensureTexture("svo-dense", denseDesc(ctx.params)) : nullptr;
  Buffer& nodePool = ctx.board.buffer("svo-nodes");
  GLuint resample = ctx.shaders.program({"svo/resample.comp.glsl"}, denseFormatDefines(ctx.params));
  auto writeDense = [&](int mip) {
    if (!dense) return;
    const SvoLevel& level = levels[depth - mip];
    setUniform(resample, "u_start", unsigned(level.start));
    setUniform(resample, "u_count", unsigned(level.count));
    glUseProgram(resample);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_NODES, nodePool.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_VALUES, values.id());
    glBindImageTexture(0, dense->id(), mip, GL_TRUE, 0, GL_WRITE_ONLY, denseFormat(ctx.params));
    dispatchCompute({int(level.count), 1, 1}, {64, 1, 1});
    barrierAll();
  };
  if (k == 0) {
    glCopyNamedBufferSubData(ctx.board.buffer("svo-leaf-values").id(), values.id(), 0, 0, GLsizeiptr(nodes) * 16);
    const uint8_t zero[4] = {0, 0, 0, 0};
    if (dense)
      for (int m = 0; m < dense->levels(); ++m) glClearTexImage(dense->id(), m, GL_RGBA, GL_UNSIGNED_BYTE, zero);
    barrierAll();
    writeDense(0);
  }
  const int level = depth - 1 - k;
  const bool childrenAreVoxels = level + 1 == depth;
  GLuint program = ctx.shaders.program({"svo/mipmap.comp.glsl"}, childrenAreVoxels ? "#define SVO_CHILDREN_ARE_VOXELS 1\n"
                                                                                   : "#define SVO_CHILDREN_ARE_VOXELS 0\n");
  setUniform(program, "u_start", unsigned(levels[level].start));
  setUniform(program, "u_count", unsigned(levels[level].count));
  setUniform(program, "u_anisotropic", anisotropic ? 1 : 0);
  setUniform(program, "u_fronts", frontsBricks(ctx.params) ? 1 : 0);
  glUseProgram(program);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_NODES, nodePool.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_VALUES, values.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_DIRECTIONAL_VALUES, directional.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_LEAF_FACING, ctx.board.buffer("svo-leaf-facing").id());
  dispatchCompute({int(levels[level].count), 1, 1}, {64, 1, 1});
  barrierAll();
  writeDense(k + 1);
  ctx.stats["level_filtered"] = level;
  ctx.stats["anisotropic"] = anisotropic ? 1 : 0;
  ctx.stats["levels_done"] = k + 2;
}

// --- svo-bricks ------------------------------------------------------------------------------------

static glm::ivec3 bricksPerAxis(uint32_t bricks) {
  int side = std::max(1, int(std::ceil(std::cbrt(double(bricks)) - 1e-9)));
  while (uint64_t(side) * side * side < bricks) ++side;
  int z = int((bricks + uint64_t(side) * side - 1) / (uint64_t(side) * side));
  return {side, side, std::max(z, 1)};
}

// The brick pool's texture for 'bricks' bricks: 3x3x3 texels each (RGBA8, or RGBA16F with
// voxel.format=rgba16f), laid out by bricksPerAxis.
static TextureDesc brickPoolDesc(uint32_t bricks, GLenum format) {
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = format;
  d.size = 3 * bricksPerAxis(bricks);
  d.levels = 1;
  d.minFilter = d.magFilter = GL_LINEAR;
  return d;
}

// The directional brick pool for 'bricks' bricks per direction: six parts stacked along z, part d
// (+x -x +y -y +z -z) holding every brick's direction d at the place bricksPerAxis gives it.
static TextureDesc directionalPoolDesc(uint32_t bricks, const ParamSet& p) {
  TextureDesc d = brickPoolDesc(bricks, brickFormat(p));
  d.size.z *= 6;
  return d;
}
// The solid-opacity bricks (mipmap.fronts) of the same bricks, laid out as one part of the
// directional pool: the opacity seen along x, y, z (rgb, the same travelling either way). Opacity
// lies in [0, 1]: RGBA8, as vct-grid's solid-opacity volume (and llvmpipe filters RGBA8 faster than
// half floats).
static TextureDesc opacityPoolDesc(uint32_t bricks) { return brickPoolDesc(bricks, GL_RGBA8); }

void BricksStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(brickPoolFractionParam());
  b.param(layoutParam());
  b.param(filterParam());
  b.param(mipmapModeParam());
  b.param(frontsParam());
  b.param(voxelFormatParam());
  b.read("svo-nodes");
  b.read("svo-levels");
  b.read("svo-counters");
  b.read("svo-values");
  b.read("svo-directional-values");
  b.read("svo-groups");  // svo-build's last level: prefix sums of the tagged voxels per group of 64
  b.write("svo-brick-counters");
  b.output("svo-brick-index", OutputKind::Buffer, Semantic::Scalar,
           "per node: its brick in the pool (0 = the reserved zero brick: untagged nodes)")
      .layout = BufferLayout{4, {{"brick", FieldType::U32, 0}}, "svo-counters", 4 * 6, 1.0f};
  b.output("svo-brick-pool", OutputKind::Volume3D, Semantic::Color,
           "the brick pool: 3x3x3 texels per brick (brick b at 3 * (b mod X, b / X mod Y, b / XY)), premultiplied "
           "radiance + opacity; borders = means of the nodes sharing the texel");
  // The brick pool is sized from the tagged-node count at run time: declared as a pool texture
  // whose start is the smallest pool (the zero brick and the root's).
  b.output("svo-directional-bricks", OutputKind::Volume3D, Semantic::Color,
           "the directional bricks (mipmap.mode=anisotropic): six parts stacked along z (+x, -x, +y, -y, +z, -z), each "
           "with one 3x3x3 brick per node above the voxels at the place of its brick number; the node as seen by a cone "
           "travelling that way (with mipmap.fronts the fronts only), borders = means of the nodes sharing the texel "
           "(one empty brick when isotropic)");
  b.output("svo-opacity-bricks", OutputKind::Volume3D, Semantic::Color,
           "the solid-opacity bricks (mipmap.fronts): the opacity of the voxels as cubes seen along x, y, z (rgb, the "
           "same travelling either way), laid out as one part of the directional bricks (one empty brick without "
           "the fronts rule)");
  b.texture("svo-brick-pool", [](const ParamSet& p, const ViewState&) { return brickPoolDesc(2, brickFormat(p)); },
            /*pool=*/true);
  b.texture("svo-directional-bricks", [](const ParamSet& p, const ViewState&) { return directionalPoolDesc(1, p); },
            /*pool=*/true);
  b.texture("svo-opacity-bricks", [](const ParamSet&, const ViewState&) { return opacityPoolDesc(1); }, /*pool=*/true);
  BufferLayout scales;
  scales.stride = kBrickScaleFloats * 4;
  const char* scaleNames[kBrickScaleFloats] = {"isotropic", "+x", "-x", "+y", "-y", "+z", "-z", "unused"};
  for (uint32_t k = 0; k < kBrickScaleFloats; ++k) scales.fields.push_back({scaleNames[k], FieldType::F32, 4 * k});
  b.output("svo-brick-scales", OutputKind::Buffer, Semantic::Scalar,
           "per brick number, with HDR bricks (voxel.format=rgba16f, Layout N): the scale of its isotropic brick's "
           "radiance and of its six directional bricks' (the largest radiance channel of the brick's texels, which "
           "hold radiance / scale in RGBA8); 1 otherwise")
      .layout = scales;
  b.buffer("svo-brick-scales", [](const ParamSet&, const ViewState&) { return kBrickScaleFloats * 4 * 2; },
           /*pool=*/true);
  b.buffer("svo-brick-index", [](const ParamSet&, const ViewState&) { return perNodeStart(4); }, /*pool=*/true);
  b.buffer("svo-brick-counters", [](const ParamSet&, const ViewState&) { return kCounterBytes; });
}

void BricksStage::execute(StageContext& ctx) {
  const int depth = octreeDepth(ctx.params);
  std::vector<SvoLevel> levels = readLevels(ctx.board);
  const uint32_t nodes = nodeCount(levels);
  const bool tile = tileLayout(ctx.params);
  // Layout N: a brick per tagged node; Layout T: per tagged node above the voxels (subdivided).
  uint32_t tagged = 0;
  for (int l = 0; l <= depth; ++l)
    if (!tile || l < depth) tagged += levels[l].tagged;
  const uint32_t needed = tagged + 1;  // + the zero brick
  const double fraction = ctx.params.getFloat("svo.brick-pool-fraction");
  const uint32_t capacity = fraction >= 1.0 ? needed : std::max(1u, uint32_t(std::floor(needed * fraction)));
  if (capacity > SVO_MAX_BRICKS)
    throw Error("svo-bricks: the brick pool needs " + std::to_string(capacity) + " bricks, more than the " +
                std::to_string(SVO_MAX_BRICKS) + " the cone tracer can address (use a lower voxel.resolution)");
  glm::ivec3 axis = bricksPerAxis(capacity);
  GLint maxSize = 0;
  glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &maxSize);
  if (3 * std::max(axis.x, axis.z) > maxSize)
    throw Error("svo-bricks: the brick pool needs " + std::to_string(capacity) + " bricks, " +
                std::to_string(3 * std::max(axis.x, axis.z)) + " texels along an axis, beyond GL_MAX_3D_TEXTURE_SIZE " +
                std::to_string(maxSize) + " (use a lower voxel.resolution)");
  Texture& pool = ctx.board.ensureTexture("svo-brick-pool", brickPoolDesc(capacity, brickFormat(ctx.params)));
  const uint8_t zero[4] = {0, 0, 0, 0};
  glClearTexImage(pool.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, zero);
  // The directional pool: the bricks above the voxels (numbers 1 .. tiles) and the zero brick.
  const bool anisotropic = anisotropicBricks(ctx.params);
  const uint32_t tiles = (nodes - 1) / 8;  // the pool is the root + 8 nodes per tile
  const uint32_t directionalBricks = anisotropic ? tiles + 1 : 1;
  const glm::ivec3 directionalAxis = bricksPerAxis(directionalBricks);
  if (3 * 6 * directionalAxis.z > maxSize)
    throw Error("svo-bricks: the directional brick pool needs " + std::to_string(3 * 6 * directionalAxis.z) +
                " texels along z, beyond GL_MAX_3D_TEXTURE_SIZE " + std::to_string(maxSize) +
                " (use a lower voxel.resolution or mipmap.mode=isotropic)");
  Texture& directional = ctx.board.ensureTexture("svo-directional-bricks", directionalPoolDesc(directionalBricks, ctx.params));
  glClearTexImage(directional.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, zero);
  const bool fronts = frontsBricks(ctx.params);
  Texture& opacity = ctx.board.ensureTexture("svo-opacity-bricks", opacityPoolDesc(fronts ? directionalBricks : 1));
  glClearTexImage(opacity.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, zero);
  Buffer& index = ctx.board.ensureBuffer("svo-brick-index", size_t(nodes) * 4);
  Buffer& scales = ctx.board.ensureBuffer("svo-brick-scales", size_t(capacity) * kBrickScaleFloats * 4);
  const float one = 1.0f;
  glClearNamedBufferData(scales.id(), GL_R32F, GL_RED, GL_FLOAT, &one);
  Buffer& counters = ctx.board.ensureBuffer("svo-brick-counters", kCounterBytes);
  std::vector<uint32_t> c(SVO_COUNTER_WORDS, 0u);
  counters.upload(c.data(), c.size() * 4);
  // The programs (svo/bricks.comp.glsl), each holding only the code its nodes need: the tiles of
  // voxels (Layout N's level D - 1), every other node, and Layout T's Gaussian pass; the layout,
  // the directional and opacity bricks and the kernel are defines of all three.
  const bool gaussian = tile && ctx.params.getChoice("svo.filter") == "gaussian";
  const auto flag = [](const char* name, bool on) { return std::string("#define ") + name + (on ? " 1\n" : " 0\n"); };
  const std::string choices = brickFormatDefines(ctx.params) + flag("SVO_LAYOUT_TILE", tile) +
                              flag("SVO_ANISOTROPIC_BRICKS", anisotropic) +
                              flag("SVO_FRONTS_BRICKS", frontsBricks(ctx.params)) + flag("SVO_GAUSSIAN", gaussian);
  const GLuint program =
      ctx.shaders.program({"svo/bricks.comp.glsl"}, choices + "#define SVO_BRICK_PASS 1\n#define SVO_VOXEL_TILES 0\n");
  const GLuint voxelTiles =
      ctx.shaders.program({"svo/bricks.comp.glsl"}, choices + "#define SVO_BRICK_PASS 1\n#define SVO_VOXEL_TILES 1\n");
  const GLuint gaussianPass =
      gaussian ? ctx.shaders.program({"svo/bricks.comp.glsl"}, choices + "#define SVO_BRICK_PASS 2\n#define SVO_VOXEL_TILES 0\n")
               : 0;
  for (GLuint p : {program, voxelTiles, gaussianPass}) {
    if (p == 0) continue;
    setUniform(p, "u_brickCapacity", unsigned(capacity));
    setUniform(p, "u_bricksPerAxis", axis);
    setUniform(p, "u_depth", depth);
    setUniform(p, "u_leafStart", unsigned(levels[depth].start));
    setUniform(p, "u_tiles", unsigned(tiles));
    setUniform(p, "u_directionalPerAxis", directionalAxis);
  }
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_NODES, ctx.board.buffer("svo-nodes").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_VALUES, ctx.board.buffer("svo-values").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_COUNTERS, counters.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_BRICK_INDEX, index.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_GROUPS, ctx.board.buffer("svo-groups").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_BRICK_SCALES, scales.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_DIRECTIONAL_VALUES,
                   ctx.board.buffer("svo-directional-values").id());
  glBindImageTexture(0, pool.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, brickFormat(ctx.params));
  glBindImageTexture(1, directional.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, brickFormat(ctx.params));
  glBindImageTexture(2, opacity.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA8);
  auto dispatchNodes = [&](GLuint p, uint32_t first, uint32_t end) {
    if (end <= first) return;
    setUniform(p, "u_firstNode", unsigned(first));
    setUniform(p, "u_nodeEnd", unsigned(end));
    glUseProgram(p);
    dispatchCompute({int(end - first), 1, 1}, {64, 1, 1});
  };
  if (tile) {
    dispatchNodes(program, 0, nodes);
  } else {
    // Layout N fills bricks per tile, from the tile's parent: the voxel-level nodes (most of the
    // pool) have no children, so only the levels above them are dispatched.
    dispatchNodes(program, 0, levels[depth - 1].start);
    dispatchNodes(voxelTiles, levels[depth - 1].start, levels[depth].start);
  }
  barrierAll();
  if (gaussian) {
    // Layout T, Gaussian: level by level from D - 2 up, each from the bricks just below it.
    glBindTextureUnit(0, pool.id());
    for (int l = depth - 2; l >= 0; --l) {
      setUniform(gaussianPass, "u_level", l);
      dispatchNodes(gaussianPass, 0, nodes);
      barrierAll();
    }
  }
  std::vector<uint8_t> bytes = counters.download(SVO_COUNTER_WORDS * 4);
  std::memcpy(c.data(), bytes.data(), c.size() * 4);
  if (c[SVO_COUNTER_OVERFLOW])
    throw Error("svo-bricks: brick pool overflow: it holds " + std::to_string(capacity) + " bricks, the octree needs " +
                std::to_string(needed) + " (svo.brick-pool-fraction=" +
                ctx.params.desc("svo.brick-pool-fraction").format(fraction) + "; 1 sizes the pool exactly)");
  ctx.stats["bricks"] = tagged;
  ctx.stats["brick_pool_bytes"] = double(pool.byteSize());
  ctx.stats["directional_bricks"] = anisotropic ? tiles : 0;
  ctx.stats["directional_brick_pool_bytes"] =
      anisotropic ? double(directional.byteSize()) + (fronts ? double(opacity.byteSize()) : 0.0) : 0.0;
  ctx.stats["opacity_brick_pool_bytes"] = fronts ? double(opacity.byteSize()) : 0.0;
  ctx.stats["brick_scale_bytes"] = scaledBricks(ctx.params) ? double(scales.size()) : 0.0;
  const double bricksBytes =
      double(pool.byteSize()) + ctx.stats["directional_brick_pool_bytes"] + ctx.stats["brick_scale_bytes"];
  ctx.stats["node_pool_bytes"] = double(nodes) * (sizeof(SvoNode) + 4);
  ctx.stats["octree_bytes"] = bricksBytes + double(nodes) * (sizeof(SvoNode) + 4);
  // What the cone tracer reads: Layout T never descends to the voxel level, whose nodes only carry
  // the leaf values into the filter (they could be dropped after this stage).
  const double tracedNodes = tile ? double(levels[depth].start) : double(nodes);
  ctx.stats["traced_octree_bytes"] = bricksBytes + tracedNodes * (sizeof(SvoNode) + 4);
  // The dense comparison: vct-grid's radiance mip chain at this resolution and format (all
  // levels), and with anisotropic mips also its six directional chains of half the edge, and with
  // the fronts rule its RGBA8 solid-opacity chain (one for both signs of an axis).
  const double texelBytes = hdrBricks(ctx.params) ? 8.0 : 4.0;
  double dense = 0.0, directionalDense = 0.0;
  for (int r = ctx.params.getInt("voxel.resolution"); r >= 1; r /= 2) dense += texelBytes * double(r) * r * r;
  for (int r = ctx.params.getInt("voxel.resolution") / 2; r >= 1; r /= 2)
    directionalDense += (6 * texelBytes + (frontsBricks(ctx.params) ? 4.0 : 0.0)) * double(r) * r * r;
  ctx.stats["dense_mip_chain_bytes"] = dense;
  ctx.stats["traced_octree_over_dense"] = ctx.stats["traced_octree_bytes"] / dense;
  if (anisotropic) {
    ctx.stats["dense_anisotropic_chain_bytes"] = dense + directionalDense;
    ctx.stats["traced_octree_over_dense_anisotropic"] = ctx.stats["traced_octree_bytes"] / (dense + directionalDense);
  }
}

// --- svo-pick --------------------------------------------------------------------------------------

void PickStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(ParamDesc::integer("pick.x", 0, 0, 511, "picked cell along x, in cells of the picked level", "cells"));
  b.param(ParamDesc::integer("pick.y", 0, 0, 511, "picked cell along y", "cells"));
  b.param(ParamDesc::integer("pick.z", 0, 0, 511, "picked cell along z", "cells"));
  b.param(ParamDesc::integer("pick.level", 0, 0, 9,
                             "mip of svo-structure the cell is given in: octree level D - mip (0 = the voxels)"));
  b.probe(ProbeDesc::volume("pick.x", "pick.y", "pick.z", "pick.level", "svo-structure"));
  b.read("svo-nodes");
  b.read("svo-levels");
  b.read("svo-neighbour-links");
  b.read("svo-brick-index");
  b.read("svo-brick-pool");
  b.read("svo-brick-scales");
  BufferLayout l;
  l.stride = sizeof(SvoPickedNode);
  l.fields = {{"node", FieldType::U32, 0}, {"level", FieldType::U32, 4}, {"cell", FieldType::Packed10_10_10, 8},
              {"word", FieldType::U32, 12}, {"brick", FieldType::U32, 72}};
  OutputDesc& o = b.output("svo-picked-node", OutputKind::Buffer, kOctreePickedNode,
                           "the picked node: index, level, cell, flags, children, neighbour links, brick and its 27 "
                           "texels (visualiser octree-picked-node)");
  o.layout = l;
  o.probeRecord = true;
  b.buffer("svo-picked-node", [](const ParamSet&, const ViewState&) { return sizeof(SvoPickedNode); });
}

void PickStage::execute(StageContext& ctx) {
  const int depth = octreeDepth(ctx.params);
  const int level = std::max(0, depth - ctx.params.getInt("pick.level"));
  const int cells = 1 << level;
  glm::ivec3 cell(ctx.params.getInt("pick.x"), ctx.params.getInt("pick.y"), ctx.params.getInt("pick.z"));
  cell = glm::clamp(cell, glm::ivec3(0), glm::ivec3(cells - 1));
  Buffer& out = ctx.board.ensureBuffer("svo-picked-node", sizeof(SvoPickedNode));
  GLuint program = ctx.shaders.program({"svo/pick.comp.glsl"});
  setUniform(program, "u_cell", cell);
  setUniform(program, "u_level", level);
  setUniform(program, "u_depth", depth);
  setUniform(program, "u_bricksPerAxis", ctx.board.texture("svo-brick-pool").desc().size / 3);
  glUseProgram(program);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_NODES, ctx.board.buffer("svo-nodes").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_NEIGHBOURS, ctx.board.buffer("svo-neighbour-links").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_BRICK_INDEX, ctx.board.buffer("svo-brick-index").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_BRICK_SCALES, ctx.board.buffer("svo-brick-scales").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_PICKED, out.id());
  glBindTextureUnit(0, ctx.board.texture("svo-brick-pool").id());
  dispatchCompute({1, 1, 1}, {8, 8, 1});
  barrierAll();
  ctx.stats["picked_level"] = level;
}

// --- svo-cone-trace --------------------------------------------------------------------------------
// The parameters shared with vct-grid's cone-trace keep its names, defaults and ranges, so the two
// techniques trace the same cones for the same settings (the AO cross-check relies on it).

static constexpr size_t kDescentBytes = sizeof(SvoDescentStep) * SVO_MAX_DESCENT_STEPS;

void ConeTraceStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(dilateParam());
  b.param(layoutParam());
  b.param(mipmapModeParam());
  b.param(frontsParam());
  b.param(ParamDesc::boolean("svo.voxel-halo", true,
                             "read a voxel without a brick (empty, or no node there) as the dense grid does: the "
                             "trilinear blend of the eight voxels around the sample, found in the octree, so a cone "
                             "starting next to a surface sees it in its first voxel as in vct-grid (Layout N without "
                             "dilation; the soft-shadow cone never reads it; off: such a voxel reads 0, and stair bands "
                             "run along the edges: the note's P2)"));
  b.param(ParamDesc::choice("cone.resolution", {"half", "full"}, 0,
                            "trace cones for every pixel (full) or every 2x2 block (half, 4x cheaper; composite "
                            "upsamples along surfaces)"));
  // vct-grid's cones (cone_setup.h's defaults), so that both trace the same cones at their
  // defaults (the AO cross-check).
  declareConeParams(b, ConeDefaults{});
  b.param(ParamDesc::choice("ao.cones", {"diffuse", "basgier-3", "basgier-5", "basgier-8"}, 0,
                            "AO from the diffuse cones (as vct-grid), or Basgier's constellations: 3 cones of 100 deg, "
                            "5 of 90 deg, 8 of 60 deg, ring layout, equal weights"));
  b.param(ParamDesc::real("ao.falloff", 0.0, 0.0, 2.0,
                          "Basgier's distance falloff lambda: each AO sample's opacity is scaled by 1 / (1 + lambda r), "
                          "r in voxels (0: none, vct-grid's plain range cut)", "1/voxel"));
  b.param(ParamDesc::boolean("ao.jitter", false,
                             "turn every pixel's cones (diffuse and AO) about its normal by a fixed per-pixel random "
                             "angle: the constellation's banding becomes noise"));
  declareSky(b);
  b.readView();
  b.read("svo-nodes");
  b.read("svo-levels");
  b.read("svo-counters");
  b.read("svo-brick-index");
  b.read("svo-values");
  b.read("svo-brick-pool");
  b.read("svo-directional-bricks");
  b.read("svo-opacity-bricks");
  b.read("svo-brick-scales");
  b.read("position");
  b.read("normal");
  b.read("albedo");
  b.read("light");
  b.write("svo-descent.count");
  b.output("indirect-diffuse", OutputKind::Image2D, Semantic::RadianceHDR,
           "outgoing indirect diffuse radiance: albedo * weighted sum of the diffuse cones (at cone.resolution)")
      .referenceMode = "indirect-1";
  // Traced only when something reads it (composite.specular above 0, a view, --only).
  b.output("indirect-specular", OutputKind::Image2D, Semantic::RadianceHDR, "radiance gathered by the specular cone")
      .onDemand = true;
  b.output("ambient-occlusion", OutputKind::Image2D, Semantic::Fraction,
           "weighted visible fraction within ao.range (1 = open)");
  // Traced only when something reads it (composite.shadow=soft-shadow-cone, a view, --only).
  b.output("soft-shadow", OutputKind::Image2D, Semantic::Fraction, "visibility of the light through the octree (1 = lit)")
      .onDemand = true;
  coneSamplesOutput(b, "every sample of the probed pixel's cones: centre+diameter, accumulated radiance+opacity, "
                       "cone/distance/mip/alpha");
  BufferLayout steps;
  steps.stride = sizeof(SvoDescentStep);
  steps.fields = {{"sample", FieldType::U32, 0}, {"level", FieldType::U32, 4}, {"node", FieldType::U32, 8},
                  {"cell", FieldType::Packed10_10_10, 12}, {"value", FieldType::Vec4, 16, FieldRole::Color}};
  steps.countResource = "svo-descent.count";
  OutputDesc& descent = b.output("svo-descent", OutputKind::Buffer, kOctreeDescent,
                                 "for every sample of the probed pixel: the node visited at each level from the root "
                                 "to the sample's fine level (0xffffffff = absent), its cell, its brick's value there");
  descent.alongside = true;
  descent.layout = steps;
  descent.probeRecord = true;
  b.texture("indirect-diffuse", [](const ParamSet& p, const ViewState& v) { return kTracedCones.desc(p, v, GL_RGBA16F); });
  b.texture("indirect-specular", [](const ParamSet& p, const ViewState& v) { return kTracedCones.desc(p, v, GL_RGBA16F); });
  b.texture("ambient-occlusion", [](const ParamSet& p, const ViewState& v) { return kTracedCones.desc(p, v, GL_R16F); });
  b.texture("soft-shadow", [](const ParamSet& p, const ViewState& v) { return kTracedCones.desc(p, v, GL_R16F); });
  b.buffer("svo-descent", [](const ParamSet&, const ViewState&) { return kDescentBytes; });
  b.buffer("svo-descent.count", [](const ParamSet&, const ViewState&) { return size_t(4); });
}

void ConeTraceStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  const int depth = octreeDepth(ctx.params);
  VoxelSpace space = VoxelSpace::fromScene(ctx.scene, res);
  const int scale = kTracedCones.scale(ctx.params);
  Texture& indirect = ctx.board.ensureTexture("indirect-diffuse", kTracedCones.desc(ctx.params, ctx.view, GL_RGBA16F));
  const bool traceSpecular = ctx.wants("indirect-specular");
  // Without the specular cone its image unit is bound to the indirect image, never written there.
  Texture& specular = traceSpecular ? ctx.board.ensureTexture("indirect-specular", kTracedCones.desc(ctx.params, ctx.view, GL_RGBA16F)) : indirect;
  Texture& ao = ctx.board.ensureTexture("ambient-occlusion", kTracedCones.desc(ctx.params, ctx.view, GL_R16F));
  const bool traceShadow = ctx.wants("soft-shadow");
  // Without the shadow cone its image unit is bound to the ambient-occlusion image, never written.
  Texture& shadow = traceShadow ? ctx.board.ensureTexture("soft-shadow", kTracedCones.desc(ctx.params, ctx.view, GL_R16F)) : ao;
  Buffer& samples = ctx.board.ensureBuffer("cone-samples", coneSamplesBytes());
  Buffer& sampleCount = ctx.board.ensureBuffer("cone-samples.count", 4);
  Buffer& descent = ctx.board.ensureBuffer("svo-descent", kDescentBytes);
  Buffer& descentCount = ctx.board.ensureBuffer("svo-descent.count", 4);
  const uint32_t zero = 0;
  sampleCount.upload(&zero, 4);
  descentCount.upload(&zero, 4);
  glm::ivec3 traced = indirect.desc().size;

  auto pack = [](const std::vector<Cone>& cones) {
    std::vector<glm::vec4> packed;
    for (const auto& c : cones) packed.push_back(glm::vec4(c.direction, c.weight));
    return packed;
  };
  const float aperture = ctx.params.getFloat("cone.aperture") * kDegrees;
  // Basgier's constellations (seed 002 section 6): 5 cones of 90 deg and 8 of 60 deg as published;
  // the 3-cone aperture (100 deg) and all directions (our ring layout) are our choice, the seed
  // gives neither. Equal weights, as his average.
  const std::string aoCones = ctx.params.getChoice("ao.cones");
  int aoCount = 0;
  float aoAperture = aperture;
  if (aoCones != "diffuse") {
    aoCount = aoCones == "basgier-3" ? 3 : aoCones == "basgier-5" ? 5 : 8;
    aoAperture = (aoCount == 3 ? 100.0f : aoCount == 5 ? 90.0f : 60.0f) * kDegrees;
  }
  std::vector<glm::vec4> ao4 = aoCount ? pack(diffuseCones(aoCount, aoAperture, "ring", "equal"))
                                       : std::vector<glm::vec4>(1, glm::vec4(0.0f));

  const glm::ivec3 brickAxis = ctx.board.texture("svo-brick-pool").desc().size / 3;
  glm::ivec3 directionalAxis = ctx.board.texture("svo-directional-bricks").desc().size / 3;
  directionalAxis.z /= 6;
  // Every pixel without recording, and the probed pixel alone with its samples and descents
  // recorded (probe_recorder.h).
  const auto [tracer, recorder] = tracerAndRecorder(ctx.shaders, {"svo/cone_trace.comp.glsl"},
                                                     coneTraceDefines(ctx.params, traceShadow, traceSpecular));
  glm::ivec2 probe(0);
  for (GLuint program : {tracer, recorder}) {
    space.setUniforms(program);
    setUniform(program, "u_depth", depth);
    setUniform(program, "u_bricksPerAxis", brickAxis);
    setUniform(program, "u_directionalPerAxis", directionalAxis);
    glProgramUniform4fv(program, glGetUniformLocation(program, "u_aoCones"), GLsizei(ao4.size()), &ao4[0].x);
    setUniform(program, "u_aoConeCount", aoCount);
    setUniform(program, "u_aoAperture", aoAperture);
    setUniform(program, "u_aoFalloff", ctx.params.getFloat("ao.falloff"));
    setUniform(program, "u_aoJitter", ctx.params.getBool("ao.jitter") ? 1 : 0);
    probe = setConeUniforms(program, ctx.params, ctx.view, space, glm::ivec2(traced), scale);
    setSkyUniforms(program, ctx.params, ctx.scene);
  }
  glUseProgram(tracer);
  glBindTextureUnit(0, ctx.board.texture("svo-brick-pool").id());
  glBindTextureUnit(1, ctx.board.texture("position").id());
  glBindTextureUnit(2, ctx.board.texture("normal").id());
  glBindTextureUnit(3, ctx.board.texture("albedo").id());
  glBindTextureUnit(4, ctx.board.texture("svo-directional-bricks").id());
  glBindTextureUnit(5, ctx.board.texture("svo-opacity-bricks").id());
  glBindBufferBase(GL_UNIFORM_BUFFER, VOXLAB_UNIFORM_LIGHT, ctx.board.buffer("light").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_NODES, ctx.board.buffer("svo-nodes").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_BRICK_INDEX, ctx.board.buffer("svo-brick-index").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_VALUES, ctx.board.buffer("svo-values").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_BRICK_SCALES, ctx.board.buffer("svo-brick-scales").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_CONE_SAMPLES, samples.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_CONE_SAMPLE_COUNT, sampleCount.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_DESCENT, descent.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SVO_BINDING_DESCENT_COUNT, descentCount.id());
  glBindImageTexture(0, indirect.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(1, specular.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  glBindImageTexture(2, ao.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R16F);
  glBindImageTexture(3, shadow.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R16F);
  dispatchCompute({traced.x, traced.y, 1}, {8, 8, 1});
  barrierAll();
  dispatchRecorder(recorder, {8, 8, 1});
  barrierAll();
  // Cap the recorded counts at the buffers' capacities (the shader counts on past them).
  auto cap = [](Buffer& count, uint32_t capacity) {
    uint32_t n = readCounter(count);
    if (n > capacity) count.upload(&capacity, 4);
  };
  cap(sampleCount, VOXLAB_MAX_CONES * VOXLAB_MAX_SAMPLES_PER_CONE);
  cap(descentCount, SVO_MAX_DESCENT_STEPS);
  ctx.stats["diffuse_cones"] = ctx.params.getInt("cone.count");
  ctx.stats["anisotropic"] = anisotropicBricks(ctx.params) ? 1 : 0;
  ctx.stats["ao_cones"] = aoCount ? aoCount : ctx.params.getInt("cone.count");
  ctx.stats["traced_pixels"] = double(traced.x) * traced.y;
  ctx.stats["probe_x"] = probe.x;
  ctx.stats["probe_y_from_top"] = traced.y - 1 - probe.y;
}

}  // namespace voxlab::svo
