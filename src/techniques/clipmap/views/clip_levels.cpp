// The clip levels of a clipmap (clipmap/anchor/clip-levels: one record per level).
//
// 2D view: the levels seen from above (+y down onto x, z), each box filled in its colour, finest
//          on top, with its physical seam (where texel N-1 meets texel 0: world cell
//          o + ((-o) mod N)) dashed and its logical origin (min corner) as a dot. Hovering reads
//          out the finest level there, the world cell under the cursor at that level and the
//          physical texel it lives at (cell & (N-1)). Over them: the anchor (the camera at the
//          end of the path) as a white cross in the level-1 cell it snaps to (cells
//          [o_0 + N/2, o_0 + N/2 + 2) of level 0: exact from the records), and the boxes of cells
//          the last move voxelized (the anchor stage's clip-slabs, when the viewer has them),
//          outlined in white over their level's colour.
// 3D view: the nested level boxes in level-0 voxels, with each level's seam planes' edges.
// Records are exact integers plus their world boxes: the golden is exact.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <imgui.h>

#include "capture/image_files.h"
#include "inspect/view3d.h"
#include "inspect/visualisers/buffer.h"
#include "techniques/clipmap/stages.h"

namespace voxlab {
namespace {

using clipmap::LevelRecord;
using clipmap::SlabRecord;

std::vector<SlabRecord> decodeSlabs(const CapturedOutput& out) { return recordsAs<SlabRecord>(out); }

std::vector<LevelRecord> decodeLevels(const CapturedOutput& out) { return recordsAs<LevelRecord>(out); }

glm::vec3 levelColour(int k) {
  static const glm::vec3 colours[8] = {{0.95f, 0.35f, 0.2f}, {0.95f, 0.75f, 0.2f}, {0.45f, 0.85f, 0.3f},
                                       {0.2f, 0.75f, 0.85f}, {0.35f, 0.45f, 0.95f}, {0.7f, 0.4f, 0.9f},
                                       {0.9f, 0.4f, 0.7f},   {0.6f, 0.6f, 0.6f}};
  return colours[k & 7];
}

int64_t modPos(int64_t a, int64_t b) { return ((a % b) + b) % b; }

constexpr int kSize = 512;

// World (x, z) of image pixel (px, py): the coarsest level's box fills the image, x to the right,
// z downwards.
struct TopView {
  float x0 = 0, z0 = 0, scale = 1;
  glm::vec2 world(int px, int py) const { return {x0 + (float(px) + 0.5f) * scale, z0 + (float(py) + 0.5f) * scale}; }
  int px(float x) const { return int(std::floor((x - x0) / scale)); }
  int py(float z) const { return int(std::floor((z - z0) / scale)); }
};

TopView topView(const std::vector<LevelRecord>& levels) {
  TopView v;
  const LevelRecord& last = levels.back();
  const float edge = std::max(last.hi.x - last.lo.x, last.hi.z - last.lo.z);
  v.x0 = last.lo.x;
  v.z0 = last.lo.z;
  v.scale = edge / float(kSize);
  return v;
}

class ClipLevelsVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "clip-levels"; }
  CaptureTier defaultTier(const OutputDesc&) const override { return CaptureTier::Exact; }

  // The records as usual, plus the top view as PNG (what the 2D view shows).
  nlohmann::json writeFiles(const CapturedOutput& out, const std::string& dir, const std::string& prefix) const override {
    nlohmann::json entry = BufferVisualiser::writeFiles(out, dir, prefix);
    SliceImage img = topImage(out);
    if (img.width > 0) {
      writePngFile(dir + "/" + prefix + ".levels.png", img.width, img.height, 4, img.rgba.data());
      entry["files"].push_back(prefix + ".levels.png");
    }
    return entry;
  }

  SliceImage image2D(const VisualiserContext& ctx) const override {
    CapturedOutput slabs;
    if (ctx.contextOutput && ctx.contextOutput("clip-slabs", slabs)) return topImage(ctx.out, decodeSlabs(slabs));
    return topImage(ctx.out);
  }

  static SliceImage topImage(const CapturedOutput& out, const std::vector<SlabRecord>& slabs = {}) {
    SliceImage img;
    auto levels = decodeLevels(out);
    if (levels.empty()) return img;
    img.width = img.height = kSize;
    img.rgba.assign(size_t(kSize) * kSize * 4, 0);
    img.pick.assign(size_t(kSize) * kSize, -1);
    const TopView v = topView(levels);
    auto put = [&](int x, int y, glm::vec3 c, float a) {
      if (x < 0 || y < 0 || x >= kSize || y >= kSize) return;
      uint8_t* p = &img.rgba[(size_t(y) * kSize + size_t(x)) * 4];
      for (int i = 0; i < 3; ++i) p[i] = uint8_t(std::clamp(p[i] * (1.0f - a) + 255.0f * c[i] * a, 0.0f, 255.0f));
      p[3] = 255;
    };
    for (int k = int(levels.size()) - 1; k >= 0; --k) {
      const LevelRecord& r = levels[size_t(k)];
      const glm::vec3 c = levelColour(k);
      const int x0 = v.px(r.lo.x), x1 = v.px(r.hi.x), y0 = v.py(r.lo.z), y1 = v.py(r.hi.z);
      for (int y = std::max(y0, 0); y < std::min(y1, kSize); ++y)
        for (int x = std::max(x0, 0); x < std::min(x1, kSize); ++x) {
          put(x, y, c * 0.35f, 1.0f);
          img.pick[size_t(y) * kSize + size_t(x)] = k;
        }
      for (int x = x0; x <= x1; ++x) put(x, y0, c, 1.0f), put(x, y1 - 1, c, 1.0f);
      for (int y = y0; y <= y1; ++y) put(x0, y, c, 1.0f), put(x1 - 1, y, c, 1.0f);
      // The physical seam: the world cell stored at texel 0, o + ((-o) mod N), per axis.
      const float s = r.hi.w;
      const float seamX = (float(r.origin[0]) + float(modPos(-int64_t(r.origin[0]), r.n))) * s;
      const float seamZ = (float(r.origin[2]) + float(modPos(-int64_t(r.origin[2]), r.n))) * s;
      for (int y = y0; y < y1; ++y)
        if ((y / 4) % 2 == 0) put(v.px(seamX), y, c, 0.9f);
      for (int x = x0; x < x1; ++x)
        if ((x / 4) % 2 == 0) put(x, v.py(seamZ), c, 0.9f);
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) put(x0 + dx, y0 + dy, glm::vec3(1.0f), 1.0f);
    }
    // The last move's slabs: their level's colour, outlined in white.
    for (const SlabRecord& b : slabs) {
      const glm::vec3 c = levelColour(int(b.lo.w));
      const int x0 = v.px(b.lo.x), x1 = std::max(v.px(b.hi.x), x0 + 1), y0 = v.py(b.lo.z), y1 = std::max(v.py(b.hi.z), y0 + 1);
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) put(x, y, c, 0.6f);
      for (int x = x0; x < x1; ++x) put(x, y0, glm::vec3(1.0f), 1.0f), put(x, y1 - 1, glm::vec3(1.0f), 1.0f);
      for (int y = y0; y < y1; ++y) put(x0, y, glm::vec3(1.0f), 1.0f), put(x1 - 1, y, glm::vec3(1.0f), 1.0f);
    }
    // The anchor: a white cross over the level-1 cell it snaps to, [o_0 + N/2, o_0 + N/2 + 2) s_0.
    const LevelRecord& l0 = levels[0];
    const float s0 = l0.hi.w;
    const glm::vec2 lo((float(l0.origin[0]) + float(l0.n / 2)) * s0, (float(l0.origin[2]) + float(l0.n / 2)) * s0);
    const int ax0 = v.px(lo.x), ax1 = std::max(v.px(lo.x + 2.0f * s0), ax0 + 1);
    const int ay0 = v.py(lo.y), ay1 = std::max(v.py(lo.y + 2.0f * s0), ay0 + 1);
    const int cx = (ax0 + ax1) / 2, cy = (ay0 + ay1) / 2;
    for (int d = -8; d <= 8; ++d) put(cx + d, cy, glm::vec3(1.0f), 1.0f), put(cx, cy + d, glm::vec3(1.0f), 1.0f);
    for (int x = ax0; x < ax1; ++x) put(x, ay0, glm::vec3(1.0f), 1.0f), put(x, ay1 - 1, glm::vec3(1.0f), 1.0f);
    for (int y = ay0; y < ay1; ++y) put(ax0, y, glm::vec3(1.0f), 1.0f), put(ax1 - 1, y, glm::vec3(1.0f), 1.0f);
    return img;
  }

  bool elementAt(const VisualiserContext& ctx, int px, int py, glm::ivec3& element) const override {
    auto levels = decodeLevels(ctx.out);
    if (levels.empty() || px < 0 || py < 0 || px >= kSize || py >= kSize) return false;
    const TopView v = topView(levels);
    const glm::vec2 w = v.world(px, py);
    for (size_t k = 0; k < levels.size(); ++k) {
      const LevelRecord& r = levels[k];
      if (w.x >= r.lo.x && w.x < r.hi.x && w.y >= r.lo.z && w.y < r.hi.z) {
        element = {int(k), px, py};
        return true;
      }
    }
    return false;
  }

  std::string describeElement(const VisualiserContext& ctx, const glm::ivec3& e) const override {
    auto levels = decodeLevels(ctx.out);
    if (e.x < 0 || e.x >= int(levels.size())) return "";
    const LevelRecord& r = levels[size_t(e.x)];
    const glm::vec2 w = topView(levels).world(e.y, e.z);
    const int64_t cx = int64_t(std::floor(w.x / r.hi.w)), cz = int64_t(std::floor(w.y / r.hi.w));
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "level %d (voxel %.4g m, origin (%d, %d, %d), T = (%d, %d, %d), lag %d): world x %.3f z %.3f -> "
                  "cell x %lld z %lld -> physical texel x %lld z %lld",
                  e.x, double(r.hi.w), r.origin[0], r.origin[1], r.origin[2], r.offset[0], r.offset[1], r.offset[2],
                  r.lag, double(w.x), double(w.y), (long long)cx, (long long)cz, (long long)modPos(cx, r.n),
                  (long long)modPos(cz, r.n));
    return buf;
  }

  std::string caption(const VisualiserContext& ctx) const override {
    return std::to_string(ctx.out.recordCount) + " clip levels from above (x right, z down); dashed: physical seam, "
           "dot: logical origin; cross: the anchor (the camera), in the level-1 cell it snaps to; white boxes: the "
           "cells the last move voxelized (clip-slabs)";
  }

  bool has3D(const OutputDesc&) const override { return true; }

  Content3D build3D(const VisualiserContext& ctx, View3D& view) const override {
    Content3D c;
    auto levels = decodeLevels(ctx.out);
    if (levels.empty()) {
      c.message = "no levels";
      return c;
    }
    const float unit = levels[0].hi.w;  // level-0 voxels
    std::vector<ViewInstance> lines;
    for (size_t k = 0; k < levels.size(); ++k)
      appendBoxEdges(lines, glm::vec3(levels[k].lo) / unit, glm::vec3(levels[k].hi) / unit,
                     glm::vec4(levelColour(int(k)), 1.0f));
    view.setLines(std::move(lines));
    c.lo = glm::vec3(levels.back().lo) / unit;
    c.hi = glm::vec3(levels.back().hi) / unit;
    c.info = std::to_string(levels.size()) + " nested clip levels, in level-0 voxels";
    return c;
  }

  void drawInspector(const VisualiserContext& ctx) const override {
    auto levels = decodeLevels(ctx.out);
    ImGui::Text("%zu clip levels", levels.size());
    for (size_t k = 0; k < levels.size(); ++k) {
      const LevelRecord& r = levels[k];
      ImGui::Text("level %zu: s = %.4g m, origin (%d, %d, %d), T = (%d, %d, %d), lag %d", k, double(r.hi.w), r.origin[0],
                  r.origin[1], r.origin[2], r.offset[0], r.offset[1], r.offset[2], r.lag);
    }
    CapturedOutput slabOut;
    if (ctx.contextOutput && ctx.contextOutput("clip-slabs", slabOut)) {
      const auto slabs = decodeSlabs(slabOut);
      ImGui::Text("last move: %zu boxes voxelized", slabs.size());
      for (const SlabRecord& b : slabs)
        ImGui::Text("level %d: cells [%d %d %d]..[%d %d %d) -> physical texel (%d, %d, %d), %d physical box%s%s",
                    int(b.lo.w), b.cellLo[0], b.cellLo[1], b.cellLo[2], b.cellHi[0], b.cellHi[1], b.cellHi[2],
                    b.physLo[0], b.physLo[1], b.physLo[2], b.physLo[3], b.physLo[3] == 1 ? "" : "es",
                    b.cellLo[3] ? " (coverage change)" : "");
    }
    BufferVisualiser::drawInspector(ctx);
  }
};

}  // namespace

VOXLAB_REGISTER_VISUALISER(ClipLevelsVisualiser, OutputKind::Buffer, clipmap::kClipLevels.name());

}  // namespace voxlab
