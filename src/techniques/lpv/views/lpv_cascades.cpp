// lpv's cascade boxes (semantic "lpv-cascades": LpvBox records from the gi stage: the fine and the
// coarse cascade's snapped boxes and the blend shell, inner box = coarse weight 0, outer box =
// coarse weight 1). Golden: the records, exact (they are snapped to cell multiples).
//
// 3D: the four boxes in world space over the latest volume before the gi stage (placed by its
// world box, as the scene overlay places volumes): orange fine, blue coarse, the shell's two boxes
// grey. A 2D view from above (x right, z down): the boxes' outlines over the context volume's
// occupied columns, so the shell can be read against the scene's footprint.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <imgui.h>

#include "inspect/view3d.h"
#include "inspect/visualisers/buffer.h"
#include "lpv/lpv_shared.h"
#include "techniques/lpv/stages.h"

namespace voxlab {
namespace {

using lpv::gpu::LpvBox;

std::vector<LpvBox> decode(const CapturedOutput& out) { return recordsAs<LpvBox>(out); }

glm::vec4 colourOf(int kind) {
  switch (kind) {
    case 0: return {1.0f, 0.6f, 0.15f, 1.0f};
    case 1: return {0.3f, 0.55f, 1.0f, 1.0f};
    default: return {0.7f, 0.7f, 0.7f, 0.8f};
  }
}
const char* kindName(int kind) {
  static const char* names[4] = {"fine cascade", "coarse cascade", "blend shell start (coarse 0)", "blend shell end (coarse 1)"};
  return names[std::clamp(kind, 0, 3)];
}

class LpvCascadesVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "lpv-cascades"; }
  CaptureTier defaultTier(const OutputDesc&) const override { return CaptureTier::Exact; }

  nlohmann::json statistics(const CapturedOutput& out) const override {
    nlohmann::json s = BufferVisualiser::statistics(out);
    nlohmann::json boxes = nlohmann::json::array();
    for (const auto& b : decode(out))
      boxes.push_back({{"box", kindName(int(b.lo.w))},
                       {"lo", {b.lo.x, b.lo.y, b.lo.z}},
                       {"hi", {b.hi.x, b.hi.y, b.hi.z}},
                       {"cell_m", b.hi.w}});
    s["boxes"] = boxes;
    return s;
  }

  bool has3D(const OutputDesc&) const override { return true; }

  Content3D build3D(const VisualiserContext& ctx, View3D& view) const override {
    Content3D c;
    std::vector<LpvBox> boxes = decode(ctx.out);
    if (boxes.empty()) {
      c.message = "no boxes: run the gi stage first";
      return c;
    }
    // View units: texels of the context volume when it has a world placement, else fine cells
    // from the coarse box's corner.
    glm::vec3 origin(boxes.size() > 1 ? boxes[1].lo : boxes[0].lo), unit(boxes[0].hi.w);
    CapturedOutput volume;
    std::string name;
    if (ctx.contextVolume && ctx.contextVolume(volume, name) && volume.world && !volume.levels.empty()) {
      origin = volume.world->lo;
      unit = (volume.world->hi - volume.world->lo) / glm::vec3(volume.levels[0].size);
      view.setVolume(mapVolume(volume.levels[0], volume.desc.semantic, DisplaySettings{}),
                     glm::vec3(volume.levels[0].size), 0.3f);
      c.info = "over " + name + "; ";
    }
    std::vector<ViewInstance> lines;
    c.lo = glm::vec3(1e30f), c.hi = glm::vec3(-1e30f);
    for (const auto& b : boxes) {
      glm::vec3 lo = (glm::vec3(b.lo) - origin) / unit, hi = (glm::vec3(b.hi) - origin) / unit;
      appendBoxEdges(lines, lo, hi, colourOf(int(b.lo.w)));
      c.lo = glm::min(c.lo, lo), c.hi = glm::max(c.hi, hi);
    }
    view.setLines(std::move(lines));
    c.info += "orange fine cascade, blue coarse, grey the blend shell (coarse weight 0 inside, 1 outside)";
    return c;
  }

  SliceImage image2D(const VisualiserContext& ctx) const override {
    SliceImage img;
    std::vector<LpvBox> boxes = decode(ctx.out);
    if (boxes.empty()) return img;
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const auto& b : boxes) lo = glm::min(lo, glm::vec3(b.lo)), hi = glm::max(hi, glm::vec3(b.hi));
    const int size = 384;
    const float scale = float(size - 1) / std::max(hi.x - lo.x, hi.z - lo.z);
    img.width = img.height = size;
    img.rgba.assign(size_t(size) * size * 4, 255);
    for (size_t i = 0; i < size_t(size) * size; ++i) img.rgba[i * 4] = img.rgba[i * 4 + 1] = img.rgba[i * 4 + 2] = 16;
    // The context volume's occupied columns (any non-empty texel along y), grey.
    CapturedOutput volume;
    std::string name;
    if (ctx.contextVolume && ctx.contextVolume(volume, name) && volume.world && !volume.levels.empty()) {
      const LevelData& L = volume.levels[0];
      glm::vec3 texel = (volume.world->hi - volume.world->lo) / glm::vec3(L.size);
      for (int z = 0; z < L.size.z; ++z)
        for (int x = 0; x < L.size.x; ++x) {
          bool any = false;
          for (int y = 0; y < L.size.y && !any; ++y) any = texelNonEmpty(volume, L, (size_t(z) * L.size.y + y) * L.size.x + x);
          if (!any) continue;
          glm::vec3 w0 = volume.world->lo + glm::vec3(x, 0, z) * texel, w1 = w0 + texel;
          int x0 = int((w0.x - lo.x) * scale), x1 = int((w1.x - lo.x) * scale);
          int y0 = int((w0.z - lo.z) * scale), y1 = int((w1.z - lo.z) * scale);
          for (int py = std::max(0, y0); py <= std::min(size - 1, y1); ++py)
            for (int px = std::max(0, x0); px <= std::min(size - 1, x1); ++px) {
              uint8_t* o = &img.rgba[(size_t(py) * size + px) * 4];
              o[0] = o[1] = o[2] = 90;
            }
        }
    }
    for (const auto& b : boxes) {
      glm::vec4 col = colourOf(int(b.lo.w));
      int x0 = int((b.lo.x - lo.x) * scale), x1 = int((b.hi.x - lo.x) * scale);
      int y0 = int((b.lo.z - lo.z) * scale), y1 = int((b.hi.z - lo.z) * scale);
      auto put = [&](int px, int py) {
        if (px < 0 || py < 0 || px >= size || py >= size) return;
        uint8_t* o = &img.rgba[(size_t(py) * size + px) * 4];
        for (int k = 0; k < 3; ++k) o[k] = uint8_t(255.0f * col[k]);
      };
      for (int px = x0; px <= x1; ++px) put(px, y0), put(px, y1);
      for (int py = y0; py <= y1; ++py) put(x0, py), put(x1, py);
    }
    return img;
  }

  std::string caption(const VisualiserContext&) const override {
    return "from above (x right, z down): orange fine cascade, blue coarse, grey blend shell; filled grey = occupied "
           "columns of the context volume";
  }

  void drawInspector(const VisualiserContext& ctx) const override {
    std::vector<LpvBox> boxes = decode(ctx.out);
    if (ImGui::BeginTable("lpv-cascades", 4, ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg)) {
      for (const char* h : {"box", "min (m)", "max (m)", "cell (m)"}) ImGui::TableSetupColumn(h);
      ImGui::TableHeadersRow();
      for (const auto& b : boxes) {
        ImGui::TableNextRow();
        ImGui::TableNextColumn(); ImGui::TextUnformatted(kindName(int(b.lo.w)));
        ImGui::TableNextColumn(); ImGui::Text("%.3f %.3f %.3f", b.lo.x, b.lo.y, b.lo.z);
        ImGui::TableNextColumn(); ImGui::Text("%.3f %.3f %.3f", b.hi.x, b.hi.y, b.hi.z);
        ImGui::TableNextColumn(); ImGui::Text("%.4f", b.hi.w);
      }
      ImGui::EndTable();
    }
  }
};

}  // namespace

VOXLAB_REGISTER_VISUALISER(LpvCascadesVisualiser, OutputKind::Buffer, lpv::kLpvCascades.name());

}  // namespace voxlab
