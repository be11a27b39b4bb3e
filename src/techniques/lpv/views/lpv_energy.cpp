// The per-step energy record of lpv's propagation (semantic "lpv-energy": records LpvEnergy, record
// step * 2 + cascade; wavefront = flux that moved in that step, step 0 = the injected VPLs; total =
// flux of the grid the lookup reads after it).
//
// 2D view and the `.plot.png` file: flux per step on a log scale, the wavefront as the bright line
// and the total as the dim one, fine cascade orange, coarse blue. What a student reads off it: the
// first step of a clamped lobe gains about 14 % (the back lobe clamped away), the wavefront scheme
// then decays as occlusion and the grid's edges take light out, and the thesis scheme's total grows
// geometrically, (I + P)^k. Statistics: per cascade the wavefront and total flux per step (rgb
// summed, W), the first step's gain (wavefront 1 / wavefront 0) and the last step's growth of the
// total. Inspector: the same as plots and a table.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <imgui.h>

#include "inspect/visualisers/buffer.h"
#include "lpv/lpv_shared.h"
#include "techniques/lpv/stages.h"

namespace voxlab {
namespace {

using lpv::gpu::LpvEnergy;
constexpr int kCascades = 2;

struct Series {
  std::vector<float> wave[kCascades], total[kCascades];
  int steps = 0;  // records per cascade
};

Series decode(const CapturedOutput& out) {
  Series s;
  if (out.desc.layout.stride != sizeof(LpvEnergy)) return s;
  size_t n = std::min<size_t>(out.recordCount, out.records.size() / sizeof(LpvEnergy));
  s.steps = int(n / kCascades);
  for (int k = 0; k < s.steps; ++k)
    for (int c = 0; c < kCascades; ++c) {
      LpvEnergy e;
      std::memcpy(&e, &out.records[(size_t(k) * kCascades + c) * sizeof e], sizeof e);
      s.wave[c].push_back(e.wavefront.x + e.wavefront.y + e.wavefront.z);
      s.total[c].push_back(e.total.x + e.total.y + e.total.z);
    }
  return s;
}

// RGB plot, top row first.
DisplayImage plot(const Series& s, int width = 320, int height = 200) {
  DisplayImage img;
  img.width = width, img.height = height;
  img.rgb.assign(size_t(width) * height * 3, 20);
  float hi = 0.0f;
  for (int c = 0; c < kCascades; ++c)
    for (int k = 0; k < s.steps; ++k) hi = std::max({hi, s.wave[c][k], s.total[c][k]});
  const float decades = 6.0f, margin = 8.0f;
  auto px = [&](int k) { return margin + (width - 2 * margin) * (s.steps > 1 ? float(k) / float(s.steps - 1) : 0.5f); };
  auto py = [&](float v) {
    float t = v > 0.0f && hi > 0.0f ? std::clamp(1.0f + std::log10(v / hi) / decades, 0.0f, 1.0f) : 0.0f;
    return margin + (height - 2 * margin) * (1.0f - t);
  };
  auto dot = [&](float x, float y, const uint8_t* rgb) {
    int ix = int(std::lround(x)), iy = int(std::lround(y));
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        int X = ix + dx, Y = iy + dy;
        if (X < 0 || Y < 0 || X >= width || Y >= height) continue;
        std::memcpy(&img.rgb[(size_t(Y) * width + X) * 3], rgb, 3);
      }
  };
  auto line = [&](const std::vector<float>& v, const uint8_t* rgb) {
    for (int k = 0; k + 1 < s.steps; ++k)
      for (int i = 0; i <= 32; ++i) {
        float t = float(i) / 32.0f;
        dot(px(k) + t * (px(k + 1) - px(k)), py(v[k]) + t * (py(v[k + 1]) - py(v[k])), rgb);
      }
    for (int k = 0; k < s.steps; ++k) dot(px(k), py(v[k]), rgb);
  };
  // Grid: one line per decade, one per step.
  for (int d = 0; d <= int(decades); ++d) {
    int y = int(margin + (height - 2 * margin) * float(d) / decades);
    for (int x = 0; x < width; ++x) img.rgb[(size_t(y) * width + x) * 3 + 1] = 60;
  }
  for (int k = 0; k < s.steps; ++k) {
    int x = int(px(k));
    for (int y = 0; y < height; ++y) img.rgb[(size_t(y) * width + x) * 3 + 2] = 60;
  }
  const uint8_t colours[kCascades][2][3] = {{{255, 150, 40}, {130, 80, 30}}, {{70, 150, 255}, {40, 80, 140}}};
  for (int c = 0; c < kCascades; ++c) {
    line(s.total[c], colours[c][1]);
    line(s.wave[c], colours[c][0]);
  }
  return img;
}

class LpvEnergyVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "lpv-energy"; }

  nlohmann::json statistics(const CapturedOutput& out) const override {
    nlohmann::json st = BufferVisualiser::statistics(out);
    Series s = decode(out);
    nlohmann::json per = nlohmann::json::object();
    for (int c = 0; c < kCascades && s.steps > 0; ++c) {
      nlohmann::json j = {{"wavefront", s.wave[c]}, {"total", s.total[c]}};
      if (s.steps > 1 && s.wave[c][0] > 0.0f) j["first_step_gain"] = s.wave[c][1] / s.wave[c][0];
      if (s.steps > 1 && s.total[c][s.steps - 2] > 0.0f)
        j["last_step_growth"] = s.total[c][s.steps - 1] / s.total[c][s.steps - 2];
      per[c == 0 ? "fine" : "coarse"] = j;
    }
    st["flux_per_step"] = per;
    return st;
  }

  nlohmann::json writeFiles(const CapturedOutput& out, const std::string& dir, const std::string& prefix) const override {
    nlohmann::json entry = BufferVisualiser::writeFiles(out, dir, prefix);
    Series s = decode(out);
    if (s.steps > 0) {
      entry["files"].push_back(prefix + ".plot.png");
      writePng(plot(s), dir + "/" + prefix + ".plot.png");
    }
    return entry;
  }

  SliceImage image2D(const VisualiserContext& ctx) const override {
    SliceImage img;
    Series s = decode(ctx.out);
    if (s.steps == 0) return img;
    DisplayImage p = plot(s);
    img.width = p.width, img.height = p.height;
    img.rgba.resize(size_t(p.width) * p.height * 4, 255);
    for (size_t i = 0; i < size_t(p.width) * p.height; ++i) std::memcpy(&img.rgba[i * 4], &p.rgb[i * 3], 3);
    return img;
  }

  std::string caption(const VisualiserContext&) const override {
    return "flux per step, log scale (6 decades): bright = wavefront, dim = total; orange fine, blue coarse";
  }

  void drawInspector(const VisualiserContext& ctx) const override {
    Series s = decode(ctx.out);
    for (int c = 0; c < kCascades && s.steps > 0; ++c) {
      const char* name = c == 0 ? "fine" : "coarse";
      ImGui::Text("%s cascade", name);
      ImGui::PlotLines((std::string("wavefront##") + name).c_str(), s.wave[c].data(), s.steps, 0, nullptr, 0.0f,
                       FLT_MAX, ImVec2(0, 60));
      ImGui::PlotLines((std::string("total##") + name).c_str(), s.total[c].data(), s.steps, 0, nullptr, 0.0f, FLT_MAX,
                       ImVec2(0, 60));
    }
    if (s.steps > 0 && ImGui::BeginTable("lpv-energy", 5, ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg)) {
      for (const char* h : {"step", "fine wavefront", "fine total", "coarse wavefront", "coarse total"})
        ImGui::TableSetupColumn(h);
      ImGui::TableHeadersRow();
      for (int k = 0; k < s.steps; ++k) {
        ImGui::TableNextRow();
        ImGui::TableNextColumn(); ImGui::Text("%d", k);
        for (int c = 0; c < kCascades; ++c) {
          float ratio = k > 0 && s.wave[c][k - 1] > 0.0f ? s.wave[c][k] / s.wave[c][k - 1] : 0.0f;
          ImGui::TableNextColumn(); ImGui::Text("%.4g (x%.3f)", s.wave[c][k], ratio);
          ImGui::TableNextColumn(); ImGui::Text("%.4g", s.total[c][k]);
        }
      }
      ImGui::EndTable();
    }
    BufferVisualiser::drawInspector(ctx);
  }
};

}  // namespace

VOXLAB_REGISTER_VISUALISER(LpvEnergyVisualiser, OutputKind::Buffer, lpv::kLpvEnergy.name());

}  // namespace voxlab
