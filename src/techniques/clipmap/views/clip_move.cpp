// The last camera move of a clipmap (clipmap/update/clip-counters: per level, what the move's
// shaders wrote, counted by atomics). With the records of the move the update stage made
// (clip-move, clip-move-boxes: from the origins it held, so a viewer camera move too) and the
// anchor stage's clip-levels (through VisualiserContext::contextOutput) it shows where the move
// worked and what it cost:
// 2D view: from above (x right, z down) as clip-levels: each level's box outlined, the boxes of
//          cells the move voxelized directly filled in their level's colour (newly exposed
//          slabs bright, cells that left the covered block darker).
// 3D view: the nested level boxes and the slab boxes, in level-0 voxels.
// Inspector: per level the move d, N^3 - prod(N - |d_i|) beside the planner's exposed cells and
//          the shaders' counts (cleared, voxelized = resolved, refiltered), then the records.
// Without those records it is the plain buffer view. Files and golden: the buffer's.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <imgui.h>

#include "inspect/view3d.h"
#include "inspect/visualisers/buffer.h"
#include "techniques/clipmap/views/clip_atlas.h"

namespace voxlab {
namespace {

using namespace clipmap;


glm::vec3 levelColour(int k) {  // as clip_levels.cpp
  static const glm::vec3 colours[8] = {{0.95f, 0.35f, 0.2f}, {0.95f, 0.75f, 0.2f}, {0.45f, 0.85f, 0.3f},
                                       {0.2f, 0.75f, 0.85f}, {0.35f, 0.45f, 0.95f}, {0.7f, 0.4f, 0.9f},
                                       {0.9f, 0.4f, 0.7f},   {0.6f, 0.6f, 0.6f}};
  return colours[k & 7];
}

// The last move, level by level.
struct Move {
  std::vector<LevelRecord> levels;
  std::vector<SlabRecord> slabs;
  std::vector<PlanRecord> plan;  // the last move's records, one per level (may be empty)
  std::vector<CounterRecord> counters;

  int64_t formula(size_t k) const {  // N^3 - prod(N - |d_i|)
    if (k >= plan.size() || k >= levels.size()) return -1;
    if (plan[k].delta[0] == 0 && plan[k].delta[1] == 0 && plan[k].delta[2] == 0 && plan[k].exposed > 0)
      return int64_t(plan[k].exposed);  // a full build: every cell
    const int64_t n = levels[k].n;
    int64_t kept = 1;
    for (int i = 0; i < 3; ++i) kept *= std::max<int64_t>(0, n - std::abs(int64_t(plan[k].delta[i])));
    return n * n * n - kept;
  }
};

bool moveOf(const VisualiserContext& ctx, Move& m) {
  m.counters = recordsAs<CounterRecord>(ctx.out);
  CapturedOutput levels, slabs, plan;
  if (!ctx.contextOutput || !ctx.contextOutput(kClipLevels.name(), levels)) return false;
  m.levels = levelRecords(levels);
  if (m.levels.empty()) return false;
  if (ctx.contextOutput("clip-move-boxes", slabs)) m.slabs = recordsAs<SlabRecord>(slabs);
  if (ctx.contextOutput("clip-move", plan)) m.plan = recordsAs<PlanRecord>(plan);
  return true;
}

constexpr int kSize = 512;

class ClipMoveVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "clip-move"; }

  SliceImage image2D(const VisualiserContext& ctx) const override {
    Move m;
    if (!moveOf(ctx, m)) return BufferVisualiser::image2D(ctx);
    SliceImage img;
    img.width = img.height = kSize;
    img.rgba.assign(size_t(kSize) * kSize * 4, 0);
    for (size_t i = 3; i < img.rgba.size(); i += 4) img.rgba[i] = 255;
    const LevelRecord& last = m.levels.back();
    const float x0 = last.lo.x, z0 = last.lo.z;
    const float scale = std::max(last.hi.x - last.lo.x, last.hi.z - last.lo.z) / float(kSize);
    auto px = [&](float x) { return int(std::floor((x - x0) / scale)); };
    auto py = [&](float z) { return int(std::floor((z - z0) / scale)); };
    auto put = [&](int x, int y, glm::vec3 c) {
      if (x < 0 || y < 0 || x >= kSize || y >= kSize) return;
      uint8_t* p = &img.rgba[(size_t(y) * kSize + size_t(x)) * 4];
      for (int i = 0; i < 3; ++i) p[i] = uint8_t(std::clamp(255.0f * c[i], 0.0f, 255.0f));
    };
    // Slabs first, coarse to fine (a finer level's slab drawn over a coarser one's), then outlines.
    std::vector<SlabRecord> slabs = m.slabs;
    std::stable_sort(slabs.begin(), slabs.end(), [](const SlabRecord& a, const SlabRecord& b) { return a.lo.w > b.lo.w; });
    for (const SlabRecord& s : slabs) {
      const glm::vec3 c = levelColour(int(s.lo.w)) * (s.cellLo[3] ? 0.55f : 1.0f);
      const int xa = px(s.lo.x), xb = std::max(px(s.hi.x), xa + 1), ya = py(s.lo.z), yb = std::max(py(s.hi.z), ya + 1);
      for (int y = ya; y < yb; ++y)
        for (int x = xa; x < xb; ++x) put(x, y, c);
    }
    for (size_t k = 0; k < m.levels.size(); ++k) {
      const LevelRecord& r = m.levels[k];
      const glm::vec3 c = levelColour(int(k));
      const int xa = px(r.lo.x), xb = px(r.hi.x), ya = py(r.lo.z), yb = py(r.hi.z);
      for (int x = xa; x <= xb; ++x) put(x, ya, c), put(x, yb - 1, c);
      for (int y = ya; y <= yb; ++y) put(xa, y, c), put(xb - 1, y, c);
    }
    return img;
  }

  bool elementAt(const VisualiserContext&, int, int, glm::ivec3&) const override { return false; }

  std::string caption(const VisualiserContext& ctx) const override {
    Move m;
    if (!moveOf(ctx, m)) return BufferVisualiser::caption(ctx);
    uint64_t formula = 0, cleared = 0, voxelized = 0, refiltered = 0, cells = 0;
    for (size_t k = 0; k < m.levels.size(); ++k) {
      formula += uint64_t(std::max<int64_t>(m.formula(k), 0));
      cells += uint64_t(m.levels[k].n) * m.levels[k].n * m.levels[k].n;
      if (k < m.counters.size())
        cleared += m.counters[k].cleared, voxelized += m.counters[k].resolved, refiltered += m.counters[k].refiltered;
    }
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "last move, from above (x right, z down): %zu boxes voxelized directly (bright: newly exposed, dark: "
                  "left the covered block); all levels: N^3 - prod(N - |d|) = %llu, cleared %llu, voxelized %llu, "
                  "refiltered %llu of %llu cells",
                  m.slabs.size(), (unsigned long long)formula, (unsigned long long)cleared,
                  (unsigned long long)voxelized, (unsigned long long)refiltered, (unsigned long long)cells);
    return buf;
  }

  bool has3D(const OutputDesc&) const override { return true; }

  Content3D build3D(const VisualiserContext& ctx, View3D& view) const override {
    Content3D c;
    Move m;
    if (!moveOf(ctx, m)) {
      c.message = "no clip-levels records (run the anchor stage)";
      return c;
    }
    const float unit = m.levels[0].hi.w;  // level-0 voxels
    std::vector<ViewInstance> lines;
    for (size_t k = 0; k < m.levels.size(); ++k)
      appendBoxEdges(lines, glm::vec3(m.levels[k].lo) / unit, glm::vec3(m.levels[k].hi) / unit,
                     glm::vec4(levelColour(int(k)) * 0.6f, 1.0f));
    for (const SlabRecord& s : m.slabs)
      appendBoxEdges(lines, glm::vec3(s.lo) / unit, glm::vec3(s.hi) / unit,
                     glm::vec4(glm::mix(levelColour(int(s.lo.w)), glm::vec3(1.0f), s.cellLo[3] ? 0.0f : 0.5f), 1.0f));
    view.setLines(std::move(lines));
    c.lo = glm::vec3(m.levels.back().lo) / unit;
    c.hi = glm::vec3(m.levels.back().hi) / unit;
    c.info = std::to_string(m.slabs.size()) + " boxes of the last move (light: newly exposed) in " +
             std::to_string(m.levels.size()) + " level boxes, in level-0 voxels";
    return c;
  }

  void drawInspector(const VisualiserContext& ctx) const override {
    Move m;
    if (moveOf(ctx, m) && ImGui::BeginTable("clip-move", 8, ImGuiTableFlags_Borders | ImGuiTableFlags_SizingFixedFit)) {
      for (const char* h : {"level", "d (cells)", "N^3-prod(N-|d|)", "exposed", "cleared", "voxelized", "refiltered", "pairs"})
        ImGui::TableSetupColumn(h);
      ImGui::TableHeadersRow();
      for (size_t k = 0; k < m.levels.size(); ++k) {
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        ImGui::Text("%zu", k);
        ImGui::TableNextColumn();
        if (k < m.plan.size()) ImGui::Text("(%d, %d, %d)", m.plan[k].delta[0], m.plan[k].delta[1], m.plan[k].delta[2]);
        ImGui::TableNextColumn();
        ImGui::Text("%lld", (long long)m.formula(k));
        ImGui::TableNextColumn();
        if (k < m.plan.size()) ImGui::Text("%u", m.plan[k].exposed);
        const CounterRecord c = k < m.counters.size() ? m.counters[k] : CounterRecord{};
        for (uint32_t v : {c.cleared, c.resolved, c.refiltered, c.pairs}) {
          ImGui::TableNextColumn();
          ImGui::Text("%u", v);
        }
      }
      ImGui::EndTable();
      ImGui::TextWrapped("A full build (d = 0 with nothing held) voxelizes every uncovered cell; a move only the slabs "
                         "it exposed and the cells that left the covered block, and refilters the covered blocks.");
      ImGui::Separator();
    }
    BufferVisualiser::drawInspector(ctx);
  }
};

}  // namespace

VOXLAB_REGISTER_VISUALISER(ClipMoveVisualiser, OutputKind::Buffer, clipmap::kClipCounters.name());

}  // namespace voxlab
