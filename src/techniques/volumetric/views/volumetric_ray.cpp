// The probed camera ray of the volumetric technique (its march stage, RaySample in
// shaders/volumetric/volumetric_shared.h): one record per march sample, with its position and
// dither offset, lit or shadowed, sigma_s, sigma_t, particle count, mu, p(mu), the light's
// irradiance E, the transmittance T, its contribution T sigma_s p E V dt and the running sum.
// The record view plots contribution, T and the running sum along the ray over the table; the
// check asserts what the march must keep: T in [0, 1] and never rising along the ray, lit 0 or 1,
// each contribution (luminance) = T sigma_s p E lit dt of its own terms, and the running sum the
// sum of the contributions so far. Positions are density-grid voxels, so the point and 3D views
// place the samples in the density volume.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include <imgui.h>

#include "inspect/visualisers/buffer.h"
#include "techniques/volumetric/stages.h"

namespace voxlab {
namespace {

struct RayRecord {
  float voxel[4], world[4], medium[4], phase[4], contribution[4];
};

std::vector<RayRecord> decode(const CapturedOutput& out) { return recordsAs<RayRecord>(out); }

float luminance(const float* c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

class VolumetricRayVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "volumetric-ray"; }

  RecordCheck checkRecords(const CapturedOutput& out) const override {
    RecordCheck c;
    const auto recs = decode(out);
    c.elements = recs.size();
    const float dt = recs.size() >= 2 ? recs[1].voxel[3] - recs[0].voxel[3] : 0.0f;
    float running = 0.0f, lastT = 1.0f;
    int lit = 0;
    char buf[200];
    for (size_t i = 0; i < recs.size() && c.error.empty(); ++i) {
      const RayRecord& r = recs[i];
      const float T = r.phase[3], V = r.medium[0];
      if (!(T >= 0.0f && T <= 1.0f) || (V != 0.0f && V != 1.0f)) {
        std::snprintf(buf, sizeof buf, "sample %zu: T %.5g not in [0, 1] or lit %.5g not 0/1", i, T, V);
        c.error = buf;
        break;
      }
      // T_i = exp(-(optical depth before i + sigma_t(x_i) u dt)): float rounding of exp only.
      if (T > lastT * (1.0f + 1e-5f)) {
        std::snprintf(buf, sizeof buf, "sample %zu: transmittance rises along the ray (%.6f after %.6f)", i, T, lastT);
        c.error = buf;
      }
      lastT = T;
      // The shader forms T sigma_s p E V dt in rgb then its luminance; recomputing it from the
      // recorded luminance of E differs by fp32 rounding of the reordered products (a few ulps).
      const float got = luminance(r.contribution);
      if (dt > 0.0f) {
        const float expect = T * r.medium[1] * r.phase[1] * r.phase[2] * V * dt;
        if (std::fabs(got - expect) > 1e-4f * std::max(std::fabs(expect), 1e-6f) + 1e-9f) {
          std::snprintf(buf, sizeof buf, "sample %zu: contribution %.6g is not T sigma_s p E lit dt = %.6g", i, got, expect);
          c.error = buf;
        }
      }
      running += got;
      // The running sum is accumulated in rgb (fp32) over up to 256 samples: 1e-4 relative covers it.
      if (std::fabs(r.contribution[3] - running) > 1e-4f * std::max(running, 1e-6f) + 1e-9f) {
        std::snprintf(buf, sizeof buf, "sample %zu: running sum %.6g is not the sum of the contributions %.6g", i,
                      r.contribution[3], running);
        c.error = buf;
      }
      lit += V > 0.5f;
    }
    std::snprintf(buf, sizeof buf, "%zu samples (%d lit), dt %.4g m, T at the last sample %.4f, L_in (luminance) %.4g",
                  recs.size(), lit, dt, recs.empty() ? 1.0f : recs.back().phase[3],
                  recs.empty() ? 0.0f : recs.back().contribution[3]);
    c.summary = buf;
    return c;
  }

  void drawRecordView(const VisualiserContext& ctx) const override {
    const auto recs = decode(ctx.out);
    const RecordCheck check = checkRecords(ctx.out);
    ImGui::Text("%s", check.summary.c_str());
    if (!check.error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", check.error.c_str());
    if (recs.empty()) return;
    std::vector<float> contribution, transmittance, sum;
    for (const RayRecord& r : recs) {
      contribution.push_back(luminance(r.contribution));
      transmittance.push_back(r.phase[3]);
      sum.push_back(r.contribution[3]);
    }
    const float w = ImGui::GetContentRegionAvail().x;
    ImGui::PlotHistogram("contribution", contribution.data(), int(contribution.size()), 0, "per sample (luminance)",
                         0.0f, FLT_MAX, ImVec2(w * 0.7f, 80));
    ImGui::PlotLines("T", transmittance.data(), int(transmittance.size()), 0, "transmittance", 0.0f, 1.0f,
                     ImVec2(w * 0.7f, 60));
    ImGui::PlotLines("sum", sum.data(), int(sum.size()), 0, "running sum", 0.0f, FLT_MAX, ImVec2(w * 0.7f, 60));
    if (ImGui::BeginTable("ray", 10, ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg | ImGuiTableFlags_ScrollY,
                          ImVec2(0, 260))) {
      for (const char* h : {"i", "t (m)", "offset u", "lit", "sigma_s", "count", "mu", "p(mu)", "T", "contribution"})
        ImGui::TableSetupColumn(h);
      ImGui::TableHeadersRow();
      for (size_t i = 0; i < recs.size(); ++i) {
        const RayRecord& r = recs[i];
        ImGui::TableNextRow();
        const float vals[9] = {float(i), r.voxel[3], r.world[3], r.medium[0], r.medium[1], r.medium[3], r.phase[0], r.phase[1], r.phase[3]};
        for (int k = 0; k < 9; ++k) {
          ImGui::TableNextColumn();
          ImGui::Text(k == 0 || k == 3 || k == 5 ? "%.0f" : "%.4g", vals[k]);
        }
        ImGui::TableNextColumn();
        ImGui::Text("%.3g", luminance(r.contribution));
      }
      ImGui::EndTable();
    }
  }
};

}  // namespace

VOXLAB_REGISTER_VISUALISER(VolumetricRayVisualiser, OutputKind::Buffer, volumetric::kRaySamples.name());

}  // namespace voxlab
