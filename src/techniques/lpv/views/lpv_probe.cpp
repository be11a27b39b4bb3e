// lpv's picked cell (semantic "lpv-probe": one LpvProbe record from the propagate stage, the cell
// probe.cell-x/y/z of cascade probe.cascade after the current step).
//
// 2D view and the `.lobes.png` file: the cell's light as polar glyphs in the three axis planes
// (left to right: xy seen from +z, xz seen from -y, zy seen from +x; right and up are the first and
// second axis): the intensity f(d) = Y00 c00 + Y1 b.d the cell sends along each direction d of the
// plane, summed over the colour channels, orange where positive, blue where negative (an L1 lobe
// has a negative back lobe unless the light is spread), with the grid the lookup reads (total)
// drawn filled and the last step's wavefront as an outline. Statistics and inspector: per channel
// the four coefficients (c00, c1-1, c10, c11), |b|/c00 and flux; the voxel's colour, contrast,
// occupancy, fragments and decoded normals; the c00 each neighbour added in this step and its
// mean face transmission, what a surface in the cell would read for each axis normal with either
// lookup sign (the facing-plates experiment), and under each neighbour its five face evaluations (the neighbour's
// intensity towards the face, the face's solid angle, the transmission, the flux through it) that
// sum to it. The record check recomputes those sums: per neighbour its c00, over all 30 faces in
// the propagation's order the cell's gathered SH (the wavefront), both exact.
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

using lpv::gpu::LpvProbe;
constexpr float kY00 = 0.282094792f;  // as shaders/common/sh.glsl
constexpr float kY1 = 0.488602512f;
constexpr float kFluxPerC00 = 3.544907702f;
constexpr float kLobe0 = 0.886226925f;  // clamped-cosine lobe: sqrt(pi) / 2, sqrt(pi / 3)
constexpr float kLobe1 = 1.023326708f;
constexpr int kPanel = 121;  // pixels per plane glyph
const char* const kChannels[3] = {"red", "green", "blue"};
const char* const kNeighbours[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};

bool decode(const CapturedOutput& out, LpvProbe& p) {
  if (out.desc.layout.stride != sizeof(LpvProbe) || out.records.size() < sizeof(LpvProbe)) return false;
  std::memcpy(&p, out.records.data(), sizeof p);
  return true;
}

glm::vec3 band1(const glm::vec4& v) { return {-v.w, -v.y, v.z}; }
float evaluate(const glm::vec4& v, const glm::vec3& d) { return kY00 * v.x + kY1 * glm::dot(band1(v), d); }
glm::vec4 sumOf(const glm::vec4* sh) { return sh[0] + sh[1] + sh[2]; }

// Listing 4.28's normal mask (0 = empty channel): |x|, |y|, |z| in 8 bits each with sign bits.
glm::vec3 decodeNormal(uint32_t m) {
  glm::vec3 v(float((m >> 18) & 255u), float((m >> 9) & 255u), float(m & 255u));
  v /= 255.0f;
  if ((m >> 26) & 1u) v.x = -v.x;
  if ((m >> 17) & 1u) v.y = -v.y;
  if ((m >> 8) & 1u) v.z = -v.z;
  return v;
}

// Face j of neighbour i's k-th evaluation: increasing j, the shared face (j = i) skipped.
int faceOf(int i, int k) { return k < i ? k : k + 1; }
// flux * lobe(axis of face j), as the propagation adds it (shaders/common/sh.glsl shLobe of the axis).
glm::vec4 axisLobe(int j) {
  const float s = (j & 1) == 0 ? 1.0f : -1.0f;
  const int axis = j >> 1;
  return {kLobe0, axis == 1 ? -kLobe1 * s : 0.0f, axis == 2 ? kLobe1 * s : 0.0f, axis == 0 ? -kLobe1 * s : 0.0f};
}

// The sums the record's faces must give: per neighbour the c00 it added, over all faces the
// gathered SH. Returns "" or the first mismatch.
std::string checkFaceSums(const LpvProbe& p) {
  glm::vec4 gathered[3] = {glm::vec4(0.0f), glm::vec4(0.0f), glm::vec4(0.0f)};
  char buf[160];
  for (int i = 0; i < 6; ++i) {
    glm::vec4 own[3] = {glm::vec4(0.0f), glm::vec4(0.0f), glm::vec4(0.0f)};
    for (int k = 0; k < 5; ++k) {
      const glm::vec4 lobe = axisLobe(faceOf(i, k));
      for (int ch = 0; ch < 3; ++ch) {
        own[ch] = own[ch] + p.faceFlux[5 * i + k][ch] * lobe;
        gathered[ch] = gathered[ch] + p.faceFlux[5 * i + k][ch] * lobe;
      }
    }
    for (int ch = 0; ch < 3; ++ch)
      if (own[ch].x != p.fromNeighbour[i][ch]) {
        std::snprintf(buf, sizeof buf, "from %s, %s: the faces' fluxes give c00 %.9g, the record %.9g", kNeighbours[i],
                      kChannels[ch], own[ch].x, p.fromNeighbour[i][ch]);
        return buf;
      }
  }
  for (int ch = 0; ch < 3; ++ch)
    if (gathered[ch] != p.wavefront[ch]) {
      std::snprintf(buf, sizeof buf, "%s: the 30 faces give c00 %.9g, the gathered light (wavefront) %.9g", kChannels[ch],
                    gathered[ch].x, p.wavefront[ch].x);
      return buf;
    }
  return "";
}

glm::vec3 axisNormal(int i) {
  glm::vec3 n(0.0f);
  n[i >> 1] = (i & 1) == 0 ? 1.0f : -1.0f;
  return n;
}
// max(0, <sh, lobe(d)>): the cell's light convolved with a clamped cosine around d (sh.glsl's
// shDotLobe in the same order).
float lookup(const glm::vec4& sh, const glm::vec3& d) {
  const float a = sh.x * kLobe0, b = sh.y * (-kLobe1 * d.y), c = sh.z * (kLobe1 * d.z), e = sh.w * (-kLobe1 * d.x);
  return std::max(0.0f, ((a + b) + c) + e);
}

DisplayImage lobes(const LpvProbe& p) {
  DisplayImage img;
  img.width = 3 * kPanel, img.height = kPanel;
  img.rgb.assign(size_t(img.width) * img.height * 3, 16);
  const glm::vec4 total = sumOf(p.total), wave = sumOf(p.wavefront);
  auto fmaxOf = [](const glm::vec4& v) { return std::abs(kY00 * v.x) + kY1 * glm::length(band1(v)); };
  const float ft = fmaxOf(total), fw = fmaxOf(wave);
  const glm::vec3 right[3] = {{1, 0, 0}, {1, 0, 0}, {0, 0, 1}};
  const glm::vec3 up[3] = {{0, 1, 0}, {0, 0, 1}, {0, 1, 0}};
  const float radius = 0.47f * kPanel;
  for (int panel = 0; panel < 3; ++panel)
    for (int y = 0; y < kPanel; ++y)
      for (int x = 0; x < kPanel; ++x) {
        uint8_t* o = &img.rgb[(size_t(y) * img.width + size_t(panel) * kPanel + x) * 3];
        if (x == 0) { o[0] = o[1] = o[2] = 60; continue; }  // panel border
        const float dx = float(x) - 0.5f * kPanel, dy = 0.5f * kPanel - float(y);
        const float r = std::sqrt(dx * dx + dy * dy);
        if (std::abs(dx) < 0.5f || std::abs(dy) < 0.5f) { o[0] = o[1] = o[2] = 40; }  // axes
        if (r < 0.5f) continue;
        const glm::vec3 d = (dx / r) * right[panel] + (dy / r) * up[panel];
        if (ft > 0.0f) {
          const float f = evaluate(total, d);
          if (r <= radius * std::abs(f) / ft) {
            if (f >= 0.0f) o[0] = 255, o[1] = 150, o[2] = 40;
            else o[0] = 60, o[1] = 130, o[2] = 255;
          }
        }
        if (fw > 0.0f) {  // the wavefront's outline, on its own scale
          const float f = std::abs(evaluate(wave, d)) * radius / fw;
          if (std::abs(r - f) < 0.8f) o[0] = o[1] = o[2] = 235;
        }
      }
  return img;
}

nlohmann::json shJson(const glm::vec4& v) {
  const float dir = v.x > 0.0f ? glm::length(band1(v)) / v.x : 0.0f;
  return {{"c00", v.x}, {"c1-1", v.y}, {"c10", v.z}, {"c11", v.w}, {"directionality", dir}, {"flux", v.x * kFluxPerC00}};
}

class LpvProbeVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "lpv-probe"; }

  nlohmann::json statistics(const CapturedOutput& out) const override {
    nlohmann::json st = BufferVisualiser::statistics(out);
    LpvProbe p;
    if (!decode(out, p)) return st;
    nlohmann::json cell = {{"cell", {p.cell.x, p.cell.y, p.cell.z}}, {"cascade", p.cell.w}, {"step", p.voxel.z}};
    for (int ch = 0; ch < 3; ++ch) {
      cell["total"][kChannels[ch]] = shJson(p.total[ch]);
      cell["wavefront"][kChannels[ch]] = shJson(p.wavefront[ch]);
    }
    const uint32_t word = p.voxel.x;
    cell["voxel"] = {{"occupied", (word >> 31) != 0u},
                     {"colour", {float((word >> 16) & 255u) / 255.0f, float((word >> 8) & 255u) / 255.0f,
                                 float(word & 255u) / 255.0f}},
                     {"contrast", float((word >> 24) & 127u) / 127.0f},
                     {"fragments", p.voxel.y}};
    for (int k = 0; k < 4; ++k) {
      glm::vec3 n = decodeNormal(p.normals[k]);
      cell["voxel"]["normals"].push_back(p.normals[k] ? nlohmann::json{n.x, n.y, n.z} : nlohmann::json(nullptr));
    }
    for (int i = 0; i < 6; ++i) {
      nlohmann::json faces = nlohmann::json::array();
      for (int k = 0; k < 5; ++k) {
        const glm::vec4 &in = p.faceIntensity[5 * i + k], &fl = p.faceFlux[5 * i + k];
        faces.push_back({{"face", kNeighbours[faceOf(i, k)]},
                         {"intensity", {in.x, in.y, in.z}},
                         {"solid_angle", in.w},
                         {"transmission", fl.w},
                         {"flux", {fl.x, fl.y, fl.z}}});
      }
      cell["from_neighbour"][kNeighbours[i]] = {{"c00", {p.fromNeighbour[i].x, p.fromNeighbour[i].y, p.fromNeighbour[i].z}},
                                                {"transmission", p.fromNeighbour[i].w},
                                                {"faces", faces}};
    }
    cell["weight"] = p.weight.x;
    // What a surface in this cell with normal n reads (gi.comp.glsl per unit of gi.radiance-scale /
    // cell^2): the light convolved with a cosine around -n (the default lookup) or +n (the thesis).
    for (int i = 0; i < 6; ++i) {
      const glm::vec3 n = axisNormal(i);
      nlohmann::json minus = nlohmann::json::array(), plus = nlohmann::json::array();
      for (int ch = 0; ch < 3; ++ch) {
        minus.push_back(lookup(p.total[ch], -n));
        plus.push_back(lookup(p.total[ch], n));
      }
      cell["lookup"][kNeighbours[i]] = {{"minus_n", minus}, {"plus_n", plus}};
    }
    st["probe"] = cell;
    return st;
  }

  nlohmann::json writeFiles(const CapturedOutput& out, const std::string& dir, const std::string& prefix) const override {
    nlohmann::json entry = BufferVisualiser::writeFiles(out, dir, prefix);
    LpvProbe p;
    if (decode(out, p)) {
      entry["files"].push_back(prefix + ".lobes.png");
      writePng(lobes(p), dir + "/" + prefix + ".lobes.png");
    }
    return entry;
  }

  SliceImage image2D(const VisualiserContext& ctx) const override {
    SliceImage img;
    LpvProbe p;
    if (!decode(ctx.out, p)) return BufferVisualiser::image2D(ctx);
    DisplayImage d = lobes(p);
    img.width = d.width, img.height = d.height;
    img.rgba.resize(size_t(d.width) * d.height * 4, 255);
    for (size_t i = 0; i < size_t(d.width) * d.height; ++i) std::memcpy(&img.rgba[i * 4], &d.rgb[i * 3], 3);
    return img;
  }

  std::string caption(const VisualiserContext&) const override {
    return "the picked cell's light in the xy, xz and zy planes: filled = what the lookup reads (orange positive, blue "
           "negative), white outline = the last step's wavefront";
  }

  void drawInspector(const VisualiserContext& ctx) const override {
    LpvProbe p;
    if (decode(ctx.out, p)) {
      ImGui::Text("cell (%d, %d, %d) of cascade %d after step %u", p.cell.x, p.cell.y, p.cell.z, p.cell.w, p.voxel.z);
      if (ImGui::BeginTable("lpv-probe-sh", 7, ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg)) {
        for (const char* h : {"", "c00", "c1-1", "c10", "c11", "|b|/c00", "flux (W)"}) ImGui::TableSetupColumn(h);
        ImGui::TableHeadersRow();
        for (int part = 0; part < 2; ++part)
          for (int ch = 0; ch < 3; ++ch) {
            const glm::vec4& v = part == 0 ? p.total[ch] : p.wavefront[ch];
            ImGui::TableNextRow();
            ImGui::TableNextColumn();
            ImGui::Text("%s %s", part == 0 ? "total" : "wave", kChannels[ch]);
            for (int k = 0; k < 4; ++k) {
              ImGui::TableNextColumn();
              ImGui::Text("%.4g", v[k]);
            }
            ImGui::TableNextColumn();
            ImGui::Text("%.3f", v.x > 0.0f ? glm::length(band1(v)) / v.x : 0.0f);
            ImGui::TableNextColumn();
            ImGui::Text("%.4g", v.x * kFluxPerC00);
          }
        ImGui::EndTable();
      }
      ImGui::Text("flux through a face = ((intensity x solid angle) x transmission) x %.4g; c00 += flux x %.4f",
                  p.weight.x, kLobe0);
      for (int i = 0; i < 6; ++i) {
        char title[128];
        std::snprintf(title, sizeof title, "from %s: c00 (%.3g, %.3g, %.3g), mean transmission %.3f###from%d",
                      kNeighbours[i], p.fromNeighbour[i].x, p.fromNeighbour[i].y, p.fromNeighbour[i].z,
                      p.fromNeighbour[i].w, i);
        if (!ImGui::TreeNode(title)) continue;
        if (ImGui::BeginTable("lpv-probe-faces", 5, ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg)) {
          for (const char* h : {"face", "intensity r, g, b (W/sr)", "solid angle (sr)", "transmission", "flux r, g, b (W)"})
            ImGui::TableSetupColumn(h);
          ImGui::TableHeadersRow();
          for (int k = 0; k < 5; ++k) {
            const glm::vec4 &in = p.faceIntensity[5 * i + k], &fl = p.faceFlux[5 * i + k];
            ImGui::TableNextRow();
            ImGui::TableNextColumn();
            ImGui::Text("%s", kNeighbours[faceOf(i, k)]);
            ImGui::TableNextColumn();
            ImGui::Text("%.3g, %.3g, %.3g", in.x, in.y, in.z);
            ImGui::TableNextColumn();
            ImGui::Text("%.4f", in.w);
            ImGui::TableNextColumn();
            ImGui::Text("%.3f", fl.w);
            ImGui::TableNextColumn();
            ImGui::Text("%.3g, %.3g, %.3g", fl.x, fl.y, fl.z);
          }
          ImGui::EndTable();
        }
        ImGui::TreePop();
      }
      if (ImGui::TreeNode("lpv-probe-lookup", "what a surface in this cell reads (red), per normal n")) {
        if (ImGui::BeginTable("lpv-probe-lookup-table", 3, ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg)) {
          for (const char* h : {"normal n", "cosine around -n (default)", "around +n (thesis)"}) ImGui::TableSetupColumn(h);
          ImGui::TableHeadersRow();
          for (int i = 0; i < 6; ++i) {
            ImGui::TableNextRow();
            ImGui::TableNextColumn();
            ImGui::Text("%s", kNeighbours[i]);
            ImGui::TableNextColumn();
            ImGui::Text("%.4f", lookup(p.total[0], -axisNormal(i)));
            ImGui::TableNextColumn();
            ImGui::Text("%.4f", lookup(p.total[0], axisNormal(i)));
          }
          ImGui::EndTable();
        }
        ImGui::TreePop();
      }
      const std::string error = checkFaceSums(p);
      if (error.empty()) ImGui::TextDisabled("the faces sum to each neighbour's c00 and to the gathered light");
      else ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", error.c_str());
    }
    BufferVisualiser::drawInspector(ctx);
  }

  RecordCheck checkRecords(const CapturedOutput& out) const override {
    RecordCheck r;
    LpvProbe p;
    if (!decode(out, p)) {
      r.error = "not one LpvProbe record";
      return r;
    }
    r.elements = 30;
    r.summary = "cell (" + std::to_string(p.cell.x) + ", " + std::to_string(p.cell.y) + ", " + std::to_string(p.cell.z) +
                "), 6 neighbours x 5 faces";
    r.error = checkFaceSums(p);
    if (r.error.empty()) r.summary += ", summing to each neighbour's c00 and the gathered light";
    return r;
  }
};

}  // namespace

VOXLAB_REGISTER_VISUALISER(LpvProbeVisualiser, OutputKind::Buffer, lpv::kLpvProbe.name());

}  // namespace voxlab
