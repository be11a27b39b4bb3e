// Volumes of L1 spherical harmonics (semantic "sh-l1": lpv's VPL, light and wavefront volumes; one
// RGBA32F texel per cell holding c00, c1-1, c10, c11 of one colour channel, shaders/common/sh.glsl).
//
// 2D view, three modes (inspector):
//   log c00         c00 in false colour on a log scale, kDecades decades below the level's largest
//                   c00 (black: c00 <= 0 or below the range). A propagation wavefront spans many
//                   decades, so a linear ramp shows only the cells next to the VPLs.
//   directionality  |b| / c00 in [0, 2/sqrt 3] (b = (-c11, -c1-1, c10), the band-1 vector); 2/sqrt 3
//                   is a single clamped-cosine lobe, 0 light from all sides; magenta: a cell breaking
//                   the cone condition c00 >= 0, |b| <= (2/sqrt 3) c00 (invariant of the note).
//   lobes           one polar glyph per cell: the intensity the cell sends along each direction of
//                   the slice plane, f(d) = Y00 c00 + Y1 b.d, filled orange where positive and blue
//                   where negative (an L1 field has a negative back lobe unless it is a cosine).
// The PNG `voxlab run` writes is the log c00 view (the texel mapping below). Statistics add the
// field's flux (sum of c00 x 2 sqrt pi), the largest directionality and the cells that break the
// cone condition. 3D: the log c00 volume with one line per lit cell along its b (length ~ |b|/c00).
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <imgui.h>

#include "inspect/view3d.h"
#include "inspect/visualisers/levels.h"
#include "techniques/lpv/stages.h"

namespace voxlab {
namespace {

constexpr float kY00 = 0.282094792f;  // as shaders/common/sh.glsl
constexpr float kY1 = 0.488602512f;
constexpr float kFluxPerC00 = 3.544907702f;
constexpr float kConeLimit = 1.154700538f;  // 2 / sqrt 3: |b| / c00 of one clamped-cosine lobe
constexpr float kDecades = 4.0f;
constexpr int kGlyph = 15;  // pixels per cell in the lobe view
// Slack of the cone-condition count: fp32 sums of up to 30 lobes per step exceed the limit by at
// most 3e-7 relative (measured in tests/unit/test_lpv.cpp, ConeConditionEverywhere).
constexpr float kConeSlack = 1e-5f;

using lpv::kShL1;

glm::vec3 band1(const float* v) { return {-v[3], -v[1], v[2]}; }

// Position of c on a log scale kDecades below 'top' (0 at the bottom, 1 at top); -1 = nothing.
float logPosition(float c, float top) {
  if (!(c > 0.0f) || !(top > 0.0f)) return -1.0f;
  return std::clamp(1.0f + std::log10(c / top) / kDecades, 0.0f, 1.0f);
}

void logC00(const float* v, int, float exposure, float, float hi, uint8_t* o) {
  float t = logPosition(v[0] * exposure, hi);
  if (t < 0.0f) {
    o[0] = o[1] = o[2] = 0;
    return;
  }
  falseColourRamp(t, o);
}

bool breaksCone(const float* v) {
  return v[0] < -1e-12f || glm::length(band1(v)) > kConeLimit * v[0] * (1.0f + kConeSlack) + 1e-12f;
}

void directionality(const float* v, uint8_t* o) {
  if (breaksCone(v)) {
    o[0] = 255, o[1] = 0, o[2] = 255;
    return;
  }
  if (!(v[0] > 0.0f)) {
    o[0] = o[1] = o[2] = 0;
    return;
  }
  falseColourRamp(std::min(glm::length(band1(v)) / v[0] / kConeLimit, 1.0f), o);
}

struct Registration {
  Registration() { registerTexelMapping(kShL1, {&logC00, true, false, false}); }
} registration;

float levelMaxC00(const LevelData& L) {
  float hi = 0.0f;
  for (size_t i = 0; i < L.texelCount(); ++i) hi = std::max(hi, L.values[i * L.channels]);
  return hi;
}

class ShVolumeVisualiser : public VolumeVisualiser {
 public:
  enum Mode { kLog = 0, kDirectionality = 1, kLobes = 2 };

  const char* name() const override { return "sh-l1"; }

  nlohmann::json statistics(const CapturedOutput& out) const override {
    nlohmann::json s = VolumeVisualiser::statistics(out);
    if (out.levels.empty() || out.levels[0].channels < 4) return s;
    const LevelData& L = out.levels[0];
    double c00 = 0.0;
    float maxDir = 0.0f;
    size_t broken = 0, lit = 0;
    for (size_t i = 0; i < L.texelCount(); ++i) {
      const float* v = &L.values[i * L.channels];
      c00 += v[0];
      if (breaksCone(v)) ++broken;
      if (v[0] > 0.0f) {
        ++lit;
        maxDir = std::max(maxDir, glm::length(band1(v)) / v[0]);
      }
    }
    s["sh"] = {{"flux", c00 * kFluxPerC00},
               {"cells_lit", lit},
               {"max_directionality", maxDir},
               {"cone_condition_violations", broken}};
    return s;
  }

  SliceImage image2D(const VisualiserContext& ctx) const override {
    const LevelData* L = shownLevel(ctx);
    if (!L || L->channels < 4) return VolumeVisualiser::image2D(ctx);
    if (mode_ == kLog) return VolumeVisualiser::image2D(ctx);
    SliceSpec s = sliceToShow(*L, ctx.view.slice);
    glm::ivec2 e = sliceExtent(*L, s);
    if (mode_ == kDirectionality) {
      SliceImage img;
      img.width = e.x, img.height = e.y;
      img.rgba.assign(size_t(e.x) * e.y * 4, 255);
      for (int py = 0; py < e.y; ++py)
        for (int px = 0; px < e.x; ++px) {
          glm::ivec3 t = sliceTexel(*L, s, px, py);
          directionality(&L->values[((size_t(t.z) * L->size.y + t.y) * L->size.x + t.x) * L->channels],
                         &img.rgba[(size_t(py) * e.x + px) * 4]);
        }
      return img;
    }
    return lobes(*L, s, e);
  }

  bool elementAt(const VisualiserContext& ctx, int px, int py, glm::ivec3& element) const override {
    if (mode_ != kLobes) return VolumeVisualiser::elementAt(ctx, px, py, element);
    return VolumeVisualiser::elementAt(ctx, px / kGlyph, py / kGlyph, element);
  }

  std::string describeElement(const VisualiserContext& ctx, const glm::ivec3& t) const override {
    const LevelData* L = shownLevel(ctx);
    if (!L || L->channels < 4 || t.x < 0 || t.y < 0 || t.z < 0 || t.x >= L->size.x || t.y >= L->size.y ||
        t.z >= L->size.z)
      return VolumeVisualiser::describeElement(ctx, t);
    const float* v = &L->values[((size_t(t.z) * L->size.y + t.y) * L->size.x + t.x) * L->channels];
    glm::vec3 b = band1(v);
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "cell (%d, %d, %d): c00 %.4g, b (%.3g, %.3g, %.3g), |b|/c00 %.3f (lobe %.3f), flux %.4g W%s", t.x, t.y,
                  t.z, v[0], b.x, b.y, b.z, v[0] > 0.0f ? glm::length(b) / v[0] : 0.0f, kConeLimit, v[0] * kFluxPerC00,
                  breaksCone(v) ? ", BREAKS the cone condition" : "");
    return buf;
  }

  std::string caption(const VisualiserContext&) const override {
    switch (mode_) {
      case kDirectionality: return "|b| / c00: 0 (blue) = light from all sides, 2/sqrt 3 (yellow) = one cosine lobe; magenta = cone condition broken";
      case kLobes: return "intensity sent along each direction of the slice plane: orange positive, blue negative";
      default: return "c00 on a log scale: 4 decades below the level's largest value (black below)";
    }
  }

  Content3D build3D(const VisualiserContext& ctx, View3D& view) const override {
    Content3D c = VolumeVisualiser::build3D(ctx, view);
    const LevelData* L = shownLevel(ctx);
    if (!L || L->channels < 4) return c;
    const float scale = float(ctx.out.levels[0].size.x) / float(L->size.x);
    const float hi = levelMaxC00(*L);
    std::vector<ViewInstance> lines;
    for (int z = 0; z < L->size.z; ++z)
      for (int y = 0; y < L->size.y; ++y)
        for (int x = 0; x < L->size.x && lines.size() < 40000; ++x) {
          const float* v = &L->values[((size_t(z) * L->size.y + y) * L->size.x + x) * L->channels];
          if (logPosition(v[0], hi) <= 0.0f) continue;
          glm::vec3 b = band1(v);
          float len = glm::length(b);
          if (!(len > 0.0f)) continue;
          glm::vec3 centre = (glm::vec3(x, y, z) + 0.5f) * scale;
          glm::vec3 tip = centre + b / len * (0.5f * scale * std::min(len / v[0] / kConeLimit, 1.0f));
          lines.push_back({glm::vec4(centre, 0.0f), glm::vec4(1.0f, 1.0f, 1.0f, 1.0f)});
          lines.push_back({glm::vec4(tip, 0.0f), glm::vec4(1.0f, 0.5f, 0.1f, 1.0f)});
        }
    view.setLines(std::move(lines));
    c.info += "; lines: direction of b per cell, length |b| / c00 (half a cell = one cosine lobe)";
    return c;
  }

  void drawInspector(const VisualiserContext& ctx) const override {
    ImGui::TextUnformatted("SH view");
    const char* names[3] = {"log c00", "|b| / c00", "lobes"};
    for (int m = 0; m < 3; ++m) {
      ImGui::SameLine();
      ImGui::RadioButton(names[m], &mode_, m);
    }
    if (ctx.statistics.contains("sh")) drawStatisticsTable("sh-stats", ctx.statistics["sh"]);
    VolumeVisualiser::drawInspector(ctx);
  }

 private:
  // Polar glyphs: world directions of the image's right and up axes from the slice mapping itself.
  SliceImage lobes(const LevelData& L, const SliceSpec& s, glm::ivec2 e) const {
    auto axisOf = [&](glm::ivec3 d) {
      glm::vec3 a(0.0f);
      for (int k = 0; k < 3; ++k) a[k] = float(d[k] > 0) - float(d[k] < 0);
      return a;
    };
    glm::vec3 right(0.0f), up(0.0f);
    const int axisU = s.axis == 0 ? 2 : 0, axisV = s.axis == 1 ? 2 : 1;
    right[axisU] = 1.0f, up[axisV] = 1.0f;  // fallbacks for one-texel extents
    if (e.x > 1) right = axisOf(sliceTexel(L, s, 1, 0) - sliceTexel(L, s, 0, 0));
    if (e.y > 1) up = axisOf(sliceTexel(L, s, 0, 0) - sliceTexel(L, s, 0, 1));
    float fmax = 0.0f;
    for (int py = 0; py < e.y; ++py)
      for (int px = 0; px < e.x; ++px) {
        glm::ivec3 t = sliceTexel(L, s, px, py);
        const float* v = &L.values[((size_t(t.z) * L.size.y + t.y) * L.size.x + t.x) * L.channels];
        fmax = std::max(fmax, std::abs(kY00 * v[0]) + kY1 * glm::length(band1(v)));
      }
    SliceImage img;
    img.width = e.x * kGlyph, img.height = e.y * kGlyph;
    img.rgba.assign(size_t(img.width) * img.height * 4, 255);
    const float radius = 0.47f * kGlyph;
    for (int cy = 0; cy < e.y; ++cy)
      for (int cx = 0; cx < e.x; ++cx) {
        glm::ivec3 t = sliceTexel(L, s, cx, cy);
        const float* v = &L.values[((size_t(t.z) * L.size.y + t.y) * L.size.x + t.x) * L.channels];
        glm::vec3 b = band1(v);
        for (int gy = 0; gy < kGlyph; ++gy)
          for (int gx = 0; gx < kGlyph; ++gx) {
            uint8_t* o = &img.rgba[((size_t(cy) * kGlyph + gy) * img.width + size_t(cx) * kGlyph + gx) * 4];
            o[0] = o[1] = o[2] = (gx == 0 || gy == 0) ? 48 : 16;  // cell borders, background
            if (!(fmax > 0.0f) || gx == 0 || gy == 0) continue;
            float dx = float(gx) - 0.5f * kGlyph, dy = 0.5f * kGlyph - float(gy);
            float r = std::sqrt(dx * dx + dy * dy);
            if (r < 0.5f) continue;
            glm::vec3 d = (dx / r) * right + (dy / r) * up;
            float f = kY00 * v[0] + kY1 * glm::dot(b, d);
            if (r > radius * std::abs(f) / fmax) continue;
            if (f >= 0.0f) o[0] = 255, o[1] = 150, o[2] = 40;
            else o[0] = 60, o[1] = 130, o[2] = 255;
          }
      }
    return img;
  }

  mutable int mode_ = kLog;
};

}  // namespace

VOXLAB_REGISTER_VISUALISER(ShVolumeVisualiser, OutputKind::Volume3D, kShL1.name());

}  // namespace voxlab
