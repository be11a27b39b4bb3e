// Layered RSM data (the lrsm technique, src/techniques/lrsm/lrsm.h): atlases whose n layers lie
// side by side in one image (layer l covers x in [l W, (l+1) W), W = height), stored premultiplied
// by the layer's coverage alpha. The 2D view shows every layer of the chosen level, with what the
// gather reads from it: A*R or alpha (radiance), the mean normal n/alpha or alpha (normal), mu,
// sigma or alpha (moments: alpha z'^k, k = 1..4, whose alpha is the normal atlas's at the same
// level); the value under the cursor names the layer and un-premultiplies; the statistics add each
// layer's coverage per level. The layer-id image gets a colour per layer.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include <imgui.h>

#include "inspect/visualisers/levels.h"
#include "techniques/lrsm/stages.h"

namespace voxlab {
namespace {

using lrsm::kLayerDepth;
using lrsm::kLayerId;
using lrsm::kLayerNormal;
using lrsm::kLayerRadiance;

enum class Attribute { Radiance, Normal, Depth };

Attribute attributeOf(const OutputDesc& d) {
  if (d.semantic == kLayerRadiance) return Attribute::Radiance;
  return d.semantic == kLayerNormal ? Attribute::Normal : Attribute::Depth;
}

// The alpha of each attribute's texels: radiance .a, normal .w; the moments hold none (their
// four channels are alpha z'^k), so theirs is the normal atlas's .w at the same level.
struct AlphaSource {
  CapturedOutput normal;  // the normal atlas, for the moments
  const LevelData* level = nullptr;
  float at(int x, int y) const { return level ? level->at(x, y, 0, 3) : 0.0f; }
};
AlphaSource alphaFor(const VisualiserContext& ctx, const LevelData* shown) {
  AlphaSource a;
  if (attributeOf(ctx.out.desc) != Attribute::Depth) {
    a.level = shown;
  } else if (ctx.contextOutput && ctx.contextOutput(kLayerNormal.name(), a.normal) &&
             ctx.view.level < int(a.normal.levels.size()) && shown &&
             a.normal.levels[ctx.view.level].size == shown->size) {
    a.level = &a.normal.levels[ctx.view.level];
  }
  return a;
}

const char* const kModes[3][3] = {{"A*R", "alpha", nullptr}, {"mean normal n", "alpha", nullptr}, {"mu", "sigma", "alpha"}};
int modeCount(Attribute a) { return a == Attribute::Depth ? 3 : 2; }

// What the user chose per view (kept across frames, keyed by the viewer's settings object).
std::map<const ViewSettings*, int>& modes() {
  static std::map<const ViewSettings*, int> m;
  return m;
}

int layersOf(const LevelData& L) { return L.size.y > 0 ? std::max(L.size.x / L.size.y, 1) : 1; }

class LayerAtlasVisualiser : public ImageVisualiser {
 public:
  const char* name() const override { return "lrsm-layers"; }
  CaptureTier defaultTier(const OutputDesc&) const override { return CaptureTier::Tolerance; }

  nlohmann::json statistics(const CapturedOutput& out) const override {
    nlohmann::json s = ImageVisualiser::statistics(out);
    if (attributeOf(out.desc) == Attribute::Depth) return s;  // no alpha of their own
    nlohmann::json perLevel = nlohmann::json::array();
    for (const LevelData& L : out.levels) {
      const int n = layersOf(L), w = L.size.y;
      nlohmann::json layers = nlohmann::json::array();
      for (int l = 0; l < n; ++l) {
        double alpha = 0;
        for (int y = 0; y < w; ++y)
          for (int x = 0; x < w; ++x) alpha += L.at(l * w + x, y, 0, std::min(3, L.channels - 1));
        layers.push_back(alpha / (double(w) * w));
      }
      perLevel.push_back(layers);
    }
    s["layer_coverage_per_level"] = perLevel;
    s["layers"] = out.levels.empty() ? 0 : layersOf(out.levels[0]);
    return s;
  }

  SliceImage image2D(const VisualiserContext& ctx) const override {
    const LevelData* L = shownLevel(ctx);
    if (!L) return {};
    const Attribute a = attributeOf(ctx.out.desc);
    const int mode = std::clamp(modes()[&ctx.view], 0, modeCount(a) - 1);
    const AlphaSource alphas = alphaFor(ctx, L);
    const float x = ctx.view.display.exposure;
    SliceImage img;
    img.width = L->size.x;
    img.height = L->size.y;
    img.rgba.assign(size_t(img.width) * img.height * 4, 255);
    float sigmaMax = 1e-12f;
    if (a == Attribute::Depth && mode == 1)
      for (int y = 0; y < L->size.y; ++y)
        for (int px = 0; px < L->size.x; ++px) sigmaMax = std::max(sigmaMax, sigmaAt(*L, alphas.at(px, y), px, y));
    for (int py = 0; py < img.height; ++py)
      for (int px = 0; px < img.width; ++px) {
        const int ty = img.height - 1 - py;
        uint8_t* o = &img.rgba[(size_t(py) * img.width + px) * 4];
        const float alpha = alphas.at(px, ty);
        auto grey = [&](float v) { o[0] = o[1] = o[2] = unitToByte(v); };
        if (mode == modeCount(a) - 1) { grey(alpha * x); continue; }
        if (alpha <= 0.0f) { o[0] = o[1] = o[2] = 0; continue; }
        if (a == Attribute::Radiance) {
          for (int k = 0; k < 3; ++k) {
            float v = L->at(px, ty, 0, k) * x;
            o[k] = unitToByte(srgbEncode(v / (1.0f + v)));
          }
        } else if (a == Attribute::Normal) {
          for (int k = 0; k < 3; ++k) o[k] = unitToByte(L->at(px, ty, 0, k) / alpha * 0.5f + 0.5f);
        } else if (mode == 0) {
          grey(L->at(px, ty, 0, 0) / alpha);
        } else {
          falseColourRamp(sigmaAt(*L, alpha, px, ty) / sigmaMax, o);
        }
      }
    return img;
  }

  std::string describeElement(const VisualiserContext& ctx, const glm::ivec3& t) const override {
    const LevelData* L = shownLevel(ctx);
    if (!L || t.x < 0 || t.y < 0 || t.x >= L->size.x || t.y >= L->size.y) return "";
    const Attribute a = attributeOf(ctx.out.desc);
    const int w = L->size.y, layer = t.x / w;
    const float alpha = alphaFor(ctx, L).at(t.x, t.y);
    char buf[256];
    if (a == Attribute::Radiance)
      std::snprintf(buf, sizeof buf, "layer %d texel (%d, %d), level %d: alpha %.4g, A*R (%.4g, %.4g, %.4g)", layer,
                    t.x % w, w - 1 - t.y, ctx.view.level, alpha, L->at(t.x, t.y, 0, 0), L->at(t.x, t.y, 0, 1),
                    L->at(t.x, t.y, 0, 2));
    else if (a == Attribute::Normal) {
      const float s = alpha > 0 ? 1.0f / alpha : 0.0f;
      std::snprintf(buf, sizeof buf, "layer %d texel (%d, %d), level %d: alpha %.4g, n/alpha (%.3f, %.3f, %.3f), |n/alpha| %.3f",
                    layer, t.x % w, w - 1 - t.y, ctx.view.level, alpha, L->at(t.x, t.y, 0, 0) * s,
                    L->at(t.x, t.y, 0, 1) * s, L->at(t.x, t.y, 0, 2) * s,
                    std::sqrt(std::pow(L->at(t.x, t.y, 0, 0) * s, 2.0f) + std::pow(L->at(t.x, t.y, 0, 1) * s, 2.0f) +
                              std::pow(L->at(t.x, t.y, 0, 2) * s, 2.0f)));
    } else {
      const float mu = alpha > 0 ? L->at(t.x, t.y, 0, 0) / alpha : 0.0f;
      const float e2 = alpha > 0 ? L->at(t.x, t.y, 0, 1) / alpha : 0.0f;
      std::snprintf(buf, sizeof buf, "layer %d texel (%d, %d), level %d: alpha %.4g, mu %.5f, E[z^2] %.5f, sigma^2 %.3g",
                    layer, t.x % w, w - 1 - t.y, ctx.view.level, alpha, mu, e2, e2 - mu * mu);
    }
    return buf;
  }

  void drawInspector(const VisualiserContext& ctx) const override {
    const Attribute a = attributeOf(ctx.out.desc);
    int& mode = modes()[&ctx.view];
    ImGui::Combo("show", &mode, kModes[int(a)], modeCount(a));
    if (!ctx.out.levels.empty())
      ImGui::Text("%d layers side by side, each %d texels wide at level 0", layersOf(ctx.out.levels[0]),
                  ctx.out.levels[0].size.y);
    ImageVisualiser::drawInspector(ctx);
  }

 private:
  static float sigmaAt(const LevelData& L, float alpha, int x, int y) {
    if (alpha <= 0.0f) return 0.0f;
    const float mu = L.at(x, y, 0, 0) / alpha;
    return std::sqrt(std::max(L.at(x, y, 0, 1) / alpha - mu * mu, 0.0f));
  }
};

// Layer ids: a distinct colour per layer (hue by id), black where the RSM sees nothing (255).
void layerIdColour(const float* v, int, float, float, float, uint8_t* o) {
  const int id = int(v[0]);
  if (id >= 255 || id < 0) { o[0] = o[1] = o[2] = 0; return; }
  static const uint8_t palette[8][3] = {{230, 80, 60}, {60, 160, 230}, {240, 200, 60}, {90, 200, 100},
                                        {180, 90, 220}, {240, 140, 40}, {60, 210, 200}, {220, 220, 220}};
  const uint8_t* c = palette[id % 8];
  const float shade = id < 8 ? 1.0f : 0.6f;  // ids 8..15 repeat the palette darker
  for (int k = 0; k < 3; ++k) o[k] = uint8_t(float(c[k]) * shade);
}

// The files `voxlab run` writes (PNG per level) show what the default 2D view shows: A*R
// tonemapped, the mean normal n / alpha, alpha mu = alpha E[z'] in grey (the moments hold no alpha
// of their own); black where a layer is empty.
void layerRadianceColour(const float* v, int n, float x, float, float, uint8_t* o) {
  for (int k = 0; k < 3; ++k) {
    const float y = (k < n ? v[k] : 0.0f) * x;
    o[k] = unitToByte(srgbEncode(y / (1.0f + y)));
  }
}
void layerNormalColour(const float* v, int n, float, float, float, uint8_t* o) {
  const float a = n >= 4 ? v[3] : 0.0f;
  for (int k = 0; k < 3; ++k) o[k] = a > 0.0f ? unitToByte(v[k] / a * 0.5f + 0.5f) : 0;
}
void layerDepthColour(const float* v, int n, float, float, float, uint8_t* o) {
  o[0] = o[1] = o[2] = n >= 1 ? unitToByte(v[0]) : 0;
}

struct Registration {
  Registration() {
    registerTexelMapping(kLayerId, {&layerIdColour, false, false, true});
    registerTexelMapping(kLayerRadiance, {&layerRadianceColour, false, false, false});
    registerTexelMapping(kLayerNormal, {&layerNormalColour, false, false, false});
    registerTexelMapping(kLayerDepth, {&layerDepthColour, false, false, false});
  }
} registration;

}  // namespace

VOXLAB_REGISTER_VISUALISER(LayerAtlasVisualiser, OutputKind::Image2D, kLayerRadiance.name());
VOXLAB_REGISTER_VISUALISER(LayerAtlasVisualiser, OutputKind::Image2D, kLayerNormal.name());
VOXLAB_REGISTER_VISUALISER(LayerAtlasVisualiser, OutputKind::Image2D, kLayerDepth.name());

}  // namespace voxlab
