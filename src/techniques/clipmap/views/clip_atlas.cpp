// The clipmap's atlas (clipmap/update/clip-atlas: every level's physical texture, semantic
// clip-atlas). Without the level records it is shown as any colour volume; with them (the
// clip-levels output of the anchor stage, through VisualiserContext::contextOutput):
// 2D view: one z slice of one level and face, N x N texels enlarged, either
//          - physical (as stored): texel (x, y, z) of the level's block. The logical origin
//            (cell o_k, at texel T_k = o_k mod N) is a white dot; the dashed lines through it
//            are where the region's far side (cell o_k + N - 1, texel T_k - 1) meets its near
//            side: the world wraps there. After a move only the texels of the move's cells change.
//          - unrolled (logical order): texel (x, y) of slice z shows cell o_k + (x, y, z), read at
//            its toroidal address; the dashed lines are the physical seam (texel N-1 next to
//            texel 0), at logical (N - T_k) mod N.
//          Hovering reads out the texel -> world cell -> world box and the value. The texels of
//          the cells the last move voxelized (the update stage's clip-move-boxes, when the viewer
//          has them) are outlined in yellow: a slab's physical boxes after wrapping.
// Inspector: level, face, slice, the unroll toggle, then the volume's controls and statistics.
#include "techniques/clipmap/views/clip_atlas.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <imgui.h>

#include "inspect/visualisers/levels.h"

namespace voxlab {
namespace clipmap {

std::vector<LevelRecord> levelRecords(const CapturedOutput& out) { return recordsAs<LevelRecord>(out); }

static Cell originOf(const LevelRecord& r) { return Cell(r.origin[0], r.origin[1], r.origin[2]); }

glm::ivec3 atlasSliceTexel(const LevelRecord& r, const AtlasSlice& s, int x, int y) {
  if (!s.unrolled) return {x, y, s.z};
  return toroidal(originOf(r) + Cell(x, y, s.z), r.n);
}

Cell atlasSliceCell(const LevelRecord& r, const AtlasSlice& s, int x, int y) {
  if (s.unrolled) return originOf(r) + Cell(x, y, s.z);
  return cellAtTexel({x, y, s.z}, originOf(r), r.n);
}

LevelData atlasSliceValues(const LevelData& atlas, const LevelRecord& r, const AtlasSlice& s) {
  LevelData d;
  const int n = r.n, b = n + 2;
  d.size = {n, n, 1};
  d.channels = atlas.channels;
  d.values.resize(size_t(n) * n * size_t(d.channels));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const glm::ivec3 t = atlasSliceTexel(r, s, x, y);
      const glm::ivec3 a(s.face * b + 1 + t.x, s.level * b + 1 + t.y, 1 + t.z);
      for (int c = 0; c < d.channels; ++c) d.values[(size_t(y) * n + size_t(x)) * d.channels + c] = atlas.at(a.x, a.y, a.z, c);
    }
  return d;
}

}  // namespace clipmap

namespace {

using clipmap::AtlasSlice;
using clipmap::LevelRecord;

// The atlas holds radiance with opacity, mapped as the shared colour semantic maps it (sRGB-encoded,
// alpha as opacity), for the slices, the 3D view and the PNGs `voxlab run` writes.
void atlasColour(const float* v, int n, float x, float, float, uint8_t* o) {
  for (int k = 0; k < 3; ++k) o[k] = unitToByte(srgbEncode((k < n ? v[k] : v[0]) * x));
}

struct AtlasMappingRegistration {
  //                                                  normalise alphaIsOpacity exact
  AtlasMappingRegistration() { registerTexelMapping(clipmap::kClipAtlas, {&atlasColour, false, true, false}); }
} atlasMappingRegistration;

constexpr int kImageSize = 512;

class ClipAtlasVisualiser : public VolumeVisualiser {
 public:
  const char* name() const override { return "clip-atlas"; }

  SliceImage image2D(const VisualiserContext& ctx) const override {
    std::vector<LevelRecord> levels;
    if (!recordsOf(ctx, levels)) return VolumeVisualiser::image2D(ctx);
    const AtlasSlice s = slice(ctx, levels);
    const LevelRecord& r = levels[size_t(s.level)];
    const int n = r.n, scale = std::max(1, kImageSize / n);
    const LevelData values = clipmap::atlasSliceValues(ctx.out.levels[0], r, s);
    const SliceImage small = mapSlice(values, ctx.out.desc.semantic, SliceSpec{2, 0}, ctx.view.display);
    SliceImage img;
    img.width = img.height = n * scale;
    img.rgba.resize(size_t(img.width) * img.height * 4);
    for (int py = 0; py < img.height; ++py)
      for (int px = 0; px < img.width; ++px)
        std::memcpy(&img.rgba[(size_t(py) * img.width + px) * 4], &small.rgba[(size_t(py / scale) * n + px / scale) * 4], 4);
    auto put = [&](int x, int y, uint8_t v) {
      if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
      uint8_t* p = &img.rgba[(size_t(y) * img.width + x) * 4];
      p[0] = p[1] = p[2] = v;
      p[3] = 255;
    };
    // The marked lines, in slice texels (x right, y up): the texel column/row where they start.
    const glm::ivec3 t(r.offset[0], r.offset[1], r.offset[2]);
    const glm::ivec2 mark = s.unrolled ? glm::ivec2((n - t.x) % n, (n - t.y) % n) : glm::ivec2(t.x, t.y);
    const int lineX = mark.x * scale, lineY = (n - mark.y) * scale;  // image rows count from the top
    for (int i = 0; i < img.height; ++i)
      if ((i / 6) % 2 == 0) put(lineX, i, 255), put(lineX - 1, i, 0);
    for (int i = 0; i < img.width; ++i)
      if ((i / 6) % 2 == 0) put(i, lineY - 1, 255), put(i, lineY, 0);
    // The logical origin: texel T's lower left corner (physical), slice texel (0, 0) (unrolled).
    const int ox = s.unrolled ? 0 : t.x * scale, oy = s.unrolled ? img.height : (n - t.y) * scale;
    for (int dy = -4; dy <= 4; ++dy)
      for (int dx = -4; dx <= 4; ++dx) put(ox + dx, oy - 1 + dy, std::abs(dx) == 4 || std::abs(dy) == 4 ? 0 : 255);
    // The last move's boxes of this level: outline the region of slice texels whose cells they hold.
    CapturedOutput boxesOut;
    if (ctx.contextOutput && ctx.contextOutput("clip-move-boxes", boxesOut) &&
        boxesOut.desc.layout.stride == sizeof(clipmap::SlabRecord)) {
      std::vector<clipmap::SlabRecord> boxes(std::min<size_t>(boxesOut.recordCount, boxesOut.records.size() / sizeof(clipmap::SlabRecord)));
      if (!boxes.empty()) std::memcpy(boxes.data(), boxesOut.records.data(), boxes.size() * sizeof(clipmap::SlabRecord));
      auto inBox = [&](int x, int y) {
        if (x < 0 || y < 0 || x >= n || y >= n) return false;
        const clipmap::Cell c = clipmap::atlasSliceCell(r, s, x, y);
        for (const auto& b : boxes)
          if (int(b.lo.w) == s.level && c.x >= b.cellLo[0] && c.y >= b.cellLo[1] && c.z >= b.cellLo[2] &&
              c.x < b.cellHi[0] && c.y < b.cellHi[1] && c.z < b.cellHi[2])
            return true;
        return false;
      };
      auto yellow = [&](int x, int y) {
        if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
        uint8_t* p = &img.rgba[(size_t(y) * img.width + x) * 4];
        p[0] = 255, p[1] = 220, p[2] = 0, p[3] = 255;
      };
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          if (!inBox(x, y)) continue;
          const int left = x * scale, right = (x + 1) * scale - 1, top = (n - 1 - y) * scale, bottom = (n - y) * scale - 1;
          for (int i = 0; i < scale; ++i) {
            if (!inBox(x - 1, y)) yellow(left, top + i);
            if (!inBox(x + 1, y)) yellow(right, top + i);
            if (!inBox(x, y + 1)) yellow(left + i, top);
            if (!inBox(x, y - 1)) yellow(left + i, bottom);
          }
        }
    }
    return img;
  }

  bool elementAt(const VisualiserContext& ctx, int px, int py, glm::ivec3& element) const override {
    std::vector<LevelRecord> levels;
    if (!recordsOf(ctx, levels)) return VolumeVisualiser::elementAt(ctx, px, py, element);
    const AtlasSlice s = slice(ctx, levels);
    const int n = levels[size_t(s.level)].n, scale = std::max(1, kImageSize / n);
    if (px < 0 || py < 0 || px >= n * scale || py >= n * scale) return false;
    element = {px / scale, n - 1 - py / scale, s.z};
    return true;
  }

  std::string describeElement(const VisualiserContext& ctx, const glm::ivec3& e) const override {
    std::vector<LevelRecord> levels;
    if (!recordsOf(ctx, levels)) return VolumeVisualiser::describeElement(ctx, e);
    const AtlasSlice s = slice(ctx, levels);
    const LevelRecord& r = levels[size_t(s.level)];
    const glm::ivec3 t = clipmap::atlasSliceTexel(r, s, e.x, e.y);
    const clipmap::Cell c = clipmap::atlasSliceCell(r, s, e.x, e.y);
    const double size = double(r.hi.w);
    const int b = r.n + 2;
    const LevelData& atlas = ctx.out.levels[0];
    const glm::ivec3 a(s.face * b + 1 + t.x, s.level * b + 1 + t.y, 1 + t.z);
    char buf[400];
    std::snprintf(buf, sizeof buf,
                  "level %d face %d: %s (%d, %d, %d) -> physical texel (%d, %d, %d) -> world cell (%lld, %lld, %lld) = "
                  "[%.4g, %.4g) x [%.4g, %.4g) x [%.4g, %.4g) m; value (%.3f, %.3f, %.3f, %.3f)",
                  s.level, s.face, s.unrolled ? "logical" : "physical", e.x, e.y, e.z, t.x, t.y, t.z, (long long)c.x,
                  (long long)c.y, (long long)c.z, double(c.x) * size, double(c.x + 1) * size, double(c.y) * size,
                  double(c.y + 1) * size, double(c.z) * size, double(c.z + 1) * size, atlas.at(a.x, a.y, a.z, 0),
                  atlas.at(a.x, a.y, a.z, 1), atlas.at(a.x, a.y, a.z, 2), atlas.at(a.x, a.y, a.z, 3));
    return buf;
  }

  std::string caption(const VisualiserContext& ctx) const override {
    std::vector<LevelRecord> levels;
    if (!recordsOf(ctx, levels)) return "the atlas of every level (no clip-levels records: run the anchor stage)";
    const AtlasSlice s = slice(ctx, levels);
    const LevelRecord& r = levels[size_t(s.level)];
    char buf[300];
    if (s.unrolled)
      std::snprintf(buf, sizeof buf,
                    "level %d, logical slice z %d, unrolled (x right, y up: cell o + (x, y, z)); dot: the logical origin o "
                    "= (%d, %d, %d); dashed: the physical seam (texel %d next to texel 0)",
                    s.level, s.z, r.origin[0], r.origin[1], r.origin[2], r.n - 1);
    else
      std::snprintf(buf, sizeof buf,
                    "level %d, physical slice z %d (as stored, x right, y up); dot: the logical origin o = (%d, %d, %d) "
                    "at texel T = (%d, %d, %d); dashed: where the region wraps (cell o + N - 1 next to cell o)",
                    s.level, s.z, r.origin[0], r.origin[1], r.origin[2], r.offset[0], r.offset[1], r.offset[2]);
    return buf;
  }

  void drawInspector(const VisualiserContext& ctx) const override {
    std::vector<LevelRecord> levels;
    if (recordsOf(ctx, levels)) {
      const int faces = std::max(1, ctx.out.levels[0].size.x / (levels[0].n + 2));
      ImGui::SliderInt("clip level", &level_, 0, int(levels.size()) - 1);
      ImGui::SliderInt("face", &face_, 0, faces - 1, faces > 1 ? "%d (0 isotropic; +x -x +y -y +z -z)" : "%d");
      if (z_ < 0) z_ = levels[0].n / 2;
      ImGui::SliderInt("slice z", &z_, 0, levels[0].n - 1);
      ImGui::Checkbox("unroll into logical order", &unrolled_);
      const LevelRecord& r = levels[size_t(std::clamp(level_, 0, int(levels.size()) - 1))];
      ImGui::Text("origin o = (%d, %d, %d) cells of %.4g m, T = o mod %d = (%d, %d, %d)", r.origin[0], r.origin[1],
                  r.origin[2], double(r.hi.w), r.n, r.offset[0], r.offset[1], r.offset[2]);
      ImGui::Separator();
    }
    VolumeVisualiser::drawInspector(ctx);
  }

 private:
  static bool recordsOf(const VisualiserContext& ctx, std::vector<LevelRecord>& levels) {
    CapturedOutput records;
    if (!ctx.contextOutput || ctx.out.levels.empty() || !ctx.contextOutput(clipmap::kClipLevels.name(), records))
      return false;
    levels = clipmap::levelRecords(records);
    if (levels.empty() || levels[0].n <= 0) return false;
    const int b = levels[0].n + 2;
    const glm::ivec3 size = ctx.out.levels[0].size;
    return size.y == int(levels.size()) * b && size.z == b && size.x % b == 0;
  }

  AtlasSlice slice(const VisualiserContext& ctx, const std::vector<LevelRecord>& levels) const {
    AtlasSlice s;
    const int faces = std::max(1, ctx.out.levels[0].size.x / (levels[0].n + 2));
    s.level = std::clamp(level_, 0, int(levels.size()) - 1);
    s.face = std::clamp(face_, 0, faces - 1);
    s.z = std::clamp(z_ < 0 ? levels[0].n / 2 : z_, 0, levels[0].n - 1);
    s.unrolled = unrolled_;
    return s;
  }

  mutable int level_ = 0, face_ = 0, z_ = -1;
  mutable bool unrolled_ = false;
};

}  // namespace

VOXLAB_REGISTER_VISUALISER(ClipAtlasVisualiser, OutputKind::Volume3D, clipmap::kClipAtlas.name());

}  // namespace voxlab
