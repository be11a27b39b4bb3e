// lpv's occlusion per cell and direction (semantic "lpv-occlusion": LpvOcclusion records from the
// propagate stage, one per cell, index (z * res + y) * res + x): the transmission
// 1 - clamp(A (0.25 + 0.5 n.d)) the propagation applies to light leaving a cell head on along each
// of the six axes (n: the stored normal it picks for that direction, A: lpv.occlusion-amplifier).
// The voxel grid itself is lpv's geometry volume; this is what it blocks.
//
// 2D view and the `.slice.png` file: one slice of cells (the view's slice axis and index, the
// middle one by default), one glyph per cell: four triangles pointing along the slice's in-plane
// axes, each coloured by the transmission of light travelling that way, and a centre square for
// the lesser of the two out-of-plane directions. Black: passes everything (empty cells are dark
// grey), bright orange: blocks everything; a one-sided reading of a wall shows as a glyph bright on
// one side only. Picking a glyph names the cell and its six transmissions. Statistics: occupied
// cells, cells that block some direction, the least and the mean head-on transmission of occupied
// cells. 3D: the buffer's point view (cells as points).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <imgui.h>

#include "inspect/visualisers/buffer.h"
#include "lpv/lpv_shared.h"
#include "techniques/lpv/stages.h"

namespace voxlab {
namespace {

using lpv::gpu::LpvOcclusion;
constexpr int kGlyph = 13;  // pixels per cell

struct Grid {
  int res = 0;
  std::vector<LpvOcclusion> cells;
  const LpvOcclusion& at(int x, int y, int z) const { return cells[(size_t(z) * res + y) * res + x]; }
};

Grid decode(const CapturedOutput& out) {
  Grid g;
  if (out.desc.layout.stride != sizeof(LpvOcclusion)) return g;
  const size_t n = std::min<size_t>(out.recordCount, out.records.size() / sizeof(LpvOcclusion));
  int res = int(std::lround(std::cbrt(double(n))));
  if (res <= 0 || size_t(res) * res * res != n) return g;
  g.res = res;
  g.cells.resize(n);
  std::memcpy(g.cells.data(), out.records.data(), n * sizeof(LpvOcclusion));
  return g;
}

// Transmission of light travelling along axis a (0 x, 1 y, 2 z) in direction s (+1, -1).
float transmission(const LpvOcclusion& o, int a, int s) { return s > 0 ? o.plus[a] : o.minus[a]; }

void blockedColour(float t, uint8_t* o) {
  const float b = std::clamp(1.0f - t, 0.0f, 1.0f);
  o[0] = uint8_t(std::lround(255.0f * b));
  o[1] = uint8_t(std::lround(150.0f * b * b));
  o[2] = uint8_t(std::lround(40.0f * b * b * b));
}

// The slice's in-plane axes (right, up) and normal axis, as SliceSpec's convention: axis 0 shows
// (z, y), 1 shows (x, z), 2 shows (x, y).
void sliceAxes(int axis, int& u, int& v) {
  u = axis == 0 ? 2 : 0;
  v = axis == 1 ? 2 : 1;
}

SliceImage slice(const Grid& g, const SliceSpec& chosen) {
  SliceImage img;
  if (g.res == 0) return img;
  const int axis = std::clamp(chosen.axis, 0, 2);
  const int index = chosen.index < 0 ? g.res / 2 : std::min(chosen.index, g.res - 1);
  int u, v;
  sliceAxes(axis, u, v);
  img.width = img.height = g.res * kGlyph;
  img.rgba.assign(size_t(img.width) * img.height * 4, 255);
  img.pick.assign(size_t(img.width) * img.height, -1);
  for (int cy = 0; cy < g.res; ++cy)
    for (int cx = 0; cx < g.res; ++cx) {
      glm::ivec3 c(0);
      c[axis] = index, c[u] = cx, c[v] = g.res - 1 - cy;  // image rows top first: up = +v
      const LpvOcclusion& o = g.at(c.x, c.y, c.z);
      const int32_t record = int32_t((size_t(c.z) * g.res + c.y) * g.res + c.x);
      for (int gy = 0; gy < kGlyph; ++gy)
        for (int gx = 0; gx < kGlyph; ++gx) {
          const size_t p = (size_t(cy) * kGlyph + gy) * img.width + size_t(cx) * kGlyph + gx;
          uint8_t* out = &img.rgba[p * 4];
          img.pick[p] = record;
          out[0] = out[1] = out[2] = (gx == 0 || gy == 0) ? 48 : 22;  // cell borders, empty cell
          if (!o.occupied || gx == 0 || gy == 0) continue;
          const float dx = float(gx) - 0.5f * kGlyph, dy = 0.5f * kGlyph - float(gy);
          float t;
          if (std::abs(dx) < 0.17f * kGlyph && std::abs(dy) < 0.17f * kGlyph)
            t = std::min(transmission(o, axis, 1), transmission(o, axis, -1));
          else if (std::abs(dx) >= std::abs(dy))
            t = transmission(o, u, dx > 0 ? 1 : -1);
          else
            t = transmission(o, v, dy > 0 ? 1 : -1);
          blockedColour(t, out);
        }
    }
  return img;
}

class LpvOcclusionVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "lpv-occlusion"; }

  nlohmann::json statistics(const CapturedOutput& out) const override {
    nlohmann::json st = BufferVisualiser::statistics(out);
    Grid g = decode(out);
    size_t occupied = 0, blocking = 0;
    double least = 1.0, mean = 0.0;
    for (const auto& o : g.cells) {
      if (!o.occupied) continue;
      ++occupied;
      blocking += o.plus.w < 1.0f;
      least = std::min(least, double(o.plus.w));
      mean += o.minus.w;
    }
    st["occlusion"] = {{"cells", g.cells.size()},
                       {"occupied", occupied},
                       {"blocking", blocking},
                       {"least_transmission", least},
                       {"mean_transmission_occupied", occupied ? mean / double(occupied) : 1.0}};
    return st;
  }

  nlohmann::json writeFiles(const CapturedOutput& out, const std::string& dir, const std::string& prefix) const override {
    nlohmann::json entry = BufferVisualiser::writeFiles(out, dir, prefix);
    SliceImage img = slice(decode(out), SliceSpec{});
    if (img.width > 0) {
      DisplayImage d;
      d.width = img.width, d.height = img.height;
      d.rgb.resize(size_t(img.width) * img.height * 3);
      for (size_t i = 0; i < size_t(img.width) * img.height; ++i) std::memcpy(&d.rgb[i * 3], &img.rgba[i * 4], 3);
      entry["files"].push_back(prefix + ".slice.png");
      writePng(d, dir + "/" + prefix + ".slice.png");
    }
    return entry;
  }

  SliceImage image2D(const VisualiserContext& ctx) const override {
    SliceImage img = slice(decode(ctx.out), ctx.view.slice);
    return img.width > 0 ? img : BufferVisualiser::image2D(ctx);
  }

  std::string describeElement(const VisualiserContext& ctx, const glm::ivec3& element) const override {
    Grid g = decode(ctx.out);
    if (g.res == 0 || element.x < 0 || size_t(element.x) >= g.cells.size())
      return BufferVisualiser::describeElement(ctx, element);
    const LpvOcclusion& o = g.cells[size_t(element.x)];
    const int x = element.x % g.res, y = (element.x / g.res) % g.res, z = element.x / (g.res * g.res);
    char buf[256];
    if (!o.occupied) {
      std::snprintf(buf, sizeof buf, "cell (%d, %d, %d): empty, passes all light", x, y, z);
      return buf;
    }
    std::snprintf(buf, sizeof buf,
                  "cell (%d, %d, %d): transmission +x %.3f -x %.3f +y %.3f -y %.3f +z %.3f -z %.3f (least %.3f)", x, y,
                  z, o.plus.x, o.minus.x, o.plus.y, o.minus.y, o.plus.z, o.minus.z, o.plus.w);
    return buf;
  }

  std::string caption(const VisualiserContext&) const override {
    return "transmission of light leaving each cell head on: triangles = in-plane directions of travel, centre = "
           "the lesser out-of-plane one; black passes, orange blocks";
  }

  void drawInspector(const VisualiserContext& ctx) const override {
    if (ctx.statistics.contains("occlusion")) drawStatisticsTable("lpv-occlusion", ctx.statistics["occlusion"]);
    BufferVisualiser::drawInspector(ctx);
  }
};

}  // namespace

VOXLAB_REGISTER_VISUALISER(LpvOcclusionVisualiser, OutputKind::Buffer, lpv::kLpvOcclusion.name());

}  // namespace voxlab
