// The per-layer gather of one probed pixel (lrsm's cone-gather stage, LrsmGatherRecord in
// shaders/lrsm/lrsm_shared.h): one record per (cone, sphere sample, layer) with every term of
// Algorithm 1. The record view groups them by cone and sample: the sample's centre, radius, voxel
// mip, alpha and transmittance, its RSM footprint and LRSM mip, then per layer in range, f, N, mu,
// sigma^2, V, A*R and the contribution. The check asserts what the gather must keep: f, V, alpha
// and transmittance in [0,1], sigma^2 >= 0, transmittance non-increasing along a cone, and each
// contribution = f * A*R * V * N * J of its own terms (J: the coverage estimator's Jacobian
// 1 / <n.l>, 1 for Algorithm 1 as printed).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <vector>

#include <imgui.h>

#include "inspect/visualisers/buffer.h"
#include "techniques/lrsm/stages.h"

namespace voxlab {
namespace {

struct GatherRecord {
  float v[8][4];
};

std::vector<GatherRecord> decode(const CapturedOutput& out) { return recordsAs<GatherRecord>(out); }

enum { kCentre, kCone, kMarch, kLayer, kMoments, kCoverage, kContribution, kFootprint };

class GatherVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "lrsm-gather"; }

  RecordCheck checkRecords(const CapturedOutput& out) const override {
    RecordCheck c;
    const auto recs = decode(out);
    c.elements = recs.size();
    std::map<int, float> lastT;
    int inRange = 0, contributing = 0;
    auto within = [](float x) { return x >= 0.0f && x <= 1.0f; };
    for (size_t i = 0; i < recs.size() && c.error.empty(); ++i) {
      const auto& r = recs[i].v;
      const int cone = int(r[kCone][0]);
      const float f = r[kLayer][2], N = r[kLayer][3], V = r[kMoments][2], T = r[kMarch][0];
      char buf[160];
      if (!within(f) || !within(V) || !within(r[kCone][3]) || !within(T) || r[kMoments][1] < 0.0f) {
        std::snprintf(buf, sizeof buf, "record %zu: f %.4g, V %.4g, alpha %.4g, T %.4g or sigma^2 %.4g out of range", i, f, V,
                      r[kCone][3], T, r[kMoments][1]);
        c.error = buf;
      }
      auto it = lastT.find(cone);
      if (it != lastT.end() && T > it->second + 1e-6f) {
        std::snprintf(buf, sizeof buf, "record %zu: transmittance rises along cone %d (%.5f after %.5f)", i, cone, T, it->second);
        c.error = buf;
      }
      lastT[cone] = T;
      for (int k = 0; k < 3; ++k) {
        const float J = r[kFootprint][2];
        const float expect = (r[kLayer][1] > 0.5f && N > 0.0f && V > 0.0f) ? f * r[kCoverage][k] * V * N * J : 0.0f;
        // fp32 products of the same five factors in another order: a few ulps.
        if (std::fabs(r[kContribution][k] - expect) > 1e-5f * std::max(1.0f, std::fabs(expect))) {
          std::snprintf(buf, sizeof buf, "record %zu: contribution %.6g is not f * A*R * V * N * J = %.6g", i,
                        r[kContribution][k], expect);
          c.error = buf;
        }
      }
      inRange += r[kLayer][1] > 0.5f;
      contributing += r[kContribution][0] + r[kContribution][1] + r[kContribution][2] > 0.0f;
    }
    c.summary = std::to_string(recs.size()) + " layer records, " + std::to_string(inRange) + " in range, " +
                std::to_string(contributing) + " contributing";
    return c;
  }

  void drawRecordView(const VisualiserContext& ctx) const override {
    const auto recs = decode(ctx.out);
    RecordCheck check = checkRecords(ctx.out);
    ImGui::Text("%s", check.summary.c_str());
    if (!check.error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", check.error.c_str());
    size_t i = 0;
    while (i < recs.size()) {
      const int cone = int(recs[i].v[kCone][0]);
      size_t end = i;
      while (end < recs.size() && int(recs[end].v[kCone][0]) == cone) ++end;
      char title[64];
      std::snprintf(title, sizeof title, "cone %d (%zu layer records)", cone, end - i);
      if (ImGui::TreeNode(title)) {
        size_t j = i;
        while (j < end) {
          const int sample = int(recs[j].v[kCone][1]);
          size_t sEnd = j;
          while (sEnd < end && int(recs[sEnd].v[kCone][1]) == sample) ++sEnd;
          const auto& r = recs[j].v;
          char head[256];
          std::snprintf(head, sizeof head,
                        "sample %d: x_c (%.3f, %.3f, %.3f) r_c %.3f, voxel mip %.2f, alpha %.3f, T %.3f, uv (%.3f, %.3f), "
                        "d_circle %.2f, LRSM level %.2f, z_c %.3f", sample, r[kCentre][0], r[kCentre][1], r[kCentre][2],
                        r[kCentre][3], r[kCone][2], r[kCone][3], r[kMarch][0], r[kMarch][1], r[kMarch][2],
                        r[kFootprint][0], r[kMarch][3], r[kFootprint][1]);
          if (ImGui::TreeNode((void*)(intptr_t)(j + 1), "%s", head)) {
            if (ImGui::BeginTable("layers", 10, ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg)) {
              for (const char* h : {"layer", "in range", "f", "N", "mu", "sigma^2", "z'", "V", "A*R", "contribution"})
                ImGui::TableSetupColumn(h);
              ImGui::TableHeadersRow();
              for (size_t k = j; k < sEnd; ++k) {
                const auto& q = recs[k].v;
                ImGui::TableNextRow();
                const float vals[8] = {q[kLayer][0], q[kLayer][1], q[kLayer][2], q[kLayer][3],
                                       q[kMoments][0], q[kMoments][1], q[kMoments][3], q[kMoments][2]};
                for (int c = 0; c < 8; ++c) {
                  ImGui::TableNextColumn();
                  ImGui::Text(c < 2 ? "%.0f" : "%.4g", vals[c]);
                }
                ImGui::TableNextColumn();
                ImGui::Text("%.3g %.3g %.3g", q[kCoverage][0], q[kCoverage][1], q[kCoverage][2]);
                ImGui::TableNextColumn();
                ImGui::Text("%.3g %.3g %.3g", q[kContribution][0], q[kContribution][1], q[kContribution][2]);
              }
              ImGui::EndTable();
            }
            ImGui::TreePop();
          }
          j = sEnd;
        }
        ImGui::TreePop();
      }
      i = end;
    }
  }
};

}  // namespace

VOXLAB_REGISTER_VISUALISER(GatherVisualiser, OutputKind::Buffer, lrsm::kGatherRecords.name());

}  // namespace voxlab
