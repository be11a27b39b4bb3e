// near-field checks against answers that do not come from the code under test (testing.md):
//  - exact: the OR / XOR / ray-mask tables (CPU invariants and the GPU table against the CPU, row
//    127 included: the public code's XOR[128] fetch), the GPU first-bit function on all single
//    bits and adversarial masks, the binary grid against the fragment list and the CPU reference
//    voxelizer, every mip level against the CPU OR of its children, the hierarchical traversal
//    against a brute-force DDA over the grid, the probe's step records (levels change by one per
//    step, hits only at level 0), the guard for origins outside the volume, and the R32UI view of
//    an RGBA32UI texture being refused (why the grid is built in a separate word texture);
//  - self-intersection: rays from a plane never hit the plane's own voxels, over all angles;
//  - physics: the indirect image against a CPU near-field estimator on Embree (same receivers,
//    same offsets and radius, the shared light model, an exact shadow ray), and against the full
//    one-bounce reference (the loss beyond the radius is reported).
#include <gtest/gtest.h>

#include <embree3/rtcore.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <glm/gtx/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <set>
#include <array>
#include <cstdio>

#include "gpu/gl_debug.h"
#include "graph/reference_mode.h"
#include "inspect/visualiser.h"
#include "common/shared.h"
#include "run/reference_error.h"
#include "core/paths.h"
#include "gpu/shader_library.h"
#include "near_field/near_field_shared.h"
#include "reference/cpu_voxelizer.h"
#include "reference/image_io.h"
#include "reference/path_tracer.h"
#include "scene/light_model.h"
#include "techniques/common/binary_voxels_stage.h"
#include "techniques/common/voxel_space.h"
#include "techniques/near_field/bitmask.h"
#include "techniques/near_field/near_field.h"
#include "techniques/near_field/surface_query.h"
#include "test_support.h"

namespace voxlab {
namespace {

using namespace nearfield;
using testing_support::capture;
using testing_support::session;

RunRequest request(std::vector<std::string> sets, const std::string& until = "", int size = 128,
                   const std::string& scene = "cornell-box") {
  RunRequest r;
  r.technique = "near-field";
  r.scene = scene;
  r.until = until;
  r.sets = std::move(sets);
  r.width = r.height = size;
  return r;
}

// The snapshot suite's settings (tests/golden/near-field/settings.json), so the runs are shared.
RunRequest snapshotRequest() {
  return request({"voxel.resolution=64", "rays.count=4", "rsm.resolution=128", "shadow.resolution=256"});
}

std::vector<BitColumn> readLevel(HeadlessSession& s, const std::string& texture, int level) {
  Texture& t = s.cursor().board().texture(texture);
  glm::ivec3 size = t.levelSize(level);
  return readBitColumns(t.id(), level, size.x, size.y);
}

bool sameColumn(const BitColumn& a, const BitColumn& b) { return a == b; }

// --- Tables --------------------------------------------------------------------------------------

TEST(NearFieldTables, OrAndXorInvariants) {
  auto orT = orTable();
  auto xorT = xorTable();
  ASSERT_EQ(orT.size(), 128u);
  ASSERT_EQ(xorT.size(), 129u);
  BitColumn all{0, 0, 0, 0};
  for (int k = 0; k < 128; ++k) {
    EXPECT_EQ(popcount(orT[k]), 1) << k;
    EXPECT_TRUE(hasSlice(orT[k], k)) << k;
    for (int c = 0; c < 4; ++c) {
      EXPECT_EQ(all[c] & orT[k][c], 0u) << "OR[" << k << "] overlaps an earlier entry";
      all[c] |= orT[k][c];
    }
    EXPECT_EQ(popcount(xorT[k]), 128 - k) << k;
    for (int c = 0; c < 4; ++c) EXPECT_EQ(xorT[k][c], orT[k][c] | xorT[k + 1][c]) << "XOR[" << k << "] channel " << c;
  }
  for (int c = 0; c < 4; ++c) {
    EXPECT_EQ(all[c], 0xFFFFFFFFu);
    EXPECT_EQ(xorT[0][c], 0xFFFFFFFFu);  // thesis Listing 4.39's comment says 0x7FFFFFFF
    EXPECT_EQ(xorT[128][c], 0u);
  }
  // Bit order: slice 0 is R's MSB, slice 31 R's bit 0, slice 32 G's MSB, slice 127 A's bit 0.
  EXPECT_EQ(orT[0][0], 0x80000000u);
  EXPECT_EQ(orT[31][0], 1u);
  EXPECT_EQ(orT[32][1], 0x80000000u);
  EXPECT_EQ(orT[127][3], 1u);
}

TEST(NearFieldTables, VoxelSizesFollowResolutionAndTheFixed128Slices) {
  auto& s = session(snapshotRequest());
  const Scene& scene = s.cursor().scene();
  for (int res : {16, 64, 128, 512}) {
    BinaryGridGeometry g = BinaryGridGeometry::of(scene, res);
    VoxelSpace space = VoxelSpace::fromScene(scene, res);
    EXPECT_FLOAT_EQ(g.columnSize, space.voxelSize) << res;
    EXPECT_FLOAT_EQ(g.sliceDepth, space.edge() / 128.0f) << res;  // 128 slices whatever the resolution
    EXPECT_FLOAT_EQ(g.voxelDiagonal, std::sqrt(2 * g.columnSize * g.columnSize + g.sliceDepth * g.sliceDepth));
    int first, last;
    slicesOfVoxel(res - 1, res, first, last);
    EXPECT_EQ(last, 127) << "the last voxel of a column must reach slice 127 at " << res;
    slicesOfVoxel(0, res, first, last);
    EXPECT_EQ(first, 0);
  }
}

TEST(NearFieldTables, GpuTablesEqualCpuIncludingRow127) {
  auto& s = session(snapshotRequest());
  auto orGpu = readLevel(s, "or-table", 0);
  auto xorGpu = readLevel(s, "xor-table", 0);
  auto rays = readLevel(s, "ray-masks", 0);
  auto orT = orTable();
  auto xorT = xorTable();
  for (int k = 0; k < 128; ++k) EXPECT_TRUE(sameColumn(orGpu[k], orT[k])) << "OR[" << k << "]";
  for (int k = 0; k <= 128; ++k) EXPECT_TRUE(sameColumn(xorGpu[k], xorT[k])) << "XOR[" << k << "]";
  int wrong = 0;
  for (int j = 0; j < 128; ++j)
    for (int i = 0; i <= j; ++i) {
      const BitColumn& m = rays[size_t(j) * 128 + i];
      BitColumn expect{0, 0, 0, 0};
      for (int k = i; k <= j; ++k) setSlice(expect, k);
      if (m != expect || popcount(m) != j - i + 1) ++wrong;
    }
  EXPECT_EQ(wrong, 0) << "ray masks (i <= j) that are not the OR of slices i..j";
  // Row 127 needs XOR[128] = 0: the public code fetches texel 128 of a 128-texel table there.
  for (int i = 0; i < 128; ++i) EXPECT_TRUE(sameColumn(rays[size_t(127) * 128 + i], xorT[i])) << "row 127, i = " << i;
}

// Runs masks through the GPU's firstSliceAlong (shaders/near_field/traversal.glsl).
std::vector<glm::uvec4> gpuKernel(HeadlessSession& s, int mode, const void* input, size_t inputBytes, int count,
                                  int budget = 0) {
  GLuint program = s.cursor().shaders().program({"near_field/segments.comp.glsl"});
  Buffer in("test.segments", std::max<size_t>(inputBytes, 16), input);
  Buffer out("test.hits", size_t(count) * 16 + 16);
  int res = s.cursor().params().getInt("voxel.resolution");
  setUniform(program, "u_count", count);
  setUniform(program, "u_mode", mode);
  setUniform(program, "u_budget", budget);
  setUniform(program, "u_gridRes", res);
  setUniform(program, "u_maxLevel", maxLevelOf(res));
  setUniform(program, "u_startLevel", 3);
  glUseProgram(program);
  glBindTextureUnit(4, s.cursor().board().texture("bitmask-hierarchy").id());
  glBindTextureUnit(5, s.cursor().board().texture("ray-masks").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, NF_BINDING_SEGMENTS, in.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, NF_BINDING_SEGMENT_HITS, out.id());
  dispatchCompute({count, 1, 1}, {64, 1, 1});
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  std::vector<glm::uvec4> result(count);
  auto bytes = out.download(size_t(count) * 16);
  std::memcpy(result.data(), bytes.data(), bytes.size());
  return result;
}

// GP3 / thesis Listing 4.48: bit position by int(log2(float(int(x)))) (non-reversed rays).
int gp3HighestBit(uint32_t x) {
  float f = float(int32_t(x));
  float l = std::log2(f);
  return std::isnan(l) ? -1000 : int(l);
}

TEST(NearFieldTables, GpuFirstSliceEqualsCpuOnSingleBitsAndAdversarialMasks) {
  auto& s = session(snapshotRequest());
  std::vector<BitColumn> masks;
  for (int k = 0; k < 128; ++k) masks.push_back(orMask(k));
  // Channels whose bit 31 is set (int(x) < 0 in GP3's formula), values >= 2^24 that float rounds,
  // lowest-bit-at-31 channels for reversed rays, and random patterns.
  const uint32_t adversarial[] = {0x80000000u, 0x80000001u, 0xFFFFFFFFu, 0x01FFFFFFu, 0x00FFFFFFu, 0x7FFFFFFFu,
                                  0x00000001u, 0x40000000u, 0x03FFFFFFu, 0x0FFFFFFFu};
  for (uint32_t a : adversarial)
    for (int c = 0; c < 4; ++c) {
      BitColumn m{0, 0, 0, 0};
      m[c] = a;
      masks.push_back(m);
      m[3 - c] |= 0x80000000u;
      masks.push_back(m);
    }
  std::mt19937 rng(7);
  for (int i = 0; i < 200; ++i) {
    uint32_t a = uint32_t(rng() & rng()), b = uint32_t(rng() & rng() & rng()), c = uint32_t(rng() & rng()), d = uint32_t(rng());
    masks.push_back({a, b, c, d});
  }
  auto r = gpuKernel(s, 1, masks.data(), masks.size() * 16, int(masks.size()));
  for (size_t i = 0; i < masks.size(); ++i) {
    EXPECT_EQ(int(r[i].x) - 1, firstSliceAlong(masks[i], false)) << "mask " << i << " toward +z";
    EXPECT_EQ(int(r[i].y) - 1, firstSliceAlong(masks[i], true)) << "mask " << i << " toward -z";
  }
  // The listing's float formula is wrong where this test looks: a set bit 31 gives NaN, and
  // 0x01FFFFFF rounds up to 2^25 (slice off by one). findMSB has neither problem.
  EXPECT_NE(gp3HighestBit(0x80000000u), 31);
  EXPECT_NE(gp3HighestBit(0x01FFFFFFu), 24);
}

// --- Binary grid and hierarchy --------------------------------------------------------------------

std::vector<uint32_t> fragmentKeys(HeadlessSession& s) {
  CapturedOutput f = capture(s, "voxelize", "fragments");
  std::vector<uint32_t> keys;
  for (uint32_t i = 0; i < f.recordCount; ++i) {
    uint32_t k;
    std::memcpy(&k, &f.records[size_t(i) * f.desc.layout.stride], 4);
    keys.push_back(k);
  }
  return keys;
}

TEST(NearFieldGrid, BinaryGridEqualsFragmentListBitForBit) {
  auto& s = session(snapshotRequest());
  const int res = 64;
  auto gpu = readLevel(s, "binary-voxels", 0);
  auto cpu = binaryGridFromVoxelKeys(fragmentKeys(s), res);
  ASSERT_EQ(gpu.size(), cpu.size());
  size_t differing = 0, setBits = 0;
  for (size_t i = 0; i < gpu.size(); ++i) {
    differing += gpu[i] != cpu[i];
    setBits += size_t(popcount(gpu[i]));
  }
  EXPECT_GT(setBits, 10000u);
  EXPECT_EQ(differing, 0u) << "columns that differ from the CPU OR of the fragment list";
  // Popcount output = popcount of each column.
  Texture& pc = s.cursor().board().texture("binary-popcount");
  std::vector<uint32_t> counts(size_t(res) * res);
  glGetTextureImage(pc.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, GLsizei(counts.size() * 4), counts.data());
  for (size_t i = 0; i < counts.size(); ++i) ASSERT_EQ(int(counts[i]), popcount(gpu[i])) << "column " << i;
}

TEST(NearFieldGrid, BinaryGridAt128EqualsCpuReferenceVoxelizer) {
  auto& s = session(request({"voxel.resolution=128"}, "hierarchy", 64));
  const Scene& scene = s.cursor().scene();
  auto gpu = readLevel(s, "binary-voxels", 0);
  auto ref = binaryGridFromVoxelKeys(referenceVoxelSet(scene, VoxelSpace::fromScene(scene, 128)), 128);
  // At 128 one slice is one voxel: bit (x, y, k) <=> the dense occupancy of voxel (x, y, z = k).
  size_t missing = 0, extra = 0, total = 0;
  for (size_t i = 0; i < gpu.size(); ++i)
    for (int k = 0; k < 128; ++k) {
      bool g = hasSlice(gpu[i], k), r = hasSlice(ref[i], k);
      total += r;
      missing += r && !g;
      extra += g && !r;
    }
  EXPECT_GT(total, 50000u);
  EXPECT_EQ(missing, 0u);
  // The conservative voxelizer's set equals the reference (measured 0 extra on the Cornell box at
  // 128, docs/testing.md); allow the 0.1 % of float-rounding face touches that test allows.
  EXPECT_LE(extra, total / 1000);
}

TEST(NearFieldGrid, EveryMipLevelIsTheOrOfItsChildren) {
  auto& s = session(snapshotRequest());
  const int res = 64;
  auto chain = orMipChain(readLevel(s, "binary-voxels", 0), res);
  ASSERT_EQ(int(chain.size()), maxLevelOf(res) + 1);
  for (int l = 0; l < int(chain.size()); ++l) {
    auto gpu = readLevel(s, "bitmask-hierarchy", l);
    size_t differing = 0;
    for (size_t i = 0; i < gpu.size(); ++i) differing += gpu[i] != chain[l][i];
    EXPECT_EQ(differing, 0u) << "level " << l;
    if (l > 0) {
      const int r = res >> l;
      for (int y = 0; y < r; ++y)
        for (int x = 0; x < r; ++x)
          for (int j = 0; j < 4; ++j)
            ASSERT_GE(popcount(gpu[size_t(y) * r + x]),
                      popcount(chain[l - 1][size_t(2 * y + (j >> 1)) * (2 * r) + 2 * x + (j & 1)]));
    }
  }
  // The top texel is the OR of everything.
  BitColumn all{0, 0, 0, 0};
  for (const auto& c : chain[0])
    for (int i = 0; i < 4; ++i) all[i] |= c[i];
  EXPECT_EQ(readLevel(s, "bitmask-hierarchy", maxLevelOf(res))[0], all);
}

// The Cornell box's columns are too regular to show a wrong child: its walls and blocks give
// neighbouring columns the same slices, so a hierarchy that ORs child (1, 0) twice and leaves out
// (1, 1) still matched it (mutation nf-hierarchy-child). Sparse random columns (1 in 8 non-empty,
// each bit set with probability 1/8) written into binary-voxels make every child count.
TEST(NearFieldGrid, EveryMipLevelIsTheOrOfItsChildrenOnRandomColumns) {
  auto& s = session(snapshotRequest());
  StepCursor& c = s.cursor();
  const int res = 64;
  Texture& base = c.board().texture("binary-voxels");
  std::mt19937 rng(21);
  std::vector<uint32_t> words(size_t(res) * res * 4, 0u);
  for (size_t i = 0; i < words.size(); i += 4)
    if (rng() % 8 == 0)
      for (int w = 0; w < 4; ++w) words[i + w] = uint32_t(rng()) & uint32_t(rng()) & uint32_t(rng());
  glTextureSubImage2D(base.id(), 0, 0, 0, res, res, GL_RGBA_INTEGER, GL_UNSIGNED_INT, words.data());
  const int hierarchy = c.technique().stageIndex("hierarchy");
  c.invalidate(hierarchy);
  c.runThrough(hierarchy);
  auto level0 = readLevel(s, "binary-voxels", 0);
  auto chain = orMipChain(level0, res);
  for (int l = 1; l < int(chain.size()); ++l) {
    auto gpu = readLevel(s, "bitmask-hierarchy", l);
    ASSERT_EQ(gpu.size(), chain[l].size());
    size_t differing = 0;
    for (size_t i = 0; i < gpu.size(); ++i) differing += gpu[i] != chain[l][i];
    EXPECT_EQ(differing, 0u) << "level " << l;
  }
  c.invalidate(c.technique().stageIndex("binary-voxels"));
  c.runAll();  // leave the shared session as the other tests expect it
}

TEST(NearFieldGrid, LogicOpOrMergesPointsIntoOneColumn) {
  // The thesis' path (seed 000 Listing 4.43): points into an RGBA32UI target with glLogicOp(GL_OR).
  // Two points in the same texel with different slices must leave both bits set (pitfall 5.8);
  // measured on llvmpipe: it works, so both the logic op and imageAtomicOr (what binary-voxels
  // uses, on its own R32UI words texture) are available there.
  auto& s = session(snapshotRequest());
  TextureDesc d;
  d.format = GL_RGBA32UI;
  d.size = {4, 4, 1};
  d.minFilter = d.magFilter = GL_NEAREST;
  Texture target("test.logic-or", d);
  const uint32_t zero[4] = {0, 0, 0, 0};
  glClearTexImage(target.id(), 0, GL_RGBA_INTEGER, GL_UNSIGNED_INT, zero);
  Framebuffer fb("test.logic-or.fbo");
  fb.attach(GL_COLOR_ATTACHMENT0, target);
  fb.setDrawBuffers(1);
  fb.checkComplete();
  GLuint program = s.cursor().shaders().program({"near_field/logic_or_points.vert.glsl", "near_field/logic_or_points.frag.glsl"});
  const int texels[8] = {1, 2, 1, 2, 1, 2, 3, 0};  // (x, y) pairs: three points at (1, 2), one at (3, 0)
  const int slices[4] = {0, 77, 127, 40};
  glProgramUniform2iv(program, glGetUniformLocation(program, "u_texel"), 4, texels);
  glProgramUniform1iv(program, glGetUniformLocation(program, "u_slice"), 4, slices);
  glProgramUniform2i(program, glGetUniformLocation(program, "u_size"), 4, 4);
  VertexArray vao;
  glBindFramebuffer(GL_FRAMEBUFFER, fb.id());
  glViewport(0, 0, 4, 4);
  glDisable(GL_DEPTH_TEST);
  glEnable(GL_COLOR_LOGIC_OP);
  glLogicOp(GL_OR);
  glUseProgram(program);
  glBindVertexArray(vao.id());
  glDrawArrays(GL_POINTS, 0, 4);
  glDisable(GL_COLOR_LOGIC_OP);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  auto cols = readBitColumns(target.id(), 0, 4, 4);
  BitColumn expect{0, 0, 0, 0};
  for (int k : {0, 77, 127}) setSlice(expect, k);
  EXPECT_EQ(cols[2 * 4 + 1], expect) << "the three points of texel (1, 2)";
  EXPECT_EQ(cols[0 * 4 + 3], orMask(40));
  EXPECT_EQ(popcount(cols[0]), 0);
}

TEST(NearFieldGrid, RgbaUintColumnsHaveNoR32uiView) {
  auto& s = session(snapshotRequest());
  (void)s;
  while (glGetError() != GL_NO_ERROR) {
  }
  TextureDesc d;
  d.format = GL_RGBA32UI;
  d.size = {4, 4, 1};
  d.minFilter = d.magFilter = GL_NEAREST;
  Texture columns("test.columns", d);
  GLuint view = 0;
  glGenTextures(1, &view);
  glTextureView(view, GL_TEXTURE_2D, columns.id(), GL_R32UI, 0, 1, 0, 1);
  GLenum err = glGetError();
  glDeleteTextures(1, &view);
  // GL 4.5 table 8.22: RGBA32UI is in the 128-bit view class, R32UI in the 32-bit one.
  EXPECT_EQ(err, GLenum(GL_INVALID_OPERATION));
  // The debug output reported exactly that error (the test listener would fail on it): take it.
  std::vector<GLDebugMessage> failures = takeGLFailures();
  ASSERT_EQ(failures.size(), 1u);
  EXPECT_NE(failures[0].describe().find("GL_INVALID_OPERATION"), std::string::npos) << failures[0].describe();
}

// --- Traversal ------------------------------------------------------------------------------------

struct SegmentRun {
  std::vector<glm::vec4> segs;
  std::vector<glm::uvec4> hits;
};

SegmentRun runSegments(HeadlessSession& s, int count, int budget, uint32_t seed, float maxLength, bool inside = true) {
  SegmentRun r;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < count; ++i) {
    glm::vec3 o(u(rng), u(rng), u(rng));
    if (!inside) o = glm::vec3(u(rng) * 3 - 1, u(rng) * 3 - 1, u(rng) * 3 - 1);
    glm::vec3 d = glm::normalize(glm::vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f));
    r.segs.push_back(glm::vec4(o, 0));
    r.segs.push_back(glm::vec4(o + d * (maxLength * u(rng)), 0));
  }
  r.hits = gpuKernel(s, 0, r.segs.data(), r.segs.size() * 16, count, budget);
  return r;
}

TEST(NearFieldTraversal, HierarchicalWalkEqualsBruteForceDda) {
  auto& s = session(snapshotRequest());
  const int res = 64;
  auto grid = readLevel(s, "binary-voxels", 0);
  const int n = 20000;
  SegmentRun r = runSegments(s, n, 1024, 11, 0.6f);
  int hits = 0, mismatches = 0, tieMismatches = 0, exhausted = 0;
  for (int i = 0; i < n; ++i) {
    uint32_t end = r.hits[i].w & 0xFFu;
    if (end == NF_END_BUDGET) { ++exhausted; continue; }
    DdaResult dda = bruteForceDda(grid, res, glm::vec3(r.segs[2 * i]), glm::vec3(r.segs[2 * i + 1]));
    bool gpuHit = end == NF_END_HIT;
    hits += dda.hit;
    bool same = gpuHit == dda.hit && (!gpuHit || glm::ivec3(r.hits[i]) == dda.voxel);
    if (!same) (dda.tie ? tieMismatches : mismatches) += 1;
  }
  RecordProperty("hits", hits);
  RecordProperty("tie_mismatches", tieMismatches);
  EXPECT_GT(hits, n / 10);  // the segments do meet the Cornell box's walls
  EXPECT_EQ(exhausted, 0) << "walks that ran out of 1024 steps";
  EXPECT_EQ(mismatches, 0) << "walks that disagree with the DDA where no corner/edge tie explains it";
  // Ties (two faces crossed within 1e-5 in t) are measure-zero up to float rounding: measured 0
  // of 20000; a handful would still be rounding, not a traversal error.
  EXPECT_LE(tieMismatches, n / 1000);
}

TEST(NearFieldTraversal, StepBudgetExhaustionIsReportedNotAMiss) {
  auto& s = session(snapshotRequest());
  SegmentRun r = runSegments(s, 4000, 2, 12, 1.0f);
  int exhausted = 0, hits = 0;
  for (const auto& h : r.hits) {
    exhausted += (h.w & 0xFFu) == NF_END_BUDGET;
    hits += (h.w & 0xFFu) == NF_END_HIT;
    EXPECT_LE(h.w >> 8, 2u) << "a walk took more steps than its budget";
  }
  EXPECT_GT(exhausted, 1000) << "two steps cannot reach level 0 from level 3: most walks must exhaust";
  EXPECT_EQ(hits, 0);
}

TEST(NearFieldTraversal, OriginsOutsideTheVolumeGiveNoHitThroughTheGuard) {
  auto& s = session(snapshotRequest());
  SegmentRun r = runSegments(s, 4000, 256, 13, 1.0f, false);
  int outside = 0;
  for (int i = 0; i < 4000; ++i) {
    glm::vec3 o(r.segs[2 * i]);
    bool out = glm::any(glm::lessThan(o, glm::vec3(0))) || glm::any(glm::greaterThanEqual(o, glm::vec3(1)));
    uint32_t end = r.hits[i].w & 0xFFu;
    if (out) {
      ++outside;
      EXPECT_EQ(end, NF_END_OUTSIDE) << "segment " << i;
      EXPECT_EQ(r.hits[i].w >> 8, 0u) << "an outside origin must not fetch (0 steps)";
    } else {
      EXPECT_NE(end, NF_END_OUTSIDE);
    }
  }
  EXPECT_GT(outside, 2000);
}

TEST(NearFieldTraversal, ProbeRecordsChangeLevelByOneAndHitOnlyAtLevelZero) {
  // Probe a floor pixel whose first ray hits (checked below), several rays of the run.
  for (int ray = 0; ray < 4; ++ray) {
    auto& s = session(request({"voxel.resolution=64", "rays.count=4", "rsm.resolution=128", "shadow.resolution=256", "probe.x=0.3", "probe.y=0.8",
                               "probe.ray=" + std::to_string(ray)}));
    CapturedOutput steps = capture(s, "rays", "traversal-steps");
    ASSERT_GT(steps.recordCount, 0u);
    std::vector<gpu::TraversalStep> rec(steps.recordCount);
    std::memcpy(rec.data(), steps.records.data(), rec.size() * sizeof(gpu::TraversalStep));
    const int top = maxLevelOf(64);
    for (size_t i = 0; i < rec.size(); ++i) {
      EXPECT_EQ(rec[i].where.x, uint32_t(i)) << "records in walk order";
      EXPECT_LE(rec[i].slices.x, rec[i].slices.y) << "a ray mask with first > last slice (the table's unused half)";
      uint32_t action = rec[i].slices.z;
      if (action == NF_END_HIT) {
        EXPECT_EQ(rec[i].where.y, 0u) << "hit above level 0";
        EXPECT_EQ(i + 1, rec.size()) << "a hit ends the walk";
      }
      if (i + 1 < rec.size()) {
        int expected = action == NF_STEP_DESCEND ? int(rec[i].where.y) - 1 : std::min(int(rec[i].where.y) + 1, top);
        EXPECT_EQ(int(rec[i + 1].where.y), expected) << "step " << i;
      }
    }
    CapturedOutput probe = capture(s, "rays", "probe-ray");
    gpu::ProbeRay p;
    std::memcpy(&p, probe.records.data(), sizeof(p));
    EXPECT_EQ(p.receiver.w, 1.0f);
    EXPECT_EQ(uint32_t(p.steps.x), steps.recordCount);
    if (p.result.w == NF_END_HIT) EXPECT_EQ(rec.back().slices.z, NF_END_HIT);
  }
}

// --- Self-intersection ----------------------------------------------------------------------------

// Rays from points of the wall-floor scene's floor (y = 0, normal +y), far enough from the wall
// that a ray within the radius can only meet the floor, with the rays stage's start offsets.
int floorSelfHits(HeadlessSession& s, float normalOffset, float rayOffset) {
  const Scene& scene = s.cursor().scene();
  const int res = 128;
  BinaryGridGeometry g = BinaryGridGeometry::of(scene, res);
  const float radius = 0.5f * 0.3f;  // metres; the wall is at z = 0.1, points at z <= -0.5
  std::vector<glm::vec4> segs;
  for (int a = 0; a < 90; ++a) {          // theta 0..89 degrees
    for (int p = 0; p < 16; ++p) {        // azimuths and positions
      float theta = float(a) * 3.14159265f / 180.0f, phi = float(p) * 0.3927f + 0.1f;
      glm::vec3 d(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      glm::vec3 pt(-0.6f + 0.07f * float(p), 0.0f, -0.55f - 0.013f * float(a % 7));
      float along = rayOffset * g.voxelDiagonal / std::max(std::cos(theta), 1e-3f);
      if (along >= radius) continue;
      glm::vec3 o = pt + glm::vec3(0, 1, 0) * (normalOffset * g.voxelDiagonal) + d * along;
      glm::vec3 e = o + d * (radius - along);
      segs.push_back(glm::vec4((o - g.origin) / g.edge, 0));
      segs.push_back(glm::vec4((e - g.origin) / g.edge, 0));
    }
  }
  auto hits = gpuKernel(s, 0, segs.data(), segs.size() * 16, int(segs.size() / 2), 1024);
  int n = 0;
  for (const auto& h : hits) n += (h.w & 0xFFu) == NF_END_HIT;
  return n;
}

TEST(NearFieldSelfIntersection, PlaneRaysNeverHitThePlanesOwnVoxels) {
  auto& s = session(request({"voxel.resolution=128"}, "hierarchy", 64, projectPath("tests/data/scenes/wall-floor.gltf")));
  EXPECT_EQ(floorSelfHits(s, 0.8f, 0.6f), 0) << "with the default offsets";
  // The test can fail: without offsets the rays start inside the floor's voxels.
  EXPECT_GT(floorSelfHits(s, 0.0f, 0.0f), 100);
}


// --- Physics --------------------------------------------------------------------------------------

// The near-field estimator on the CPU, on Embree: for a receiver p (normal n, albedo rho), cosine
// rays with the rays stage's start offsets and radius; at the first hit within the radius, the
// reflected direct radiance rho_hit/pi * E * |cos| of the shared light model with an exact shadow
// ray, counted when the receiver lies on the lit side of the hit surface. No voxels, no RSM.
class NearFieldOracle {
 public:
  explicit NearFieldOracle(const Scene& scene) : scene_(scene) {
    device_ = rtcNewDevice(nullptr);
    rtc_ = rtcNewScene(device_);
    RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                           3 * sizeof(float), scene.positions.size()));
    for (size_t i = 0; i < scene.positions.size(); ++i)
      for (int c = 0; c < 3; ++c) vb[3 * i + c] = scene.positions[i][c];
    auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                              3 * sizeof(unsigned), scene.triangleCount()));
    for (size_t i = 0; i < scene.indices.size(); ++i) ib[i] = scene.indices[i];
    rtcCommitGeometry(g);
    rtcAttachGeometry(rtc_, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(rtc_);
  }
  ~NearFieldOracle() {
    rtcReleaseScene(rtc_);
    rtcReleaseDevice(device_);
  }

  // Reflected direct radiance arriving at o along d from the first surface within tMax (0 = none).
  glm::vec3 radianceAlong(glm::vec3 o, glm::vec3 d, float tMax, glm::vec3 receiver) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh{};
    rh.ray.org_x = o.x; rh.ray.org_y = o.y; rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x; rh.ray.dir_y = d.y; rh.ray.dir_z = d.z;
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = tMax;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(rtc_, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return glm::vec3(0.0f);
    glm::vec3 x = o + d * rh.ray.tfar;
    glm::vec3 ng = glm::normalize(glm::vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
    const Light& light = scene_.lights.at(0);
    LightSample ls = sampleLight(light, x);
    float cosL = glm::dot(ng, ls.toLight);
    if (cosL == 0.0f || (cosL > 0.0f) != (glm::dot(ng, receiver - x) > 0.0f)) return glm::vec3(0.0f);
    glm::vec3 side = cosL > 0.0f ? ng : -ng;
    RTCRay shadow{};
    glm::vec3 so = x + side * 1e-4f;
    shadow.org_x = so.x; shadow.org_y = so.y; shadow.org_z = so.z;
    shadow.dir_x = ls.toLight.x; shadow.dir_y = ls.toLight.y; shadow.dir_z = ls.toLight.z;
    shadow.tnear = 0.0f;
    shadow.tfar = std::isinf(ls.distance) ? 1e30f : ls.distance - 2e-4f;
    shadow.mask = 0xFFFFFFFFu;
    rtcOccluded1(rtc_, &ctx, &shadow);
    if (shadow.tfar < 0.0f) return glm::vec3(0.0f);  // occluded
    glm::vec3 rho(scene_.materials[scene_.triangleMaterial(rh.hit.primID)].baseColor);
    return rho / 3.14159265f * ls.irradianceAtNormalIncidence * std::abs(cosL);
  }

 private:
  const Scene& scene_;
  RTCDevice device_ = nullptr;
  RTCScene rtc_ = nullptr;
};

struct Readback {
  int w = 0, h = 0, channels = 4;
  std::vector<float> v;
  const float* at(int x, int y) const { return &v[(size_t(y) * w + x) * channels]; }
};

Readback readFloat(HeadlessSession& s, const std::string& name) {
  Texture& t = s.cursor().board().texture(name);
  Readback r;
  r.w = t.levelSize(0).x;
  r.h = t.levelSize(0).y;
  r.v.resize(size_t(r.w) * r.h * 4);
  glGetTextureImage(t.id(), 0, GL_RGBA, GL_FLOAT, GLsizei(r.v.size() * 4), r.v.data());
  return r;
}

// Sum over the surface pixels (position.w != 0) of a size x size image's r+g+b, over the same sum of
// the reference (ref.width / size times finer, box-filtered onto each pixel; rows bottom-up).
double surfaceMeanOverReference(const Readback& pos, const Readback& image, const reference::Image& ref, int size) {
  const int f = ref.width / size;
  double refSum = 0, sum = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      if (pos.at(x, y)[3] == 0.0f) continue;
      for (int j = 0; j < f * f; ++j) {
        const float* r = ref.at(x * f + j % f, (size - 1 - y) * f + j / f);
        refSum += (r[0] + r[1] + r[2]) / double(f * f);
      }
      sum += image.at(x, y)[0] + image.at(x, y)[1] + image.at(x, y)[2];
    }
  return sum / refSum;
}

// --- Hit voxel vs the true surface ---------------------------------------------------------------

// Distance from world point p to binary voxel v's box, per axis in that axis' voxel size, in
// double (the test's own computation; the record's is surface_query.cpp's gapToVoxel in float).
glm::dvec3 axisGapCells(const BinaryGridGeometry& g, glm::ivec3 v, glm::vec3 p) {
  const glm::dvec3 dims(g.resolution, g.resolution, kBinarySlices);
  const glm::dvec3 c = (glm::dvec3(p) - glm::dvec3(g.origin)) / double(g.edge) * dims;
  return glm::max(glm::max(glm::dvec3(v) - c, c - (glm::dvec3(v) + 1.0)), glm::dvec3(0.0));
}
double chebyshev(glm::dvec3 a) { return std::max({a.x, a.y, a.z}); }

// t (unit-space segment parameter) at which segment o -> e enters voxel v's box (slab test).
double tEnterVoxel(glm::ivec3 v, int res, glm::dvec3 o, glm::dvec3 e) {
  const glm::dvec3 dims(res, res, kBinarySlices), d = e - o;
  double t0 = -1e30;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) continue;
    double lo = (v[a] / dims[a] - o[a]) / d[a], hi = ((v[a] + 1) / dims[a] - o[a]) / d[a];
    t0 = std::max(t0, std::min(lo, hi));
  }
  return std::max(t0, 0.0);
}

// Many rays as the rays stage casts them (random receivers of the G-buffer, cosine directions, the
// default start offsets and radius), walked by the GPU traversal over the Cornell box's voxels and
// cast exactly by the reference path tracer's Embree query. What holds for every ray: the walk
// never enters its hit voxel after the true surface (conservative voxels put the surface point's
// own voxel on the ray, so the walk stops there or earlier), it finds every surface within the
// radius, and where the hit voxel overlaps the true surface's plane the walk stops at most the
// voxel's extent along the normal / |cos| before the surface (the entry point lies in a box that
// meets the plane). How far the hit voxel lies from the true point is measured and bounded.
TEST(NearFieldProbe, HitVoxelContainsOrTouchesTheTrueFirstHitOnManyRandomRays) {
  auto& s = session(snapshotRequest());
  const Scene& scene = s.cursor().scene();
  const int res = 64;
  const BinaryGridGeometry g = BinaryGridGeometry::of(scene, res);
  const glm::dvec3 cell(g.columnSize, g.columnSize, g.sliceDepth);
  const float radius = 0.5f * g.edge;  // half the volume's edge: rays that end short as well as rays that hit
  Readback pos = readFloat(s, "position"), nrm = readFloat(s, "normal");
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  struct Ray { glm::vec3 o, d; float length; };
  std::vector<Ray> rays;
  std::vector<glm::vec4> segs;
  const int wanted = 8000;
  while (int(rays.size()) < wanted) {
    const int x = std::min(int(u(rng) * pos.w), pos.w - 1), y = std::min(int(u(rng) * pos.h), pos.h - 1);
    if (pos.at(x, y)[3] == 0.0f) continue;
    const glm::vec3 P(pos.at(x, y)[0], pos.at(x, y)[1], pos.at(x, y)[2]);
    const glm::vec3 N = glm::normalize(glm::vec3(nrm.at(x, y)[0], nrm.at(x, y)[1], nrm.at(x, y)[2]));
    const glm::vec3 T = glm::normalize(std::abs(N.x) > 0.9f ? glm::cross(N, glm::vec3(0, 1, 0)) : glm::cross(N, glm::vec3(1, 0, 0)));
    const glm::vec3 B = glm::cross(N, T);
    const float u1 = u(rng), phi = 6.2831853f * u(rng), cosT = std::sqrt(1.0f - u1), sinT = std::sqrt(u1);
    const glm::vec3 d = glm::normalize(T * (sinT * std::cos(phi)) + B * (sinT * std::sin(phi)) + N * cosT);
    const float along = 0.6f * g.voxelDiagonal / std::max(cosT, 1e-3f);
    if (along >= radius) continue;
    const glm::vec3 o = P + N * (0.8f * g.voxelDiagonal) + d * along;
    const glm::vec3 ou = (o - g.origin) / g.edge;
    if (glm::any(glm::lessThan(ou, glm::vec3(0))) || glm::any(glm::greaterThanEqual(ou, glm::vec3(1)))) continue;
    rays.push_back({o, d, radius - along});
    segs.push_back(glm::vec4(ou, 0));
    segs.push_back(glm::vec4((o + d * (radius - along) - g.origin) / g.edge, 0));
  }
  const auto hits = gpuKernel(s, 0, segs.data(), segs.size() * 16, wanted, 1024);
  reference::ReferenceTracer tracer(scene);
  int walkHits = 0, contains = 0, touches = 0, samePlaneFarther = 0, otherSurface = 0;
  int beyondSurface = 0, beyondPlaneBound = 0, hitNoSurface = 0, hitJustBeyondRadius = 0, surfaceNoHit = 0;
  double worstGap = 0, worstSamePlaneGap = 0, sumGap = 0;
  for (int i = 0; i < wanted; ++i) {
    const Ray& r = rays[i];
    const float tTrue = tracer.firstHit(r.o, r.d);
    const bool surface = tTrue <= r.length;
    const bool hit = (hits[i].w & 0xFFu) == NF_END_HIT;
    ASSERT_NE(hits[i].w & 0xFFu, NF_END_BUDGET) << "ray " << i << " ran out of 1024 steps";
    const glm::ivec3 v(hits[i].x, hits[i].y, hits[i].z);
    if (hit && !surface) {
      ++hitNoSurface;  // a voxel of a surface the ray passes within a voxel of, or one just past the radius
      hitJustBeyondRadius += tTrue <= r.length + g.voxelDiagonal;
      continue;
    }
    if (!hit) { surfaceNoHit += surface; continue; }
    ++walkHits;
    const glm::vec3 x = r.o + r.d * tTrue;
    const double gap = chebyshev(axisGapCells(g, v, x));
    worstGap = std::max(worstGap, gap);
    sumGap += gap;
    const double tEnter = tEnterVoxel(v, res, glm::dvec3(segs[2 * i]), glm::dvec3(segs[2 * i + 1])) * r.length;
    // 1e-4 of a column: float rounding of the segment's ends (1e-7 relative of a 1.2 m volume is 6e-6 columns).
    beyondSurface += tEnter > tTrue + 1e-4 * g.columnSize;
    // The true surface's plane, from the triangle the exact query names at the same t as Embree.
    const SurfaceHit sh = firstSurfaceAlong(scene, r.o, r.d, r.length);
    ASSERT_TRUE(sh.hit);
    ASSERT_NEAR(sh.t, tTrue, 1e-5f) << "the record's ray/triangle query disagrees with Embree";
    const glm::dvec3 p0(scene.positions[scene.indices[3 * sh.triangle]]);
    const glm::dvec3 n = glm::normalize(glm::cross(glm::dvec3(scene.positions[scene.indices[3 * sh.triangle + 1]]) - p0,
                                                   glm::dvec3(scene.positions[scene.indices[3 * sh.triangle + 2]]) - p0));
    const glm::dvec3 lo = glm::dvec3(g.origin) + glm::dvec3(v) * cell, centre = lo + 0.5 * cell;
    const double extentN = glm::dot(glm::abs(n), cell);  // the box's extent along n
    const bool meetsPlane = std::abs(glm::dot(centre - p0, n)) <= 0.5 * extentN;
    if (gap <= 1e-4) ++contains;  // 1e-4 cells: the rounding above
    else if (gap <= 1.0 + 1e-4) ++touches;
    else if (meetsPlane) ++samePlaneFarther;
    else ++otherSurface;
    if (meetsPlane) {
      worstSamePlaneGap = std::max(worstSamePlaneGap, gap);
      const double cosN = std::abs(glm::dot(n, glm::dvec3(r.d)));
      beyondPlaneBound += tTrue - tEnter > extentN / cosN + 1e-4 * g.columnSize;
    }
  }
  std::printf("hit voxel vs true first hit, %d rays, %d walk hits on a surface: %d contain it, %d touch it (a 26-neighbour "
              "holds it), %d farther on the same plane (grazing), %d on another surface's voxel; gap worst %.2f voxels "
              "(same plane %.2f), mean %.3f; %d hits with no surface within the radius (%d of them within a voxel "
              "diagonal past it), %d surfaces missed, %d entered beyond the surface, %d beyond the plane bound\n",
              wanted, walkHits, contains, touches, samePlaneFarther, otherSurface, worstGap, worstSamePlaneGap,
              walkHits ? sumGap / walkHits : 0.0, hitNoSurface, hitJustBeyondRadius, surfaceNoHit, beyondSurface,
              beyondPlaneBound);
  RecordProperty("contain", contains);
  RecordProperty("touch", touches);
  RecordProperty("same_plane_farther", samePlaneFarther);
  RecordProperty("other_surface", otherSurface);
  EXPECT_GT(walkHits, wanted / 4);  // measured 2927 of 8000 (the rest leave the open box or end short)
  EXPECT_EQ(beyondSurface, 0) << "a walk stopped in a voxel entered after the true surface";
  EXPECT_EQ(surfaceNoHit, 0) << "a surface within the radius the walk did not find (a hole in the voxels)";
  EXPECT_EQ(beyondPlaneBound, 0) << "a hit voxel on the surface's plane farther before it than extent / |cos|";
  // The measured bound (64 columns, 128 slices, seed 21): 687 contain, 1323 touch, so 69 % of the
  // hits hold the true point within one voxel; the rest are grazing rays on the same plane or
  // voxels of another surface the ray passes within a voxel of (near misses at the blocks' edges).
  // Bounds at about 0.85x / 2x of what was measured, so a coarser or shifted voxelization fails.
  EXPECT_GE(contains + touches, 0.58 * walkHits);
  EXPECT_LE(otherSurface, 0.075 * walkHits);     // measured 108 (3.7 %)
  EXPECT_LE(hitNoSurface, 0.08 * wanted);        // measured 311 (3.9 %), 81 of them just past the radius
}

// The probe record's CPU half (surface point, its t and triangle, the gaps) against the test's own
// computation: Embree's first hit from the record's origin along its direction, the gaps in
// double from the record's hit voxel. Probed floor and wall pixels, several ray indices.
TEST(NearFieldProbe, RecordedSurfacePointAndGapsAgreeWithAnIndependentComputation) {
  int withGap = 0, withSurface = 0;
  for (const char* where : {"probe.x=0.3 probe.y=0.8", "probe.x=0.15 probe.y=0.4"})
    for (int ray = 0; ray < 4; ++ray) {
      std::vector<std::string> sets = {"voxel.resolution=64", "rays.count=4", "rsm.resolution=128", "shadow.resolution=256"};
      const std::string w(where);
      sets.push_back(w.substr(0, w.find(' ')));
      sets.push_back(w.substr(w.find(' ') + 1));
      sets.push_back("probe.ray=" + std::to_string(ray));
      auto& s = session(request(sets));
      const Scene& scene = s.cursor().scene();
      const BinaryGridGeometry g = BinaryGridGeometry::of(scene, 64);
      const CapturedOutput out = capture(s, "rays", "probe-ray");
      gpu::ProbeRay p;
      ASSERT_EQ(out.records.size(), sizeof(p));
      std::memcpy(&p, out.records.data(), sizeof(p));
      ASSERT_EQ(p.receiver.w, 1.0f) << where << " ray " << ray;
      const reference::ReferenceTracer tracer(scene);
      const glm::vec3 o(p.origin), d(p.direction);
      const float tTrue = tracer.firstHit(o, d);
      SCOPED_TRACE(std::string(where) + " ray " + std::to_string(ray));
      if (tTrue > p.origin.w) {
        EXPECT_EQ(p.surface.w, -1.0f) << "a surface recorded where Embree finds none within the radius";
        EXPECT_EQ(p.surfaceGap.x, -1.0f);
        continue;
      }
      ++withSurface;
      // Both in float from the same ray: measured within 2e-7 m; 1e-5 m is 1/2000 of a voxel.
      EXPECT_NEAR(p.surface.w, tTrue, 1e-5f);
      const glm::vec3 x = o + d * tTrue;
      for (int a = 0; a < 3; ++a) EXPECT_NEAR(p.surface[a], x[a], 1e-5f);
      const uint32_t tri = uint32_t(p.surfaceGap.w);
      ASSERT_LT(tri, scene.triangleCount());
      const glm::vec3 p0 = scene.positions[scene.indices[3 * tri]];
      const glm::vec3 n = glm::normalize(glm::cross(scene.positions[scene.indices[3 * tri + 1]] - p0,
                                                    scene.positions[scene.indices[3 * tri + 2]] - p0));
      EXPECT_NEAR(glm::dot(x - p0, n), 0.0f, 1e-5f) << "the recorded triangle's plane does not hold the surface point";
      if (p.result.w != NF_END_HIT) {
        EXPECT_EQ(p.surfaceGap.x, -1.0f);
        continue;
      }
      ++withGap;
      const glm::dvec3 gap = axisGapCells(g, glm::ivec3(glm::uvec3(p.result)), x);
      // float (record) against double (here) over a 1.2 m volume: 1e-4 cells is 2 um.
      EXPECT_NEAR(p.surfaceGap.x, chebyshev(gap), 1e-4);
      EXPECT_NEAR(p.surfaceGap.y, glm::length(gap), 1e-4);
      EXPECT_NEAR(p.surfaceGap.z, (tTrue - p.hitPoint.w) / g.voxelDiagonal, 1e-3);
      EXPECT_GE(p.surfaceGap.z, -1e-3f) << "the walk's hit point lies beyond the surface";

      // The view's check passes on the record and catches a surface point moved off the ray.
      const Visualiser& vis = visualiserFor(out.desc);
      EXPECT_STREQ(vis.name(), "near-field-probe-ray");
      const RecordCheck ok = vis.checkRecords(out);
      EXPECT_TRUE(ok.error.empty()) << ok.error;
      EXPECT_NE(ok.summary.find("true surface"), std::string::npos) << ok.summary;
      CapturedOutput broken = out;
      gpu::ProbeRay q = p;
      q.surface.x += 0.01f;
      std::memcpy(broken.records.data(), &q, sizeof(q));
      EXPECT_NE(vis.checkRecords(broken).error, "");
    }
  EXPECT_GE(withSurface, 4);
  EXPECT_GE(withGap, 4);
}

// --- What the views say: categories, the RSM lookup, slice depths ----------------------------------

// The category image has its own visualiser: a distinct colour per category (exact tier), the
// category's name under the cursor, and per-category pixel counts that equal the stage's own
// counters (one ray per pixel, so the image holds every ray's category).
TEST(NearFieldViews, CategoryImageNamesAndCountsEveryCategory) {
  auto& s = session(request({"voxel.resolution=64", "rays.count=1", "rsm.resolution=128", "shadow.resolution=256"}));
  const CapturedOutput out = capture(s, "rays", "ray-category");
  const Visualiser& vis = visualiserFor(out.desc);
  EXPECT_STREQ(vis.name(), "rsm-lookup-category");
  EXPECT_EQ(vis.defaultTier(out.desc), CaptureTier::Exact);
  const nlohmann::json cats = vis.statistics(out).at("categories");
  const auto& stats = s.cursor().record(s.cursor().technique().stageIndex("rays")).stats;
  const char* keys[NF_CATEGORIES] = {"valid", "no_hit", "not_in_rsm", "too_far", "wrong_facing", "budget_spent", "dropped", "no_receiver"};
  double traced = 0;
  for (int k = 0; k < NF_CATEGORIES - 1; ++k) {  // no_receiver pixels trace no ray: the counters skip them
    EXPECT_EQ(cats.at(keys[k]).get<double>(), stats.at(std::string("rays_") + keys[k])) << keys[k];
    traced += cats.at(keys[k]).get<double>();
  }
  EXPECT_EQ(traced, stats.at("rays_traced"));
  EXPECT_EQ(cats.at("unknown").get<int>(), 0);
  std::printf("ray-category: %s\n", cats.dump().c_str());
  EXPECT_GT(cats.at("valid").get<int>(), 0);
  EXPECT_GT(cats.at("no_hit").get<int>(), 0);
  // Every category its own colour.
  const TexelMapping& m = texelMapping(out.desc.semantic);
  std::set<std::array<uint8_t, 3>> colours;
  for (int k = 0; k < NF_CATEGORIES; ++k) {
    const float v = float(k);
    std::array<uint8_t, 3> rgb{};
    m.map(&v, 1, 1.0f, 0.0f, 0.0f, rgb.data());
    colours.insert(rgb);
  }
  EXPECT_EQ(colours.size(), size_t(NF_CATEGORIES));
  // Hover: the category by name, at the same pixel as the image's value.
  ViewSettings view;
  nlohmann::json st, rec;
  VisualiserContext ctx{out, st, rec, view, nullptr};
  const LevelData& L = out.levels.at(0);
  int named = 0;
  for (int y = 0; y < L.size.y; y += 5)
    for (int x = 0; x < L.size.x; x += 5) {
      const int k = int(L.at(x, y, 0, 0));
      const std::string line = vis.describeElement(ctx, {x, y, 0});
      const std::string name = k == 0 ? "valid" : k == 1 ? "no hit" : k == 3 ? "too far" : k == 7 ? "no receiver" : "";
      if (name.empty()) continue;
      EXPECT_NE(line.find(": " + name), std::string::npos) << line;
      ++named;
    }
  EXPECT_GT(named, 100);
}

// The probed ray's RSM lookup: the recorded texel's position and normal are the RSM's own texels,
// the distance is |hit - RSM position|, the category follows from distance and facing; the view's
// check passes on the record and fails on a category that contradicts the values.
TEST(NearFieldViews, ProbeRecordCarriesTheRsmLookupAndItsCheckCatchesAWrongCategory) {
  int looked = 0;
  for (int ray = 0; ray < 4; ++ray) {
    auto& s = session(request({"voxel.resolution=64", "rays.count=4", "rsm.resolution=128", "shadow.resolution=256",
                               "rsm.validity=distance", "probe.x=0.3", "probe.y=0.8",
                               "probe.ray=" + std::to_string(ray)}));
    const CapturedOutput out = capture(s, "rays", "probe-ray");
    gpu::ProbeRay p;
    ASSERT_EQ(out.records.size(), sizeof(p));
    std::memcpy(&p, out.records.data(), sizeof(p));
    const Visualiser& vis = visualiserFor(out.desc);
    const RecordCheck ok = vis.checkRecords(out);
    EXPECT_TRUE(ok.error.empty()) << ok.error;
    EXPECT_NE(ok.summary.find("RSM lookup: "), std::string::npos) << ok.summary;
    const int cat = int(p.rsmRadiance.w);
    EXPECT_EQ(int(p.rsmNormal.w), 1) << "rsm.normal-check on, distance validity: flags 1";
    if (cat != NF_CAT_VALID && cat != NF_CAT_TOO_FAR && cat != NF_CAT_WRONG_FACING) continue;
    ++looked;
    std::printf("probe ray %d: category %d, distance %.5f m vs threshold %.5f m, facing %.3f\n", ray, cat, p.rsmSample.z,
                p.rsmSample.w, p.steps.z);
    const Readback pos = readFloat(s, "rsm-position"), nrm = readFloat(s, "rsm-normal");
    const int tx = int(p.rsmSample.x), ty = int(p.rsmSample.y);
    ASSERT_TRUE(tx >= 0 && ty >= 0 && tx < pos.w && ty < pos.h);
    for (int c = 0; c < 4; ++c) EXPECT_EQ(p.rsmPosition[c], pos.at(tx, ty)[c]) << "position channel " << c;
    for (int c = 0; c < 3; ++c) EXPECT_EQ(p.rsmNormal[c], nrm.at(tx, ty)[c]) << "normal channel " << c;
    // Same float inputs on GPU and CPU: measured 0 m apart (3 lookups, 1 and 2 threads); another
    // rounding order would move it by float steps at metre scale (1e-7 m); 1e-5 m is 1/1300 of a
    // voxel diagonal (0.0133 m), far below the 0.013-0.036 m thresholds it is compared with.
    const float cpuDistance = glm::length(glm::vec3(p.hitPoint) - glm::vec3(p.rsmPosition));
    std::printf("  distance GPU - CPU: %.3g m\n", p.rsmSample.z - cpuDistance);
    EXPECT_NEAR(p.rsmSample.z, cpuDistance, 1e-5f);
    EXPECT_EQ(cat == NF_CAT_TOO_FAR, p.rsmSample.z > p.rsmSample.w);
    CapturedOutput broken = out;
    gpu::ProbeRay q = p;
    q.rsmRadiance.w = float(cat == NF_CAT_TOO_FAR ? NF_CAT_VALID : NF_CAT_TOO_FAR);
    std::memcpy(broken.records.data(), &q, sizeof(q));
    EXPECT_NE(vis.checkRecords(broken).error, "") << "a category that contradicts the distance passed the check";
  }
  EXPECT_GE(looked, 1) << "no probed ray reached the RSM lookup";
}

// The binary grid and its hierarchy are placed in the world, so a column's slices read as depth
// intervals in metres; the ray-mask table's entry (i, j) reads slices i..j at the grid's depths.
TEST(NearFieldViews, SliceDepthsAreInWorldUnits) {
  auto& s = session(snapshotRequest());
  const Scene& scene = s.cursor().scene();
  const WorldBox box = VoxelSpace::fromScene(scene, 64).box();
  const CapturedOutput grid = capture(s, "binary-voxels", "binary-voxels");
  ASSERT_TRUE(grid.world.has_value());
  EXPECT_EQ(grid.world->lo, box.lo);
  EXPECT_EQ(grid.world->hi, box.hi);
  ASSERT_TRUE(capture(s, "hierarchy", "bitmask-hierarchy").world.has_value());
  const float z0 = box.lo.z, dz = (box.hi.z - box.lo.z) / 128.0f;
  auto expectRange = [&](int i, int j) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%d-%d (z %.4g..%.4g m)", i, j, z0 + i * dz, z0 + (j + 1) * dz);
    return std::string(buf);
  };
  const CapturedOutput masks = capture(s, "bitmask-tables", "ray-masks");
  EXPECT_FALSE(masks.world.has_value()) << "the table is not placed itself";
  ViewSettings view;
  nlohmann::json st, rec;
  VisualiserContext ctx{masks, st, rec, view, nullptr};
  ctx.contextOutput = [&](const char* what, CapturedOutput& o) {
    if (std::string(what) != "binary-voxels") return false;
    o = grid;
    return true;
  };
  const Visualiser& vis = visualiserFor(masks.desc);
  const std::string line = vis.describeElement(ctx, {10, 20, 0});
  EXPECT_NE(line.find(expectRange(10, 20)), std::string::npos) << line;
  ctx.contextOutput = nullptr;
  EXPECT_EQ(vis.describeElement(ctx, {10, 20, 0}).find(" m)"), std::string::npos) << "a depth without a placement";
}

// --- RSM ------------------------------------------------------------------------------------------

TEST(NearFieldRsm, ReflectedRadianceIsAlbedoOverPiTimesTheLightModelsIrradiance) {
  auto& s = session(snapshotRequest());
  const Scene& scene = s.cursor().scene();
  Readback pos = readFloat(s, "rsm-position"), nrm = readFloat(s, "rsm-normal"), rad = readFloat(s, "rsm-radiance");
  int checked = 0, unmatched = 0;
  for (size_t t = 0; t < size_t(pos.w) * pos.h; t += 7) {
    const float* p = &pos.v[t * 4];
    if (p[3] == 0.0f) continue;
    glm::vec3 P(p[0], p[1], p[2]), N(nrm.v[t * 4], nrm.v[t * 4 + 1], nrm.v[t * 4 + 2]);
    LightSample ls = sampleLight(scene.lights.at(0), P);
    float cosL = glm::dot(glm::normalize(N), ls.toLight);
    EXPECT_GE(cosL, -1e-3f) << "RSM normal on the unlit side";
    glm::vec3 e = ls.irradianceAtNormalIncidence * std::max(cosL, 0.0f) / 3.14159265f;
    if (e.x < 1e-3f) continue;
    glm::vec3 albedo = glm::vec3(rad.v[t * 4], rad.v[t * 4 + 1], rad.v[t * 4 + 2]) / e;
    // RGBA16F storage: relative error below 1e-3; the light model runs in float on both sides.
    bool match = false;
    for (const auto& m : scene.materials)
      match = match || glm::all(glm::lessThan(glm::abs(albedo - glm::vec3(m.baseColor)), glm::vec3(3e-3f)));
    unmatched += !match;
    ++checked;
  }
  EXPECT_GT(checked, 500);
  // Texels on a triangle edge can take the neighbour's position after interpolation: measured 0.
  EXPECT_EQ(unmatched, 0) << "of " << checked << " texels, radiance / (E cos / pi) is no material's albedo";
}

struct PhysicsResult {
  double ratio = 0, worstRegion = 0, nearOverOneBounce = 0;
};

// GPU near-field indirect (64 rays, full resolution, 64 x 64) against the CPU estimator with the
// same cone of directions ('spread') and the same (rho * spread / N) scale.
PhysicsResult comparePhysics(float spread, const std::string& scenePath = "cornell-box",
                             std::vector<std::string> extraSets = {}) {
  PhysicsResult result;
  const int size = 64, rays = 64;
  // A radius of half the volume's edge (not the default, which crosses the whole volume), so the
  // comparison with the one-bounce reference shows the light lost beyond it; the paper's distance
  // validity unless extraSets says otherwise (the oracle's shadow ray is exact either way).
  std::vector<std::string> sets = {"voxel.resolution=128", "rays.count=" + std::to_string(rays), "rays.resolution=full",
                                   "rays.spread=" + std::to_string(spread), "rays.radius=0.5",
                                   "rsm.validity=distance"};
  sets.insert(sets.end(), extraSets.begin(), extraSets.end());
  auto& s = session(request(sets, "", size, scenePath));
  const Scene& scene = s.cursor().scene();
  BinaryGridGeometry g = BinaryGridGeometry::of(scene, 128);
  const float radius = 0.5f * g.edge;  // rays.radius=0.5, set above
  Readback pos = readFloat(s, "position"), nrm = readFloat(s, "normal"), alb = readFloat(s, "albedo");
  Readback ind = readFloat(s, "indirect");
  NearFieldOracle oracle(scene);
  // Region means over 4 x 4 blocks of 16 x 16 pixels, luminance-free per channel sums.
  const int blocks = 4, bs = size / blocks, cpuRays = 256;
  std::vector<glm::dvec3> gpuSum(blocks * blocks, glm::dvec3(0)), cpuSum(blocks * blocks, glm::dvec3(0));
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const float* p = pos.at(x, y);
      if (p[3] == 0.0f) continue;
      glm::vec3 P(p[0], p[1], p[2]), N = glm::normalize(glm::vec3(nrm.at(x, y)[0], nrm.at(x, y)[1], nrm.at(x, y)[2]));
      glm::vec3 rho(alb.at(x, y)[0], alb.at(x, y)[1], alb.at(x, y)[2]);
      glm::vec3 T = glm::normalize(std::abs(N.x) > 0.9f ? glm::cross(N, glm::vec3(0, 1, 0)) : glm::cross(N, glm::vec3(1, 0, 0)));
      glm::vec3 B = glm::cross(N, T);
      glm::vec3 sum(0.0f);
      for (int i = 0; i < cpuRays; ++i) {
        float u1 = u(rng) * spread, u2 = u(rng);
        float cosT = std::sqrt(1.0f - u1), sinT = std::sqrt(u1), phi = 6.2831853f * u2;
        glm::vec3 d = glm::normalize(T * (sinT * std::cos(phi)) + B * (sinT * std::sin(phi)) + N * cosT);
        float along = 0.6f * g.voxelDiagonal / std::max(cosT, 1e-3f);
        if (along >= radius) continue;
        glm::vec3 o = P + N * (0.8f * g.voxelDiagonal) + d * along;
        sum += oracle.radianceAlong(o, d, radius - along, P);
      }
      glm::vec3 cpu = rho * spread * sum / float(cpuRays);  // (rho * spread / N) sum L~, cosine sampling
      int b = (y / bs) * blocks + x / bs;
      cpuSum[b] += glm::dvec3(cpu);
      gpuSum[b] += glm::dvec3(ind.at(x, y)[0], ind.at(x, y)[1], ind.at(x, y)[2]);
    }
  glm::dvec3 gpuAll(0), cpuAll(0);
  double worstRel = 0;
  for (int b = 0; b < blocks * blocks; ++b) {
    gpuAll += gpuSum[b];
    cpuAll += cpuSum[b];
  }
  const double cpuTotal = cpuAll.x + cpuAll.y + cpuAll.z;
  // Worst region among those holding at least 2 % of the light (darker ones are mostly noise).
  for (int b = 0; b < blocks * blocks; ++b) {
    double c = cpuSum[b].x + cpuSum[b].y + cpuSum[b].z, gv = gpuSum[b].x + gpuSum[b].y + gpuSum[b].z;
    if (c > 0.02 * cpuTotal) worstRel = std::max(worstRel, std::abs(gv - c) / c);
  }
  double ratio = (gpuAll.x + gpuAll.y + gpuAll.z) / cpuTotal;
  std::printf("near-field GPU / CPU estimator (spread %.2f): %.4f (r %.4f g %.4f b %.4f), worst region %.3f\n",
              spread, ratio, gpuAll.x / cpuAll.x, gpuAll.y / cpuAll.y, gpuAll.z / cpuAll.z, worstRel);
  result.ratio = ratio;
  result.worstRegion = worstRel;
  // Full one-bounce reference (indirect-1 at 512 x 512, box-filtered to 64 x 64): the near-field
  // estimate misses what arrives from beyond the radius, so it must lie below it.
  if (scenePath != "cornell-box") return result;
  reference::Image ref = reference::readExr(projectPath("tests/golden/reference/cornell-box/indirect-1.exr"));
  result.nearOverOneBounce = surfaceMeanOverReference(pos, ind, ref, size);
  return result;
}


TEST(NearFieldPhysics, IndirectAgreesWithCpuNearFieldEstimatorAndLosesOnlyBeyondTheRadius) {
  PhysicsResult r = comparePhysics(1.0f);
  const double ratio = r.ratio, worstRel = r.worstRegion;
  RecordProperty("gpu_over_cpu", std::to_string(ratio));
  RecordProperty("worst_region_relative_difference", std::to_string(worstRel));
  // Measured 0.987 overall (per channel 0.983..0.989) and 0.082 in the worst 16 x 16 region: the
  // remaining differences are voxel hit points (up to a voxel off the surface), epsilon rejections
  // and Monte Carlo noise (64 GPU and 256 CPU rays per pixel; the whole-image mean's standard error
  // is about 0.5 %). A missing pi (the printed (rho/pi)/N form) gives 0.32, GP3's contrast 2 gives 2.
  EXPECT_NEAR(ratio, 1.0, 0.04);
  EXPECT_LT(worstRel, 0.2);
  std::printf("near-field / full one-bounce reference: %.4f\n", r.nearOverOneBounce);
  RecordProperty("near_field_over_one_bounce", std::to_string(r.nearOverOneBounce));
  // Measured 0.464 with a radius of half the volume edge: the rest of the one-bounce light
  // comes from farther away. Bounded on both sides so neither "all lost" nor "more than the whole
  // bounce" passes.
  EXPECT_GT(r.nearOverOneBounce, 0.25);
  EXPECT_LT(r.nearOverOneBounce, 0.9);
}

TEST(NearFieldPhysics, ReducedSpreadIsCompensatedInTheEstimator) {
  // Rays only within the cone that keeps half of the cosine-weighted hemisphere: the pdf is
  // cos / (pi * spread), so the estimate is scaled by spread (GP3 leaves it uncompensated, which
  // here would read about 0.5). Measured 0.987; same noise argument as above, fewer valid hits.
  PhysicsResult r = comparePhysics(0.5f);
  RecordProperty("gpu_over_cpu", std::to_string(r.ratio));
  EXPECT_NEAR(r.ratio, 1.0, 0.05);
}


// The Cornell box lit by a directional light (3 W/m^2) through its open front, travelling down
// and into the box, instead of the spot: the RSM and the lookup must follow the shared light model
// for both kinds (written once to the temporary directory).
std::string sunlitCornellBox() {
  std::string out = (std::filesystem::temp_directory_path() / "voxlab-near-field-sun.gltf").string();
  nlohmann::json g = nlohmann::json::parse(std::ifstream(projectPath("scenes/cornell-box.gltf")));
  auto& light = g["extensions"]["KHR_lights_punctual"]["lights"][0];
  light = {{"type", "directional"}, {"color", {1.0, 0.95, 0.85}}, {"intensity", 3.0}, {"name", "sun"}};
  glm::quat q = glm::rotation(glm::vec3(0, 0, -1), glm::normalize(glm::vec3(0.2f, -0.6f, 1.0f)));
  for (auto& n : g["nodes"])
    if (n.contains("extensions")) n["rotation"] = {q.x, q.y, q.z, q.w};
  std::ofstream(out) << g.dump();
  return out;
}

TEST(NearFieldRsm, DirectionalLightRsmAndEstimatorFollowTheSharedLightModel) {
  const std::string scene = sunlitCornellBox();
  {
    auto& s = session(request({"voxel.resolution=64", "rsm.resolution=128"}, "rsm", 64, scene));
    ASSERT_EQ(s.cursor().scene().lights.at(0).type, LightType::Directional);
    Readback pos = readFloat(s, "rsm-position"), nrm = readFloat(s, "rsm-normal"), rad = readFloat(s, "rsm-radiance");
    int checked = 0, unmatched = 0;
    for (size_t t = 0; t < size_t(pos.w) * pos.h; t += 7) {
      if (pos.v[t * 4 + 3] == 0.0f) continue;
      glm::vec3 P(pos.v[t * 4], pos.v[t * 4 + 1], pos.v[t * 4 + 2]), N(nrm.v[t * 4], nrm.v[t * 4 + 1], nrm.v[t * 4 + 2]);
      LightSample ls = sampleLight(s.cursor().scene().lights.at(0), P);
      glm::vec3 e = ls.irradianceAtNormalIncidence * std::max(glm::dot(glm::normalize(N), ls.toLight), 0.0f) / 3.14159265f;
      if (e.x < 1e-3f) continue;
      glm::vec3 albedo = glm::vec3(rad.v[t * 4], rad.v[t * 4 + 1], rad.v[t * 4 + 2]) / e;
      bool match = false;
      for (const auto& m : s.cursor().scene().materials)
        match = match || glm::all(glm::lessThan(glm::abs(albedo - glm::vec3(m.baseColor)), glm::vec3(3e-3f)));
      unmatched += !match;
      ++checked;
    }
    EXPECT_GT(checked, 500);
    EXPECT_EQ(unmatched, 0) << "of " << checked;  // measured 0, as for the spot
  }
  // The estimator under the sun. The sun grazes the red wall (cos 0.17): a hit point a voxel off
  // the wall projects into an RSM texel about a voxel / 0.17 away along it, beyond the paper's
  // epsilon, so the distance test rejects true hits there: measured GPU / CPU 0.910 (red 0.870),
  // worst region 0.43. rsm.validity=plane (the hit within a voxel diagonal of the sender's plane,
  // the default) measured 1.040, worst region 0.073: it keeps those hits and admits a few more than the exact
  // shadow ray does (hits within a voxel of a shadow boundary).
  PhysicsResult plane = comparePhysics(1.0f, scene, {"rsm.validity=plane"});
  RecordProperty("plane_gpu_over_cpu", std::to_string(plane.ratio));
  EXPECT_NEAR(plane.ratio, 1.0, 0.07);
  EXPECT_LT(plane.worstRegion, 0.2);
  PhysicsResult distance = comparePhysics(1.0f, scene);
  RecordProperty("distance_gpu_over_cpu", std::to_string(distance.ratio));
  EXPECT_GT(distance.ratio, 0.85);
  EXPECT_LT(distance.ratio, plane.ratio) << "the distance test should lose grazing hits the plane test keeps";
}


// --- Low-frequency noise (blotches) ----------------------------------------------------------------

// Blotches: noise the filter spreads into soft patches a few tens of pixels wide. Measured on the
// flat ceiling and on the back wall (the most common plane facing along z), each tiled into boxes
// of 16 x 16 view pixels that lie wholly on it. A box's blotch is its mean minus the mean of its
// neighbouring boxes on the plane (smooth shading, a gradient, cancels; a patch of the boxes' size
// does not); the measure is the RMS of that over the boxes, over the plane's mean, divided by the
// same measure of the reference (512 x 512 box-filtered), whose value is its own curvature and
// noise. 'image' may be traced at a fraction of the G-buffer's resolution. Returns the larger
// ratio of the two planes.
double blotchRatio(const Readback& pos, const Readback& nrm, const Readback& image, const reference::Image& ref) {
  const int size = pos.w, scale = pos.w / image.w, f = ref.width / size, box = 16, boxes = size / box;
  std::vector<float> wallZ;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      if (pos.at(x, y)[3] != 0.0f && std::abs(nrm.at(x, y)[2]) > 0.9f) wallZ.push_back(pos.at(x, y)[2]);
  std::nth_element(wallZ.begin(), wallZ.begin() + wallZ.size() / 2, wallZ.end());
  const float backWall = wallZ.empty() ? 0.0f : wallZ[wallZ.size() / 2];
  auto onPlane = [&](int plane, int x, int y) {
    const float* p = pos.at(x, y);
    const float* n = nrm.at(x, y);
    if (p[3] == 0.0f) return false;
    return plane == 0 ? n[1] < -0.9f : (std::abs(n[2]) > 0.9f && std::abs(p[2] - backWall) < 0.01f);
  };
  double worst = 0.0;
  for (int plane = 0; plane < 2; ++plane) {
    // Box means of the image and the reference; -1 where the box is not wholly on the plane.
    std::vector<double> mine(size_t(boxes) * boxes, -1.0), theirs(size_t(boxes) * boxes, -1.0);
    for (int by = 0; by < boxes; ++by)
      for (int bx = 0; bx < boxes; ++bx) {
        double a = 0, b = 0;
        bool whole = true;
        for (int y = by * box; y < (by + 1) * box && whole; ++y)
          for (int x = bx * box; x < (bx + 1) * box; ++x) {
            if (!onPlane(plane, x, y)) { whole = false; break; }
            const float* v = image.at(x / scale, y / scale);
            a += v[0] + v[1] + v[2];
            for (int j = 0; j < f * f; ++j) {
              const float* r = ref.at(x * f + j % f, (size - 1 - y) * f + j / f);
              b += (r[0] + r[1] + r[2]) / double(f * f);
            }
          }
        if (whole) {
          mine[size_t(by) * boxes + bx] = a;
          theirs[size_t(by) * boxes + bx] = b;
        }
      }
    auto blotch = [&](const std::vector<double>& m) {
      double sq = 0, sum = 0;
      int count = 0;
      for (int by = 0; by < boxes; ++by)
        for (int bx = 0; bx < boxes; ++bx) {
          const double c = m[size_t(by) * boxes + bx];
          if (c < 0) continue;
          double around = 0;
          int k = 0;
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int x = bx + dx, y = by + dy;
              if ((dx == 0 && dy == 0) || x < 0 || y < 0 || x >= boxes || y >= boxes) continue;
              const double q = m[size_t(y) * boxes + x];
              if (q >= 0) { around += q; ++k; }
            }
          if (k < 3) continue;
          sq += (c - around / k) * (c - around / k);
          sum += c;
          ++count;
        }
      return count > 0 ? std::sqrt(sq / count) / (sum / count) : 0.0;
    };
    const double b = blotch(mine), r = blotch(theirs);
    if (r <= 0) continue;
    std::printf("  %s: blotch %.4f, reference %.4f, ratio %.2f\n", plane == 0 ? "ceiling" : "back wall", b, r, b / r);
    worst = std::max(worst, b / r);
  }
  return worst;
}

TEST(NearFieldNoise, FilteredIndirectHasNoBlotchesOnTheCeilingOrTheBackWall) {
  // Both techniques at their defaults, 256 x 256, as voxlab fidelity runs them.
  const std::vector<std::pair<std::string, std::string>> runs = {{"near-field", "indirect-1"},
                                                                  {"voxel-path-tracing", "indirect-2"}};
  for (const auto& [technique, mode] : runs) {
    RunRequest r = request({}, "filter", 256);
    r.technique = technique;
    auto& s = session(r);
    const reference::Image ref = reference::readExr(projectPath("tests/golden/reference/cornell-box/" + mode + ".exr"));
    std::printf("%s, indirect-filtered against %s:\n", technique.c_str(), mode.c_str());
    const double ratio =
        blotchRatio(readFloat(s, "position"), readFloat(s, "normal"), readFloat(s, "indirect-filtered"), ref);
    RecordProperty(technique + "_blotch_ratio", std::to_string(ratio));
    // Measured 0.91 for both (back wall; ceiling 0.61): as smooth as the reference at the boxes'
    // scale. The previous defaults (white per-pixel shifts, two fixed passes, radius half the edge)
    // measured 2.92 (near-field) and 1.91 (voxel-path-tracing) on the same planes, and the images
    // showed the blotches. The sampling and filter are deterministic (the same digits at
    // LP_NUM_THREADS 1 and 2); the bound leaves 40 % of room below the blotchy 1.91.
    constexpr double kBlotchBound = 1.3;
    EXPECT_LT(ratio, kBlotchBound) << technique;
  }
}

// --- Voxel path tracing ---------------------------------------------------------------------------

RunRequest vptRequest(int bounces, int paths) {
  RunRequest r = request({"voxel.resolution=128", "paths.count=" + std::to_string(paths),
                          "paths.bounces=" + std::to_string(bounces), "rays.resolution=full"},
                         "paths", 64);
  r.technique = "voxel-path-tracing";
  return r;
}

TEST(VoxelPathTracing, OneBounceEqualsNearFieldWithoutARadius) {
  // One bounce, bounce 0 uses near-field's directions (same Hammersley points and pixel shift) and
  // offsets; near-field's radius 2 volume edges exceeds the volume's diagonal, so both walk the
  // same rays to the volume's edge: the same hits, the same lookups, the same sum.
  Readback nf;
  {
    auto& s = session(request({"voxel.resolution=128", "rays.count=16", "rays.resolution=full", "rays.radius=2"},
                              "rays", 64));
    nf = readFloat(s, "indirect");
  }
  auto& s = session(vptRequest(1, 16));
  Readback vpt = readFloat(s, "indirect");
  ASSERT_EQ(nf.v.size(), vpt.v.size());
  double worst = 0, sum = 0, nfSum = 0;
  size_t differing = 0, values = 0;
  for (size_t i = 0; i < nf.v.size(); i += 4)
    for (int c = 0; c < 3; ++c) {
      double d = std::abs(nf.v[i + c] - vpt.v[i + c]);
      worst = std::max(worst, d);
      differing += d > 1e-5;
      ++values;
      sum += vpt.v[i + c];
      nfSum += nf.v[i + c];
    }
  std::printf("one bounce vs near-field: worst %.3g, %zu of %zu values differ by more than 1e-5, means %.6f %.6f\n",
              worst, differing, values, sum / values, nfSum / values);
  EXPECT_GT(sum, 1.0);
  // The segments end at different lengths (radius vs volume diagonal), so a hit's point can round
  // into a neighbouring RSM texel: measured worst 0 (6.2e-5 in a few values with other sampling
  // patterns), means equal to 1e-6.
  EXPECT_LT(worst, 1e-3);
  EXPECT_LE(differing, values / 200);
  EXPECT_NEAR(sum / nfSum, 1.0, 1e-4);
}

// Sum of the 64 x 64 indirect image over the pixels the G-buffer covers, over the same sum of
// 'ref' (512 x 512, box-filtered to 64 x 64): the estimate's share of the reference's energy.
double vptMeanRatio(HeadlessSession& s, const reference::Image& ref) {
  return surfaceMeanOverReference(readFloat(s, "position"), readFloat(s, "indirect"), ref, 64);
}

TEST(VoxelPathTracing, MoreBouncesApproachTheAllBounceReference) {
  // Mean over the image of the indirect light against the reference's "indirect" (all bounces,
  // 512 x 512 box-filtered to 64 x 64); near-field misses the bounces after the first.
  reference::Image ref = reference::readExr(projectPath("tests/golden/reference/cornell-box/indirect.exr"));
  std::vector<double> ratios;
  for (int bounces : {1, 3}) {
    ratios.push_back(vptMeanRatio(session(vptRequest(bounces, 16)), ref));
    std::printf("voxel path tracing, %d bounce(s): %.4f of the all-bounce reference\n", bounces, ratios.back());
  }
  RecordProperty("one_bounce_ratio", std::to_string(ratios[0]));
  RecordProperty("three_bounce_ratio", std::to_string(ratios[1]));
  // Measured 0.520 (one bounce: the reference's indirect is about twice its first bounce) and 0.852
  // (three bounces): later bounces add light, and the estimate stays below the reference (no
  // emission carried, RSM rejections, voxel albedo instead of the surface's).
  EXPECT_GT(ratios[1], ratios[0] + 0.15);
  EXPECT_LT(ratios[1], 1.0);
  EXPECT_GT(ratios[0], 0.35);
}

TEST(VoxelPathTracing, KBouncesMatchTheKBounceReference) {
  // K bounces against the reference of the mode the output declares under the run's parameters
  // (referenceModeUnder: indirect-K), the file voxlab run compares with. The same image against
  // the all-bounce "indirect" is printed too: it must fall outside the band, so a declaration
  // that went back to "indirect" (or stayed at one K) fails here.
  const reference::Image all = reference::readExr(projectPath("tests/golden/reference/cornell-box/indirect.exr"));
  for (int bounces : {1, 2, 4}) {
    auto& s = session(vptRequest(bounces, 16));
    auto [stage, desc] = s.cursor().technique().findOutput("paths", "indirect");
    (void)stage;
    const std::string mode = referenceModeUnder(*desc, s.cursor().params());
    ASSERT_EQ(mode, "indirect-" + std::to_string(bounces));
    const std::string path = referenceImagePath("cornell-box", mode);
    ASSERT_TRUE(fileExists(path)) << path << " is missing; scripts/make-references.sh makes it";
    const double same = vptMeanRatio(s, reference::readExr(path)), wrong = vptMeanRatio(s, all);
    std::printf("voxel path tracing, %d bounce(s): %.4f of %s, %.4f of indirect (all bounces)\n", bounces, same,
                mode.c_str(), wrong);
    RecordProperty("ratio_to_" + mode, std::to_string(same));
    // Measured 0.9706 (K = 1 against indirect-1), 0.9647 (K = 2, indirect-2) and 0.9647 (K = 4,
    // indirect-4) with the plane validity (0.957, 0.956, 0.963 with the paper's distance test), the same four digits at LP_NUM_THREADS 1 and 2 (the paths are deterministic):
    // the estimator's known loss (no emission carried along paths, RSM rejections, a voxel's
    // albedo). The band 0.93..1.03 is set by the wrong pairings it must exclude, the nearest being
    // the all-bounce indirect at K = 4 (0.906; 0.520 at K = 1, 0.744 at K = 2, printed), then a
    // mode fixed at another K: indirect-2 at K = 1 (0.665), at K = 4 (1.173), indirect-1 at K = 2
    // (1.375) (from the references' sums: indirect-1, indirect-2, indirect-4 = 0.536, 0.771, 0.939
    // of indirect). It leaves about 3 % of room for the estimator to change either way.
    EXPECT_GT(same, 0.93) << mode;
    EXPECT_LT(same, 1.03) << mode;
    EXPECT_LT(wrong, 0.93) << "the band must tell the K-bounce reference from the all-bounce one";
  }
}

}  // namespace
}  // namespace voxlab

#include "inspect/visualiser.h"

namespace voxlab {
namespace {

using namespace nearfield;
using testing_support::capture;
using testing_support::session;

// The probe records reach the generic probe with their own visualisers: the walk is checked by
// near-field-traversal (which must catch a broken walk, or the viewer's check could not fail), the
// grid, hierarchy and tables are shown by bitmask-columns, whose value under the cursor names the
// column's set slices exactly (32-bit masks through the integer readback, not float).
TEST(NearFieldVisualisers, TraversalCheckPassesOnTheWalkAndCatchesBrokenOnes) {
  // Ray 1 of the probed floor pixel runs 0.14 m to the wall: 33 DDA cells, 14 walk steps (ray 0
  // meets the floor's neighbour within 0.06 m, too short for the hierarchy to skip anything).
  auto& s = session(request({"voxel.resolution=64", "rays.count=4", "rsm.resolution=128", "shadow.resolution=256",
                             "probe.x=0.3", "probe.y=0.8", "probe.ray=1"}));
  const CapturedOutput steps = capture(s, "rays", "traversal-steps");
  ASSERT_TRUE(steps.desc.probeRecord);
  ASSERT_TRUE(capture(s, "rays", "probe-ray").desc.probeRecord);
  const Visualiser& vis = visualiserFor(steps.desc);
  EXPECT_STREQ(vis.name(), "near-field-traversal");
  const RecordCheck ok = vis.checkRecords(steps);
  EXPECT_TRUE(ok.error.empty()) << ok.error;
  ASSERT_GT(ok.elements, 2u);
  std::vector<gpu::TraversalStep> rec(steps.recordCount);
  std::memcpy(rec.data(), steps.records.data(), rec.size() * sizeof(gpu::TraversalStep));
  ASSERT_EQ(rec.back().slices.z, NF_END_HIT) << "the probed floor pixel's ray 1 hits";
  auto broken = [&](auto change) {
    CapturedOutput c = steps;
    std::vector<gpu::TraversalStep> r = rec;
    change(r);
    std::memcpy(c.records.data(), r.data(), r.size() * sizeof(gpu::TraversalStep));
    return vis.checkRecords(c).error;
  };
  EXPECT_NE(broken([](auto& r) { r[1].where.y += 2; }), "");                       // a level jump
  EXPECT_NE(broken([](auto& r) { r.back().where.y = 1; }), "");                    // a hit above level 0
  EXPECT_NE(broken([](auto& r) { r[0].rayMask.x ^= 0x1u; }), "");                  // a ray mask not first..last
  EXPECT_NE(broken([](auto& r) { r.back().hitMask = glm::uvec4(0u); }), "");       // a hit with an empty AND
  EXPECT_NE(broken([](auto& r) { std::swap(r[0].t.x, r[0].t.y); r[0].t.x += 1e-3f; }), "");  // t in > t out

  // Beside the walk: the brute-force DDA over the same grid, cell by cell, ending on the same voxel.
  const CapturedOutput dda = capture(s, "rays", "probe-dda");
  ASSERT_TRUE(dda.desc.probeRecord);
  const Visualiser& ddaVis = visualiserFor(dda.desc);
  EXPECT_STREQ(ddaVis.name(), "near-field-dda");
  const RecordCheck ddaOk = ddaVis.checkRecords(dda);
  EXPECT_TRUE(ddaOk.error.empty()) << ddaOk.error;
  EXPECT_NE(ddaOk.summary.find("first set cell = the walk's hit"), std::string::npos) << ddaOk.summary;
  ASSERT_GT(dda.recordCount, 2u);
  // More cells than the walk's steps: the hierarchy skipped the empty runs.
  EXPECT_GT(dda.recordCount, steps.recordCount);
  CapturedOutput skipped = dda;
  std::memcpy(skipped.records.data() + 32, skipped.records.data() + 64, 32);  // a cell skipped
  EXPECT_NE(ddaVis.checkRecords(skipped).error, "");
}

TEST(NearFieldVisualisers, BitmaskColumnsNameTheExactSlicesOfAColumn) {
  auto& s = session(snapshotRequest());
  const CapturedOutput h = capture(s, "hierarchy", "bitmask-hierarchy");
  EXPECT_STREQ(visualiserFor(h.desc).name(), "bitmask-columns");
  EXPECT_STREQ(visualiserFor(capture(s, "bitmask-tables", "ray-masks").desc).name(), "bitmask-columns");
  EXPECT_TRUE(texelMapping(h.desc.semantic).exact);
  // The CPU's view of level 0 and a column whose mask has bits beyond float's 24-bit mantissa.
  const std::vector<BitColumn> cpu = readLevel(s, "bitmask-hierarchy", 0);
  const LevelData& L = h.levels[0];
  ASSERT_EQ(L.integers.size(), L.values.size());
  int picked = -1;
  for (int i = 0; i < int(cpu.size()) && picked < 0; ++i)
    for (int c = 0; c < 4; ++c)
      if (double(float(cpu[i][c])) != double(cpu[i][c])) picked = i;  // (compared in double: float(w) may be 2^32)
  ASSERT_GE(picked, 0) << "no column with more than 24 significant bits in a word";
  std::string expect;
  for (int k = 0; k < kBinarySlices; ++k) {
    if (!hasSlice(cpu[picked], k)) continue;
    int e = k;
    while (e + 1 < kBinarySlices && hasSlice(cpu[picked], e + 1)) ++e;
    expect += (expect.empty() ? "" : ", ") + std::to_string(k) + (e > k ? "-" + std::to_string(e) : "");
    k = e;
  }
  const nlohmann::json none;
  ViewSettings view;
  VisualiserContext ctx{h, none, none, view, [](CapturedOutput&, std::string&) { return false; }};
  const int x = picked % L.size.x, y = picked / L.size.x;
  const std::string text = visualiserFor(h.desc).describeElement(ctx, glm::ivec3(x, y, 0));
  EXPECT_NE(text.find(std::to_string(popcount(cpu[picked])) + " of 128 slices set: " + expect), std::string::npos)
      << text << "\nexpected slices " << expect;
}

}  // namespace
}  // namespace voxlab
