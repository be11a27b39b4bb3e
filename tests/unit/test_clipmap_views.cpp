// The clip-atlas view (src/techniques/clipmap/views/clip_atlas.cpp): its unrolled slices equal the
// GPU's unrolled levels (clip-logical, written through the GLSL toroidal address) and its
// physical slices the atlas as stored; between two runs a move apart, a physical slice changes
// only at texels whose world cells (by the C++ inverse address) the move planned; the view finds
// the level records through the viewer's context and names the logical origin.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <string>

#include <algorithm>
#include <cmath>

#include "common/shared.h"
#include "inspect/visualiser.h"
#include "techniques/clipmap/views/clip_atlas.h"
#include "techniques/clipmap/clipmap_math.h"
#include "techniques/clipmap/stages.h"
#include "test_support.h"

namespace voxlab {
namespace {

using namespace clipmap;
using testing_support::capture;
using testing_support::session;

constexpr int kN = 16, kLevels = 4;
const glm::vec3 kInside(69.0f / 256.0f, 77.0f / 256.0f, 57.0f / 256.0f);  // inside the Cornell box

RunRequest request(int moves) {
  RunRequest r;
  r.technique = "clipmap";
  r.scene = "cornell-box";
  r.until = "mips";
  r.width = r.height = 32;
  r.lookFrom = kInside;
  r.lookAt = kInside + glm::vec3(0.0f, 0.0f, 1.0f);
  // 1/64 m cells; a move of (3, -2, 5) level-0 cells moves every level's origin (levels 0-1 by
  // whole snaps) and puts the seams inside the regions.
  r.sets = {"clipmap.fill-unreached=off", "clipmap.resolution=16", "clipmap.levels=4", "clipmap.voxel-size=0.015625", "clipmap.path-step.x=0.046875",
            "clipmap.path-step.y=-0.03125", "clipmap.path-step.z=0.078125",
            "clipmap.path-moves=" + std::to_string(moves), "clipmap.look-ahead=0"};  // centred, as the checks model
  return r;
}

struct ClipRun {
  CapturedOutput atlas, levels, logical;
  std::vector<LevelRecord> records;
};

ClipRun run(int moves) {
  auto& s = session(request(moves));
  ClipRun r{capture(s, "update", "clip-atlas"), capture(s, "anchor", "clip-levels"), capture(s, "mips", "clip-logical"), {}};
  r.records = levelRecords(r.levels);
  EXPECT_EQ(r.records.size(), size_t(kLevels));
  return r;
}

TEST(ClipmapViews, UnrolledSlicesEqualTheGpuUnrollAndPhysicalSlicesTheAtlas) {
  const ClipRun r = run(1);
  const LevelData& atlas = r.atlas.levels[0];
  const LevelData& logical = r.logical.levels[0];
  size_t seamsInside = 0, nonEmpty = 0;
  for (int k = 0; k < kLevels; ++k) {
    const LevelRecord& rec = r.records[size_t(k)];
    seamsInside += rec.offset[0] != 0 || rec.offset[1] != 0 || rec.offset[2] != 0;
    for (int z = 0; z < kN; ++z) {
      const LevelData unrolled = atlasSliceValues(atlas, rec, AtlasSlice{k, 0, z, true});
      const LevelData physical = atlasSliceValues(atlas, rec, AtlasSlice{k, 0, z, false});
      for (int y = 0; y < kN; ++y)
        for (int x = 0; x < kN; ++x) {
          // The cell shown must be the one the C++ inverse address gives for the texel read.
          const glm::ivec3 t = atlasSliceTexel(rec, AtlasSlice{k, 0, z, true}, x, y);
          ASSERT_EQ(cellAtTexel(t, Cell(rec.origin[0], rec.origin[1], rec.origin[2]), kN),
                    atlasSliceCell(rec, AtlasSlice{k, 0, z, true}, x, y));
          for (int c = 0; c < 4; ++c) {
            ASSERT_EQ(unrolled.at(x, y, 0, c), logical.at(x, k * kN + y, z, c))
                << "level " << k << " logical (" << x << ", " << y << ", " << z << ")";
            ASSERT_EQ(physical.at(x, y, 0, c), atlas.at(1 + x, k * (kN + 2) + 1 + y, 1 + z, c));
          }
          nonEmpty += unrolled.at(x, y, 0, 3) > 0.0f;
        }
    }
  }
  EXPECT_GT(seamsInside, 0u) << "the test needs a level whose seam lies inside its region";
  EXPECT_GT(nonEmpty, 500u);
}

// After a move the physical image is unchanged except at the texels of the cells the move
// rebuilt: its exposed slabs, the cells that left the covered block and the refiltered covered
// block (the planner's direct boxes and covered block).
TEST(ClipmapViews, AMoveChangesThePhysicalSlicesOnlyAtItsCells) {
  const ClipRun before = run(0), after = run(1);
  const Layout layout{kLevels, kN, 0.015625};
  std::vector<Cell> o0, o1;
  for (int k = 0; k < kLevels; ++k) {
    o0.push_back(Cell(before.records[size_t(k)].origin[0], before.records[size_t(k)].origin[1], before.records[size_t(k)].origin[2]));
    o1.push_back(Cell(after.records[size_t(k)].origin[0], after.records[size_t(k)].origin[1], after.records[size_t(k)].origin[2]));
  }
  const auto plans = planMove(layout, o0, o1);
  size_t changed = 0, planned = 0;
  for (int k = 0; k < kLevels; ++k) {
    const LevelPlan& p = plans[size_t(k)];
    EXPECT_NE(p.delta, Cell(0)) << "level " << k << " must move for the test to mean anything";
    size_t changedHere = 0;
    for (int z = 0; z < kN; ++z) {
      const AtlasSlice s{k, 0, z, false};
      const LevelData a = atlasSliceValues(before.atlas.levels[0], before.records[size_t(k)], s);
      const LevelData b = atlasSliceValues(after.atlas.levels[0], after.records[size_t(k)], s);
      for (int y = 0; y < kN; ++y)
        for (int x = 0; x < kN; ++x) {
          const Cell c = atlasSliceCell(after.records[size_t(k)], s, x, y);
          bool inPlan = p.covered.contains(c);
          for (const Box& box : p.direct) inPlan = inPlan || box.contains(c);
          planned += inPlan;
          bool differs = false;
          for (int ch = 0; ch < 4; ++ch) differs = differs || a.at(x, y, 0, ch) != b.at(x, y, 0, ch);
          if (!differs) continue;
          ++changedHere;
          EXPECT_TRUE(inPlan) << "level " << k << " physical texel (" << x << ", " << y << ", " << z
                              << ") changed, but its cell " << describe(c) << " is not in the move's plan";
        }
    }
    EXPECT_LT(changedHere, size_t(kN) * kN * kN / 2) << "level " << k;
    changed += changedHere;
  }
  EXPECT_GT(changed, 100u);
  EXPECT_LT(planned, size_t(kLevels) * kN * kN * kN);
}

// The view reads the level records through the context (the viewer's contextOutput) and says
// where the logical origin is; without them it is the plain volume view.
TEST(ClipmapViews, TheAtlasViewFindsTheLevelRecords) {
  const ClipRun r = run(1);
  const Visualiser& v = visualiserFor(r.atlas.desc);
  EXPECT_STREQ(v.name(), "clip-atlas");
  nlohmann::json none;
  ViewSettings view;
  VisualiserContext plain{r.atlas, none, none, view, nullptr, nullptr};
  VisualiserContext withLevels{r.atlas, none, none, view, nullptr, [&](const char* semantic, CapturedOutput& out) {
                                 if (std::strcmp(semantic, kClipLevels.name()) != 0) return false;
                                 out = r.levels;
                                 return true;
                               }};
  const SliceImage image = v.image2D(withLevels);
  EXPECT_EQ(image.width, 512);  // N texels of 32 pixels
  const LevelRecord& rec = r.records[0];
  char origin[96];
  std::snprintf(origin, sizeof origin, "logical origin o = (%d, %d, %d) at texel T = (%d, %d, %d)", rec.origin[0],
                rec.origin[1], rec.origin[2], rec.offset[0], rec.offset[1], rec.offset[2]);
  EXPECT_NE(v.caption(withLevels).find(origin), std::string::npos) << v.caption(withLevels);
  // The logical origin's dot: white at the lower left corner of texel T in slice T.z... of any
  // slice (the dot marks the column and row).
  const int px = rec.offset[0] * 32, py = (kN - rec.offset[1]) * 32 - 1;
  EXPECT_EQ(image.rgba[(size_t(py) * image.width + px) * 4], 255);
  glm::ivec3 e;
  ASSERT_TRUE(v.elementAt(withLevels, px, py, e));
  EXPECT_EQ(glm::ivec2(e), glm::ivec2(rec.offset[0], rec.offset[1]));
  EXPECT_NE(v.describeElement(withLevels, e).find("world cell (" + std::to_string(rec.origin[0]) + ", " +
                                                  std::to_string(rec.origin[1])),
            std::string::npos)
      << v.describeElement(withLevels, e);
  EXPECT_NE(v.image2D(plain).width, 512) << "without records: the volume's slice view";
}


// The clip-levels top view marks the anchor (a white cross over the level-1 cell it snaps to) and,
// given the anchor stage's clip-slabs through the context, draws each box of the last move.
TEST(ClipmapViews, TheLevelsViewMarksTheAnchorAndTheLastMovesSlabs) {
  auto& s = session(request(1));
  const CapturedOutput levels = capture(s, "anchor", "clip-levels");
  const CapturedOutput slabs = capture(s, "anchor", "clip-slabs");
  const Visualiser& v = visualiserFor(levels.desc);
  EXPECT_STREQ(v.name(), "clip-levels");
  nlohmann::json none;
  ViewSettings view;
  VisualiserContext plain{levels, none, none, view, nullptr, nullptr};
  VisualiserContext withSlabs{levels, none, none, view, nullptr, [&](const char* what, CapturedOutput& out) {
                                if (std::strcmp(what, "clip-slabs") != 0) return false;
                                out = slabs;
                                return true;
                              }};
  const SliceImage a = v.image2D(plain), b = v.image2D(withSlabs);
  ASSERT_EQ(a.width, 512);
  ASSERT_EQ(b.rgba.size(), a.rgba.size());
  const auto records = levelRecords(levels);
  const LevelRecord& last = records.back();
  const float scale = std::max(last.hi.x - last.lo.x, last.hi.z - last.lo.z) / 512.0f;
  auto pixel = [&](const SliceImage& img, float x, float z) {
    const int px = int(std::floor((x - last.lo.x) / scale)), py = int(std::floor((z - last.lo.z) / scale));
    return &img.rgba[(size_t(py) * 512 + size_t(px)) * 4];
  };
  // The anchor (kInside + the move) lies in the marked level-1 cell; the cross's centre is white.
  const float s0 = records[0].hi.w;
  const glm::vec2 cell((float(records[0].origin[0]) + kN / 2 + 1.0f) * s0, (float(records[0].origin[2]) + kN / 2 + 1.0f) * s0);
  const glm::vec3 anchor = kInside + glm::vec3(0.046875f, -0.03125f, 0.078125f);
  EXPECT_LT(std::abs(anchor.x - cell.x), s0 + 1e-6f);
  EXPECT_LT(std::abs(anchor.z - cell.y), s0 + 1e-6f);
  const uint8_t* centre = pixel(a, cell.x, cell.y);
  EXPECT_EQ(centre[0], 255);
  EXPECT_EQ(centre[1], 255);
  EXPECT_EQ(centre[2], 255);
  // Every slab's interior changes colour when the slabs are given (and only then).
  const SlabRecord* rec = reinterpret_cast<const SlabRecord*>(slabs.records.data());
  ASSERT_GT(slabs.recordCount, 0u);
  size_t changed = 0;
  for (size_t i = 0; i < slabs.recordCount; ++i) {
    const glm::vec2 mid((rec[i].lo.x + rec[i].hi.x) / 2.0f, (rec[i].lo.z + rec[i].hi.z) / 2.0f);
    changed += std::memcmp(pixel(a, mid.x, mid.y), pixel(b, mid.x, mid.y), 3) != 0;
  }
  EXPECT_GT(changed, slabs.recordCount / 2) << "slab interiors drawn";
  EXPECT_NE(v.caption(plain).find("cross: the anchor"), std::string::npos);

  // The atlas view outlines, in yellow, the texels of level 0's slice z = N/2 whose cells the
  // move voxelized (its x slab crosses every slice): yellow only with the move's boxes given.
  const CapturedOutput atlas = capture(s, "update", "clip-atlas");
  const CapturedOutput boxes = capture(s, "update", "clip-move-boxes");
  const Visualiser& av = visualiserFor(atlas.desc);
  auto context = [&](bool withBoxes) {
    return [&, withBoxes](const char* what, CapturedOutput& out) {
      if (std::strcmp(what, kClipLevels.name()) == 0) {
        out = levels;
        return true;
      }
      if (!withBoxes || std::strcmp(what, "clip-move-boxes") != 0) return false;
      out = boxes;
      return true;
    };
  };
  VisualiserContext levelsOnly{atlas, none, none, view, nullptr, context(false)};
  VisualiserContext levelsAndBoxes{atlas, none, none, view, nullptr, context(true)};
  auto yellow = [](const SliceImage& img) {
    size_t count = 0;
    for (size_t i = 0; i + 3 < img.rgba.size(); i += 4)
      count += img.rgba[i] == 255 && img.rgba[i + 1] == 220 && img.rgba[i + 2] == 0;
    return count;
  };
  EXPECT_EQ(yellow(av.image2D(levelsOnly)), 0u);
  EXPECT_GT(yellow(av.image2D(levelsAndBoxes)), 32u) << "the x slab's outline in the physical slice";
}

// The level a cone sample reads (info.z of its record) is max(lod, minimum level) with the minimum
// level k_min(p), the finest level whose footprint region holds p, raised linearly to k_min + 1
// within clipmap.transition-band cells of that region's border: recomputed here from the records'
// positions and diameters and the clip-levels records. The band only ever raises the level, and
// changes samples near a border (narrow cones, whose width asks for level 0, cross level borders).
std::vector<gpu::ConeSample> coneSamples(const std::string& band, std::vector<LevelRecord>& levels) {
  RunRequest r = request(0);
  r.until = "cone-trace";
  r.sets.push_back("cone.resolution=full");
  r.sets.push_back("clipmap.transition-band=" + band);
  // Narrow cones, so that their level is set by the region they are in, not by their width.
  r.sets.push_back("cone.aperture=10");
  r.sets.push_back("specular.roughness=0");
  auto& s = session(r);
  levels = levelRecords(capture(s, "anchor", "clip-levels"));
  const CapturedOutput c = capture(s, "cone-trace", "cone-samples");
  std::vector<gpu::ConeSample> v(std::min<size_t>(c.recordCount, c.records.size() / sizeof(gpu::ConeSample)));
  if (!v.empty()) std::memcpy(v.data(), c.records.data(), v.size() * sizeof(gpu::ConeSample));
  return v;
}

double expectedLevel(const gpu::ConeSample& sample, const std::vector<LevelRecord>& levels, double band, bool& nearTie) {
  const int n = levels[0].n, last = int(levels.size()) - 1;
  const double s0 = levels[0].hi.w;
  double minimum = -1.0;
  nearTie = false;
  for (int k = 0; k <= last && minimum < 0.0; ++k) {
    const glm::dvec3 u = (glm::dvec3(glm::vec3(sample.position)) - glm::dvec3(glm::vec3(levels[size_t(k)].lo))) /
                         double(levels[size_t(k)].hi.w);
    const glm::dvec3 inside = glm::min(u - 0.5, double(n) - 0.5 - u);
    const double margin = std::min({inside.x, inside.y, inside.z});
    nearTie = nearTie || std::abs(margin) < 1e-3 || (band > 0.0 && std::abs(margin - band) < 1e-3);
    if (margin < 0.0) continue;
    minimum = k == last || band <= 0.0 ? double(k) : double(k) + std::clamp(1.0 - margin / band, 0.0, 1.0);
  }
  const double lod = std::max(std::log2(double(sample.position.w) / s0) - 1.0, 0.0);  // cone.lod-bias -1
  return std::min(std::max(lod, minimum), double(last + 2));                           // 16^3: 2 mips
}

TEST(ClipmapCones, TransitionBandRampsTheLevelAcrossBorders) {
  std::vector<LevelRecord> levels;
  const auto plain = coneSamples("0", levels);
  const auto banded = coneSamples("4", levels);
  ASSERT_GT(plain.size(), 20u);
  size_t checked = 0, raised = 0;
  double worst = 0.0;
  for (const auto* set : {&plain, &banded}) {
    const double band = set == &plain ? 0.0 : 4.0;
    for (const auto& sample : *set) {
      bool tie = false;
      const double want = expectedLevel(sample, levels, band, tie);
      if (tie) continue;
      ++checked;
      worst = std::max(worst, std::abs(double(sample.info.z) - want));
      EXPECT_NEAR(sample.info.z, want, 1e-3) << "band " << band << " sample at t = " << sample.info.y;
    }
  }
  // Same cones, same sample positions (t depends only on the diameters): compare level by level.
  for (size_t i = 0; i < std::min(plain.size(), banded.size()); ++i) {
    if (plain[i].info.x != banded[i].info.x || plain[i].info.y != banded[i].info.y) break;
    EXPECT_GE(banded[i].info.z, plain[i].info.z - 1e-5f);
    raised += banded[i].info.z > plain[i].info.z + 0.01f;
  }
  // The largest change of level between two samples of one cone: the band spreads the border's
  // step of a whole level over the samples within 4 cells of it.
  auto largestStep = [](const std::vector<gpu::ConeSample>& v) {
    float step = 0.0f;
    for (size_t i = 1; i < v.size(); ++i)
      if (v[i].info.x == v[i - 1].info.x) step = std::max(step, std::abs(v[i].info.z - v[i - 1].info.z));
    return step;
  };
  std::printf("transition band: %zu samples checked (worst %.2g), %zu raised by the band of 4 cells; largest level "
              "step along a cone %.3f without, %.3f with\n",
              checked, worst, raised, double(largestStep(plain)), double(largestStep(banded)));
  EXPECT_LT(largestStep(banded), largestStep(plain));
  EXPECT_GT(checked, 40u);
  EXPECT_GT(raised, 0u) << "the probed cones must cross a level border for the test to mean anything";
}

}  // namespace
}  // namespace voxlab
