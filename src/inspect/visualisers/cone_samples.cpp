// Cone samples: the probe record of a cone tracer (vct-grid's cone-trace declares one). 2D and
// table: the buffer visualiser's; 3D: one disc per sample (its diameter, coloured by accumulated
// opacity) and each cone's axis, inside the latest volume (its level 0 as context); record view:
// per cone, the mip level, accumulated opacity and luminance along the cone; check: samples exist
// and each accumulated opacity is the previous one composited front to back with the sample's
// alpha (checkFrontToBackCompositing).
#include "inspect/visualisers/cone_samples.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <sstream>

#include <imgui.h>

#include "common/shared.h"
#include "inspect/view3d.h"
#include "inspect/visualisers/buffer.h"

namespace voxlab {

std::vector<ConeSeries> decodeConeSamples(const CapturedOutput& out) {
  std::vector<ConeSeries> cones;
  uint32_t stride = out.desc.layout.stride ? out.desc.layout.stride : uint32_t(sizeof(gpu::ConeSample));
  if (stride < sizeof(gpu::ConeSample)) return cones;
  std::map<int, size_t> index;
  for (uint32_t r = 0; r < out.recordCount && size_t(r + 1) * stride <= out.records.size(); ++r) {
    gpu::ConeSample s;
    std::memcpy(&s, &out.records[size_t(r) * stride], sizeof s);
    int cone = int(s.info.x);
    auto it = index.find(cone);
    if (it == index.end()) {
      it = index.emplace(cone, cones.size()).first;
      cones.push_back({});
      cones.back().cone = cone;
    }
    ConeSeries& c = cones[it->second];
    c.distance.push_back(s.info.y);
    c.lod.push_back(s.info.z);
    c.sampleAlpha.push_back(s.info.w);
    c.diameter.push_back(s.position.w);
    c.opacity.push_back(s.accumulated.w);
    c.luminance.push_back(0.2126f * s.accumulated.x + 0.7152f * s.accumulated.y + 0.0722f * s.accumulated.z);
    c.position.push_back(glm::vec3(s.position.x, s.position.y, s.position.z));
  }
  // Records are appended by parallel invocations; order each cone by distance along it.
  for (auto& c : cones) {
    std::vector<size_t> order(c.distance.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return c.distance[a] < c.distance[b]; });
    auto perm = [&](std::vector<float>& v) {
      std::vector<float> r(v.size());
      for (size_t i = 0; i < order.size(); ++i) r[i] = v[order[i]];
      v.swap(r);
    };
    perm(c.distance), perm(c.lod), perm(c.opacity), perm(c.luminance), perm(c.diameter), perm(c.sampleAlpha);
    std::vector<glm::vec3> pos(c.position.size());
    for (size_t i = 0; i < order.size(); ++i) pos[i] = c.position[order[i]];
    c.position.swap(pos);
  }
  std::sort(cones.begin(), cones.end(), [](const ConeSeries& a, const ConeSeries& b) { return a.cone < b.cone; });
  return cones;
}

std::string checkFrontToBackCompositing(const std::vector<ConeSeries>& cones) {
  for (const auto& c : cones) {
    float before = 0.0f;
    for (size_t i = 0; i < c.opacity.size(); ++i) {
      std::ostringstream o;
      o << "cone " << c.cone << ", sample " << i << " (distance " << c.distance[i] << "): ";
      const float a = c.sampleAlpha[i];
      if (i > 0 && !(c.distance[i] > c.distance[i - 1])) {
        o << "distance does not increase (previous " << c.distance[i - 1] << ")";
        return o.str();
      }
      if (!(a >= 0.0f && a <= 1.0f)) {
        o << "sample alpha " << a << " is outside 0..1";
        return o.str();
      }
      const float expected = before + (1.0f - before) * a;
      if (!(std::fabs(c.opacity[i] - expected) <= kCompositingTolerance)) {
        o << "accumulated opacity " << c.opacity[i] << ", but " << before << " composited front to back with alpha "
          << a << " is " << expected;
        return o.str();
      }
      before = c.opacity[i];
    }
  }
  return "";
}

namespace {

// The opacity at which a cone counts as stopped by what it hit (the tracers stop at or just
// under 1: vct-grid at 0.99).
constexpr float kOpaqueEnough = 0.99f;

// Accumulated opacity 0 -> 1 as blue -> magenta -> orange -> yellow.
glm::vec3 opacityColour(float a) {
  static const glm::vec3 stops[4] = {{0.15f, 0.45f, 1.0f}, {0.85f, 0.25f, 0.85f}, {1.0f, 0.55f, 0.15f}, {1.0f, 0.95f, 0.3f}};
  float t = std::clamp(a, 0.0f, 1.0f) * 3.0f;
  int i = std::min(int(t), 2);
  return glm::mix(stops[i], stops[i + 1], t - float(i));
}

class ConeSamplesVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "cone-samples"; }
  bool has3D(const OutputDesc&) const override { return true; }

  Content3D build3D(const VisualiserContext& ctx, View3D& view) const override {
    Content3D c;
    std::vector<ConeSeries> cones = decodeConeSamples(ctx.out);
    // World positions -> texels of the context volume's level 0, through its world placement.
    CapturedOutput volume;
    std::string volumeName;
    std::function<glm::vec3(glm::vec3)> toView = [](glm::vec3 p) { return p; };
    float scale = 1.0f;
    bool haveVolume = ctx.contextVolume && ctx.contextVolume(volume, volumeName) && volume.world && !volume.levels.empty();
    if (haveVolume) {
      c.hi = glm::vec3(volume.levels[0].size);
      const glm::vec3 origin = volume.world->lo, texelsPerMetre = c.hi / (volume.world->hi - volume.world->lo);
      toView = [origin, texelsPerMetre](glm::vec3 p) { return (p - origin) * texelsPerMetre; };
      scale = texelsPerMetre.x;
      view.setVolume(mapVolume(volume.levels[0], volume.desc.semantic, DisplaySettings{}), c.hi, 0.3f);
    }
    std::vector<ViewInstance> spheres, lines;
    glm::vec3 plo(1e30f), phi(-1e30f);
    size_t samples = 0;
    for (const auto& cone : cones) {
      if (cone.position.empty()) continue;
      for (size_t i = 0; i < cone.position.size(); ++i) {
        glm::vec3 p = toView(cone.position[i]);
        float r = 0.5f * cone.diameter[i] * scale;
        spheres.push_back({glm::vec4(p, r), glm::vec4(opacityColour(cone.opacity[i]), 0.28f)});
        plo = glm::min(plo, p - r);
        phi = glm::max(phi, p + r);
        ++samples;
      }
      // The cone's axis: from its apex (first sample minus its distance) through the last sample.
      glm::vec3 first = cone.position.front(), last = cone.position.back();
      glm::vec3 dir = glm::length(last - first) > 1e-6f ? glm::normalize(last - first) : glm::vec3(0, 0, 1);
      glm::vec3 apex = first - dir * cone.distance.front();
      lines.push_back({glm::vec4(toView(apex), 0), glm::vec4(1.0f)});
      lines.push_back({glm::vec4(toView(last), 0), glm::vec4(1.0f)});
    }
    view.setSpheres(std::move(spheres));
    view.setLines(std::move(lines));
    if (!haveVolume) {
      c.lo = samples ? plo : glm::vec3(0.0f);
      c.hi = samples ? phi : glm::vec3(1.0f);
    }
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "%zu cones, %zu samples: disc = sample diameter, colour = accumulated opacity (blue 0, yellow 1)%s%s",
                  cones.size(), samples, haveVolume ? "; context: " : "", haveVolume ? (volumeName + " level 0").c_str() : "");
    c.info = buf;
    if (samples == 0) c.message = "no cone samples recorded: probe a pixel first";
    return c;
  }

  void drawRecordView(const VisualiserContext& ctx) const override {
    std::vector<ConeSeries> cones = decodeConeSamples(ctx.out);
    RecordCheck check = checkRecords(ctx.out);
    ImGui::Text("%s", check.summary.c_str());
    if (!check.error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", check.error.c_str());
    for (const auto& c : cones) {
      if (c.distance.empty()) continue;
      // The aperture follows from any sample: diameter = 2 * distance * tan(aperture / 2).
      const float aperture = c.distance.back() > 0.0f
                                 ? 2.0f * std::atan(0.5f * c.diameter.back() / c.distance.back()) * 57.29578f
                                 : 0.0f;
      const glm::vec3 axis = c.position.size() > 1 && glm::length(c.position.back() - c.position.front()) > 1e-6f
                                 ? glm::normalize(c.position.back() - c.position.front())
                                 : glm::vec3(0.0f);
      char title[160];
      std::snprintf(title, sizeof title, "cone %d: direction (%.3g, %.3g, %.3g), %.3g deg, %zu samples, to %.3g m", c.cone,
                    axis.x, axis.y, axis.z, aperture, c.distance.size(), c.distance.back());
      if (!ImGui::TreeNodeEx(title, ImGuiTreeNodeFlags_DefaultOpen)) continue;
      // What stopped it: an opaque sample, or the end of its path (the volume's edge or its maximum distance).
      const bool opaque = c.opacity.back() >= kOpaqueEnough;
      ImGui::TextWrapped("gathered luminance %.4g, opacity %.3g; stopped %s at %.4g m", c.luminance.back(),
                         c.opacity.back(), opaque ? "by an opaque sample" : "at the end of its path (the volume's edge, "
                         "its maximum distance, or a shadow cone's end short of the light)", c.distance.back());
      drawAxesPlot("lod", c.distance, c.lod, "distance [m]", "mip level", 0.0f, NAN);
      drawAxesPlot("opacity", c.distance, c.opacity, "distance [m]", "accumulated opacity", 0.0f, 1.0f);
      drawAxesPlot("radiance", c.distance, c.luminance, "distance [m]", "accumulated luminance [W/m^2/sr]", 0.0f, NAN);
      ImGui::TreePop();
    }
  }

  RecordCheck checkRecords(const CapturedOutput& out) const override {
    std::vector<ConeSeries> cones = decodeConeSamples(out);
    RecordCheck r;
    for (const auto& c : cones) r.elements += c.distance.size();
    r.summary = std::to_string(cones.size()) + " cones, " + std::to_string(r.elements) + " samples";
    r.error = checkFrontToBackCompositing(cones);
    if (r.error.empty() && r.elements > 0) r.summary += ", composited front to back along every cone";
    return r;
  }
};

}  // namespace

VOXLAB_REGISTER_VISUALISER(ConeSamplesVisualiser, OutputKind::Buffer, Semantic::ConeSamples.name());

}  // namespace voxlab
