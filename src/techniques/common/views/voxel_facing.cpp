// Facing codes (semantic "voxel-facing", techniques/common/facing.h): per voxel, which of its six
// sides show a surface's front to the cones that arrive from that side, and how squarely.
//
// Texel colour (files, 3D views, the overlay): how squarely the voxel's surfaces face each axis,
// the larger of its two sides per axis as red (x), green (y) and blue (z), like a normal map
// without signs; black where no surface is.
//
// 2D view: one glyph per voxel of the slice. A bar along each in-plane side of the voxel, as
// bright (yellow) as the surfaces' fronts face that way, and the centre as bright (cyan) as they
// face out of the slice, toward the viewer or away. A floor voxel shows a bright top bar; a wall
// one voxel thick that is lit on both sides shows bars on both: the rule cannot tell which of the
// two fronts a cone sees first, which is why thin walls leak. Picking a glyph names the six
// weights. Statistics: voxels with a surface, and per axis those with fronts on both sides.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <imgui.h>

#include "capture/output_handler.h"
#include "inspect/inspect_logic.h"
#include "inspect/visualisers/levels.h"
#include "techniques/common/facing.h"

namespace voxlab {
namespace {

const char* const kSideNames[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};

uint32_t codeAt(const LevelData& L, const glm::ivec3& t) { return uint32_t(std::lround(L.at(t.x, t.y, t.z, 0))); }

// Texel colour: per axis, the larger of its two sides' weights.
void facingColour(const float* v, int, float, float, float, uint8_t* o) {
  const uint32_t code = uint32_t(std::lround(v[0]));
  for (int a = 0; a < 3; ++a) o[a] = unitToByte(std::max(facingSide(code, a, 1), facingSide(code, a, -1)));
}

const bool kMappingRegistered = [] {
  registerTexelMapping(kVoxelFacingSemantic, {&facingColour, false, false, true});
  return true;
}();

// Pixels per voxel of the glyph view: large enough for four side bars, the whole slice within
// about 1024 pixels.
int glyphSize(const glm::ivec2& extent) { return std::clamp(1024 / std::max({extent.x, extent.y, 1}), 4, 16); }

// The texel axis (0..2) and sign that the image moves along from pixel 'from' to pixel 'to' (one
// step right or up) in slice 's' of L; axis -1 for a slice too small to tell.
void imageAxis(const LevelData& L, const SliceSpec& s, glm::ivec2 from, glm::ivec2 to, int& axis, int& sign) {
  const glm::ivec2 e = sliceExtent(L, s);
  axis = -1, sign = 1;
  if (e.x < 2 || e.y < 2) return;
  const glm::ivec3 a = sliceTexel(L, s, from.x, from.y), b = sliceTexel(L, s, to.x, to.y);
  for (int k = 0; k < 3; ++k)
    if (a[k] != b[k]) axis = k, sign = b[k] > a[k] ? 1 : -1;
}

class VoxelFacingVisualiser : public VolumeVisualiser {
 public:
  const char* name() const override { return "voxel-facing"; }

  nlohmann::json statistics(const CapturedOutput& out) const override {
    nlohmann::json st = VolumeVisualiser::statistics(out);
    if (out.levels.empty()) return st;
    const LevelData& L = out.levels[0];
    size_t surface = 0, twoSided[3] = {0, 0, 0};
    for (int z = 0; z < L.size.z; ++z)
      for (int y = 0; y < L.size.y; ++y)
        for (int x = 0; x < L.size.x; ++x) {
          const uint32_t code = codeAt(L, {x, y, z});
          if (!code) continue;
          ++surface;
          for (int a = 0; a < 3; ++a) twoSided[a] += facingSide(code, a, 1) > 0 && facingSide(code, a, -1) > 0;
        }
    st["facing"] = {{"voxels_with_a_surface", surface},
                    {"fronts_on_both_x_sides", twoSided[0]},
                    {"fronts_on_both_y_sides", twoSided[1]},
                    {"fronts_on_both_z_sides", twoSided[2]}};
    return st;
  }

  SliceImage image2D(const VisualiserContext& ctx) const override {
    const LevelData* L = shownLevel(ctx);
    if (!L) return {};
    const SliceSpec s = sliceToShow(*L, ctx.view.slice);
    const glm::ivec2 e = sliceExtent(*L, s);
    int rightAxis, rightSign, upAxis, upSign;
    imageAxis(*L, s, {0, 0}, {1, 0}, rightAxis, rightSign);
    imageAxis(*L, s, {0, 1}, {0, 0}, upAxis, upSign);
    if (rightAxis < 0 || upAxis < 0) return VolumeVisualiser::image2D(ctx);
    const int outAxis = 3 - rightAxis - upAxis;
    const int g = glyphSize(e), bar = std::max(1, g / 4);
    SliceImage img;
    img.width = e.x * g;
    img.height = e.y * g;
    img.rgba.assign(size_t(img.width) * img.height * 4, 255);
    for (int cy = 0; cy < e.y; ++cy)
      for (int cx = 0; cx < e.x; ++cx) {
        const uint32_t code = codeAt(*L, sliceTexel(*L, s, cx, cy));
        const float right = facingSide(code, rightAxis, rightSign), left = facingSide(code, rightAxis, -rightSign);
        const float up = facingSide(code, upAxis, upSign), down = facingSide(code, upAxis, -upSign);
        const float out = std::max(facingSide(code, outAxis, 1), facingSide(code, outAxis, -1));
        for (int gy = 0; gy < g; ++gy)
          for (int gx = 0; gx < g; ++gx) {
            uint8_t* o = &img.rgba[((size_t(cy) * g + gy) * img.width + size_t(cx) * g + gx) * 4];
            const bool border = gx == 0 || gy == 0;
            if (!code || border) {
              o[0] = o[1] = o[2] = border ? 40 : 18;
              continue;
            }
            float w = -1.0f;  // a side bar's weight, or -1 inside
            if (gx >= g - bar) w = right;
            else if (gx <= bar) w = left;
            if (gy <= bar) w = std::max(w, up);
            else if (gy >= g - bar) w = std::max(w, down);
            if (w >= 0.0f) {
              o[0] = unitToByte(0.15f + 0.85f * w), o[1] = unitToByte(0.12f + 0.73f * w), o[2] = unitToByte(0.1f * w);
            } else {
              o[0] = unitToByte(0.1f), o[1] = unitToByte(0.1f + 0.6f * out), o[2] = unitToByte(0.12f + 0.7f * out);
            }
          }
      }
    return img;
  }

  bool elementAt(const VisualiserContext& ctx, int px, int py, glm::ivec3& element) const override {
    const LevelData* L = shownLevel(ctx);
    if (!L) return false;
    const SliceSpec s = sliceToShow(*L, ctx.view.slice);
    const glm::ivec2 e = sliceExtent(*L, s);
    const int g = glyphSize(e);
    if (px < 0 || py < 0 || px >= e.x * g || py >= e.y * g) return false;
    element = sliceTexel(*L, s, px / g, py / g);
    return true;
  }

  std::string describeElement(const VisualiserContext& ctx, const glm::ivec3& t) const override {
    const LevelData* L = shownLevel(ctx);
    if (!L || t.x < 0 || t.y < 0 || t.z < 0 || t.x >= L->size.x || t.y >= L->size.y || t.z >= L->size.z) return "";
    const uint32_t code = codeAt(*L, t);
    char buf[256];
    int n = std::snprintf(buf, sizeof buf, "voxel (%d, %d, %d): ", t.x, t.y, t.z);
    if (!code) {
      std::snprintf(buf + n, sizeof buf - n, "no surface");
      return buf;
    }
    n += std::snprintf(buf + n, sizeof buf - n, "sides facing");
    for (int a = 0; a < 3; ++a)
      for (int sgn : {1, -1})
        n += std::snprintf(buf + n, sizeof buf - n, " %s %.1f", kSideNames[2 * a + (sgn > 0 ? 0 : 1)], facingSide(code, a, sgn));
    std::snprintf(buf + n, sizeof buf - n, " (code 0x%08x)", code);
    return buf;
  }

  std::string caption(const VisualiserContext&) const override {
    return "per voxel, how squarely its surfaces face each side: yellow bars = in-plane sides, cyan centre = out of "
           "the slice; dark = no surface";
  }

  void drawInspector(const VisualiserContext& ctx) const override {
    if (ctx.statistics.contains("facing")) drawStatisticsTable("voxel-facing", ctx.statistics["facing"]);
    VolumeVisualiser::drawInspector(ctx);
  }
};

}  // namespace

VOXLAB_REGISTER_VISUALISER(VoxelFacingVisualiser, OutputKind::Volume3D, kVoxelFacingSemantic.name());

}  // namespace voxlab
