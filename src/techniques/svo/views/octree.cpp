// Sparse voxel octree buffers (svo): the node pool and the descent records of a probed pixel.
//
// octree-nodes:   statistics and an inspector table per level (nodes, non-empty, tagged, empty
//                 siblings); 3D: the boxes of one level (the inspector's level) over the volume,
//                 orange = non-empty, blue = tagged for dilation only, grey = empty sibling. Pool
//                 indices depend on the order of atomics, so the golden is the canonical content:
//                 (flags, cell, level) per node as an exact sorted set, without pointers.
// octree-descent: record view = per sample, the path root -> fine level (node, cell, value); 3D:
//                 the nested boxes of every path; check: levels run 0, 1, 2 ... per sample, each
//                 cell is the parent cell's child (cell >> 1 == parent cell) and no node follows an
//                 absent one (invariant I12 of the technical note).
// octree-picked-node: the node svo-pick found under a click on svo-structure; 3D: its box (orange),
//                 its children (blue) and its face neighbours (green) over the volume; record view:
//                 flags, children, links, brick and the brick's 27 texels; check: a node without a
//                 brick has all-zero texels, a node with children has 8 consecutive ones.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>

#include <imgui.h>

#include "inspect/view3d.h"
#include "inspect/visualisers/buffer.h"
#include "svo/svo_shared.h"
#include "techniques/svo/stages.h"

namespace voxlab {
namespace {

using svo::SvoDescentStep;
using svo::SvoNode;
using svo::SvoPickedNode;
static_assert(sizeof(SvoPickedNode) == 512, "std430 layout of SvoPickedNode");

glm::uvec3 unpack10(uint32_t p) { return {p & 1023u, (p >> 10) & 1023u, (p >> 20) & 1023u}; }

std::vector<SvoNode> decodeNodes(const CapturedOutput& out) { return recordsAs<SvoNode>(out); }

std::vector<SvoDescentStep> decodeSteps(const CapturedOutput& out) { return recordsAs<SvoDescentStep>(out); }

// Octree depth: from the context volume's level 0 (voxels per axis) when there is one, else the
// deepest level in the records.
int depthFor(const VisualiserContext& ctx, int deepest, CapturedOutput* volume = nullptr) {
  CapturedOutput v;
  std::string name;
  if (ctx.contextVolume && ctx.contextVolume(v, name) && !v.levels.empty()) {
    int res = v.levels[0].size.x, d = 0;
    while ((1 << d) < res) ++d;
    if (volume) *volume = std::move(v);
    return std::max(d, deepest);
  }
  return deepest;
}

void addBox(std::vector<ViewInstance>& lines, glm::vec3 lo, glm::vec3 hi, glm::vec4 colour) {
  for (int e = 0; e < 12; ++e) {
    int axis = e / 4, a = (axis + 1) % 3, b = (axis + 2) % 3;
    glm::vec3 p = lo, q;
    if (e & 1) p[a] = hi[a];
    if (e & 2) p[b] = hi[b];
    q = p;
    q[axis] = hi[axis];
    lines.push_back({glm::vec4(p, 0.0f), colour});
    lines.push_back({glm::vec4(q, 0.0f), colour});
  }
}

struct LevelCounts {
  size_t nodes = 0, nonEmpty = 0, tagged = 0;
};

std::map<uint32_t, LevelCounts> countLevels(const std::vector<SvoNode>& nodes) {
  std::map<uint32_t, LevelCounts> levels;
  for (const auto& n : nodes) {
    LevelCounts& c = levels[n.level];
    ++c.nodes;
    if (n.word & svo::SVO_NON_EMPTY) ++c.nonEmpty;
    if (n.word & svo::SVO_TAG) ++c.tagged;
  }
  return levels;
}

class OctreeNodesVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "octree-nodes"; }
  CaptureTier defaultTier(const OutputDesc&) const override { return CaptureTier::Exact; }

  nlohmann::json statistics(const CapturedOutput& out) const override {
    nlohmann::json s = BufferVisualiser::statistics(out);
    nlohmann::json levels = nlohmann::json::array();
    for (const auto& [level, c] : countLevels(decodeNodes(out)))
      levels.push_back({{"level", level}, {"nodes", c.nodes}, {"non_empty", c.nonEmpty}, {"tagged", c.tagged}});
    s["levels"] = levels;
    return s;
  }

  GoldenResult compareGolden(const CapturedOutput& out, const GoldenRequest& request) const override {
    CapturedOutput canonical = out;
    std::vector<SvoNode> nodes = decodeNodes(out);
    for (auto& n : nodes) {
      n.word &= svo::SVO_TAG | svo::SVO_NON_EMPTY;
      n.parent = 0;
    }
    canonical.recordCount = uint32_t(nodes.size());
    canonical.records.assign(reinterpret_cast<const uint8_t*>(nodes.data()),
                             reinterpret_cast<const uint8_t*>(nodes.data()) + nodes.size() * sizeof(SvoNode));
    GoldenRequest exact = request;
    exact.tier = request.tier == CaptureTier::None ? CaptureTier::None : CaptureTier::Exact;
    return BufferVisualiser::compareGolden(canonical, exact);
  }

  bool has3D(const OutputDesc&) const override { return true; }

  Content3D build3D(const VisualiserContext& ctx, View3D& view) const override {
    Content3D c;
    std::vector<SvoNode> nodes = decodeNodes(ctx.out);
    int deepest = 0;
    for (const auto& n : nodes) deepest = std::max(deepest, int(n.level));
    CapturedOutput volume;
    const int depth = depthFor(ctx, deepest, &volume);
    const int level = std::clamp(ctx.view.level, 0, depth);
    const float cell = float(1 << (depth - level));
    if (!volume.levels.empty()) view.setVolume(mapVolume(volume.levels[0], volume.desc.semantic, DisplaySettings{}),
                                               glm::vec3(volume.levels[0].size), 0.3f);
    std::vector<ViewInstance> lines;
    size_t shown = 0, atLevel = 0;
    const size_t limit = 20000;
    for (const auto& n : nodes) {
      if (int(n.level) != level) continue;
      ++atLevel;
      if (shown >= limit) continue;
      glm::vec3 lo = glm::vec3(unpack10(n.coords)) * cell;
      glm::vec4 colour = (n.word & svo::SVO_NON_EMPTY) ? glm::vec4(1.0f, 0.6f, 0.15f, 1.0f)
                         : (n.word & svo::SVO_TAG)     ? glm::vec4(0.3f, 0.55f, 1.0f, 1.0f)
                                                       : glm::vec4(0.5f, 0.5f, 0.5f, 0.5f);
      addBox(lines, lo, lo + cell, colour);
      ++shown;
    }
    view.setLines(std::move(lines));
    c.hi = glm::vec3(float(1 << depth));
    char buf[200];
    std::snprintf(buf, sizeof buf, "level %d of %d: %zu nodes (%zu drawn); orange non-empty, blue dilated, grey empty "
                  "sibling; the inspector's level picks the octree level", level, depth, atLevel, shown);
    c.info = buf;
    if (nodes.empty()) c.message = "no nodes: run svo-build first";
    return c;
  }

  void drawInspector(const VisualiserContext& ctx) const override {
    ImGui::SliderInt("octree level", &ctx.view.level, 0, 12);
    auto levels = countLevels(decodeNodes(ctx.out));
    if (ImGui::BeginTable("octree-levels", 5, ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg)) {
      for (const char* h : {"level", "nodes", "non-empty", "tagged", "empty siblings"}) ImGui::TableSetupColumn(h);
      ImGui::TableHeadersRow();
      for (const auto& [level, c] : levels) {
        ImGui::TableNextRow();
        ImGui::TableNextColumn(); ImGui::Text("%u", level);
        ImGui::TableNextColumn(); ImGui::Text("%zu", c.nodes);
        ImGui::TableNextColumn(); ImGui::Text("%zu", c.nonEmpty);
        ImGui::TableNextColumn(); ImGui::Text("%zu", c.tagged);
        ImGui::TableNextColumn(); ImGui::Text("%zu", c.nodes - c.tagged);
      }
      ImGui::EndTable();
    }
    ImGui::TextDisabled("pool: %u nodes, %zu bytes", ctx.out.recordCount, size_t(ctx.out.recordCount) * sizeof(SvoNode));
    BufferVisualiser::drawInspector(ctx);
  }
};

// The check of a descent record set (I12).
RecordCheck checkDescent(const std::vector<SvoDescentStep>& steps) {
  RecordCheck r;
  std::map<uint32_t, std::vector<SvoDescentStep>> bySample;
  for (const auto& s : steps) bySample[s.sampleIndex].push_back(s);
  for (auto& [sample, path] : bySample) {
    std::sort(path.begin(), path.end(), [](const auto& a, const auto& b) { return a.level < b.level; });
    for (size_t i = 0; i < path.size() && r.error.empty(); ++i) {
      char buf[160];
      if (path[i].level != i) {
        std::snprintf(buf, sizeof buf, "sample %u: level %u where level %zu was expected", sample, path[i].level, i);
        r.error = buf;
      } else if (i > 0 && unpack10(path[i].coords) / 2u != unpack10(path[i - 1].coords)) {
        std::snprintf(buf, sizeof buf, "sample %u: the cell of level %zu is not inside the cell of level %zu", sample, i, i - 1);
        r.error = buf;
      } else if (i > 0 && path[i - 1].node == svo::SVO_ABSENT) {
        std::snprintf(buf, sizeof buf, "sample %u: a step follows an absent node at level %zu", sample, i - 1);
        r.error = buf;
      }
    }
    r.elements += path.size();
  }
  r.summary = std::to_string(bySample.size()) + " samples, " + std::to_string(r.elements) + " descent steps";
  if (r.error.empty() && r.elements) r.summary += ", every path nested from the root";
  return r;
}

class OctreeDescentVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "octree-descent"; }
  // Compared exactly once canonical: a node's index in the pool depends on the order of the
  // build's atomics, so only whether a node was there is kept; the sample, the level, the cell and
  // the brick's value at the sample (exact leaf sums, then a fixed filter) do not depend on it.
  CaptureTier defaultTier(const OutputDesc&) const override { return CaptureTier::Exact; }
  bool has3D(const OutputDesc&) const override { return true; }

  GoldenResult compareGolden(const CapturedOutput& out, const GoldenRequest& request) const override {
    CapturedOutput canonical = out;
    std::vector<SvoDescentStep> steps = decodeSteps(out);
    for (auto& s : steps)
      if (s.node != svo::SVO_ABSENT) s.node = 0;
    canonical.recordCount = uint32_t(steps.size());
    canonical.records.assign(reinterpret_cast<const uint8_t*>(steps.data()),
                             reinterpret_cast<const uint8_t*>(steps.data()) + steps.size() * sizeof(SvoDescentStep));
    return BufferVisualiser::compareGolden(canonical, request);
  }

  RecordCheck checkRecords(const CapturedOutput& out) const override { return checkDescent(decodeSteps(out)); }

  Content3D build3D(const VisualiserContext& ctx, View3D& view) const override {
    Content3D c;
    std::vector<SvoDescentStep> steps = decodeSteps(ctx.out);
    int deepest = 0;
    for (const auto& s : steps) deepest = std::max(deepest, int(s.level));
    CapturedOutput volume;
    const int depth = depthFor(ctx, deepest, &volume);
    if (!volume.levels.empty()) view.setVolume(mapVolume(volume.levels[0], volume.desc.semantic, DisplaySettings{}),
                                               glm::vec3(volume.levels[0].size), 0.3f);
    std::vector<ViewInstance> lines;
    for (const auto& s : steps) {
      if (lines.size() > 200000) break;
      float cell = float(1 << (depth - int(s.level)));
      glm::vec3 lo = glm::vec3(unpack10(s.coords)) * cell;
      float t = depth ? float(s.level) / float(depth) : 1.0f;
      glm::vec4 colour = s.node == svo::SVO_ABSENT ? glm::vec4(0.5f, 0.5f, 0.5f, 0.6f)
                                                   : glm::vec4(1.0f - t, 0.4f + 0.6f * t, 1.0f, 1.0f);
      addBox(lines, lo, lo + cell, colour);
    }
    view.setLines(std::move(lines));
    c.hi = glm::vec3(float(1 << depth));
    c.info = "descent paths of the probed pixel's samples: root (pink) to fine level (cyan), grey = absent";
    if (steps.empty()) c.message = "no descents recorded: probe a pixel first";
    return c;
  }

  void drawRecordView(const VisualiserContext& ctx) const override {
    std::vector<SvoDescentStep> steps = decodeSteps(ctx.out);
    RecordCheck check = checkRecords(ctx.out);
    ImGui::Text("%s", check.summary.c_str());
    if (!check.error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", check.error.c_str());
    std::sort(steps.begin(), steps.end(), [](const auto& a, const auto& b) {
      return a.sampleIndex != b.sampleIndex ? a.sampleIndex < b.sampleIndex : a.level < b.level;
    });
    if (ImGui::BeginTable("descent", 5, ImGuiTableFlags_Borders | ImGuiTableFlags_ScrollY, ImVec2(0, 300))) {
      for (const char* h : {"sample", "level", "node", "cell", "value (rgb, a)"}) ImGui::TableSetupColumn(h);
      ImGui::TableHeadersRow();
      for (const auto& s : steps) {
        glm::uvec3 cell = unpack10(s.coords);
        ImGui::TableNextRow();
        ImGui::TableNextColumn(); ImGui::Text("%u", s.sampleIndex);
        ImGui::TableNextColumn(); ImGui::Text("%u", s.level);
        ImGui::TableNextColumn();
        if (s.node == svo::SVO_ABSENT) ImGui::TextDisabled("absent"); else ImGui::Text("%u", s.node);
        ImGui::TableNextColumn(); ImGui::Text("%u %u %u", cell.x, cell.y, cell.z);
        ImGui::TableNextColumn();
        ImGui::Text("%.3f %.3f %.3f, %.3f", s.value[0], s.value[1], s.value[2], s.value[3]);
      }
      ImGui::EndTable();
    }
  }
};

bool decodePicked(const CapturedOutput& out, SvoPickedNode& p) {
  if (out.desc.layout.stride != sizeof(SvoPickedNode) || out.records.size() < sizeof(SvoPickedNode) || out.recordCount < 1)
    return false;
  std::memcpy(&p, out.records.data(), sizeof p);
  return true;
}

class OctreePickedNodeVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "octree-picked-node"; }
  CaptureTier defaultTier(const OutputDesc&) const override { return CaptureTier::Exact; }
  bool has3D(const OutputDesc&) const override { return true; }

  RecordCheck checkRecords(const CapturedOutput& out) const override {
    RecordCheck r;
    SvoPickedNode p;
    if (!decodePicked(out, p)) {
      r.error = "no picked-node record";
      return r;
    }
    if (p.node == svo::SVO_ABSENT) {
      r.summary = "no node at the picked cell (empty at that level)";
      return r;
    }
    r.elements = 1;
    bool zero = true;
    for (float v : p.texels) zero = zero && v == 0.0f;
    if (p.brick == 0 && !zero) r.error = "a node without a brick has non-zero texels";
    for (int k = 1; k < 8 && r.error.empty(); ++k)
      if (p.children[0] != svo::SVO_ABSENT && p.children[k] != p.children[0] + uint32_t(k)) r.error = "children not consecutive";
    int links = 0;
    for (uint32_t n : p.neighbours) links += n != svo::SVO_ABSENT;
    r.summary = "node " + std::to_string(p.node) + " at level " + std::to_string(p.level) + ", " + std::to_string(links) +
                " neighbour links, brick " + std::to_string(p.brick);
    return r;
  }

  Content3D build3D(const VisualiserContext& ctx, View3D& view) const override {
    Content3D c;
    SvoPickedNode p;
    if (!decodePicked(ctx.out, p)) return c;
    CapturedOutput volume;
    const int depth = depthFor(ctx, int(p.level), &volume);
    if (!volume.levels.empty()) view.setVolume(mapVolume(volume.levels[0], volume.desc.semantic, DisplaySettings{}),
                                               glm::vec3(volume.levels[0].size), 0.3f);
    const float cell = float(1 << (depth - int(p.level)));
    const glm::vec3 lo = glm::vec3(unpack10(p.coords)) * cell;
    std::vector<ViewInstance> lines;
    addBox(lines, lo, lo + cell, glm::vec4(1.0f, 0.6f, 0.15f, 1.0f));
    if (p.children[0] != svo::SVO_ABSENT)
      for (int k = 0; k < 8; ++k) {
        glm::vec3 o = lo + 0.5f * cell * glm::vec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
        addBox(lines, o, o + 0.5f * cell, glm::vec4(0.3f, 0.55f, 1.0f, 1.0f));
      }
    for (int d = 0; d < 6; ++d) {
      if (p.neighbours[d] == svo::SVO_ABSENT) continue;
      glm::vec3 o = lo;
      o[d >> 1] += (d & 1) ? -cell : cell;
      addBox(lines, o, o + cell, glm::vec4(0.3f, 0.9f, 0.3f, 1.0f));
    }
    view.setLines(std::move(lines));
    c.hi = glm::vec3(float(1 << depth));
    c.info = checkRecords(ctx.out).summary + "; orange the node, blue its children, green its face neighbours";
    if (p.node == svo::SVO_ABSENT) c.message = "no node at the picked cell: click a non-empty voxel of svo-structure";
    return c;
  }

  void drawRecordView(const VisualiserContext& ctx) const override {
    SvoPickedNode p;
    if (!decodePicked(ctx.out, p)) return;
    RecordCheck check = checkRecords(ctx.out);
    ImGui::Text("%s", check.summary.c_str());
    if (!check.error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", check.error.c_str());
    glm::uvec3 cc = unpack10(p.coords);
    ImGui::Text("cell (%u, %u, %u), flags %s%s, first child %u", cc.x, cc.y, cc.z, (p.word & svo::SVO_TAG) ? "tagged " : "",
                (p.word & svo::SVO_NON_EMPTY) ? "non-empty" : "", p.word & svo::SVO_CHILD_MASK);
    const char* dirs[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
    for (int d = 0; d < 6; ++d) {
      if (d) ImGui::SameLine();
      if (p.neighbours[d] == svo::SVO_ABSENT) ImGui::TextDisabled("%s -", dirs[d]);
      else ImGui::Text("%s %u", dirs[d], p.neighbours[d]);
    }
    if (ImGui::BeginTable("brick", 4, ImGuiTableFlags_Borders | ImGuiTableFlags_ScrollY, ImVec2(0, 300))) {
      for (const char* h : {"texel", "r", "g, b", "a"}) ImGui::TableSetupColumn(h);
      ImGui::TableHeadersRow();
      for (int t = 0; t < 27; ++t) {
        const float* v = &p.texels[4 * t];
        ImGui::TableNextRow();
        ImGui::TableNextColumn(); ImGui::Text("%d %d %d", t % 3, (t / 3) % 3, t / 9);
        ImGui::TableNextColumn(); ImGui::Text("%.3f", v[0]);
        ImGui::TableNextColumn(); ImGui::Text("%.3f %.3f", v[1], v[2]);
        ImGui::TableNextColumn(); ImGui::Text("%.3f", v[3]);
      }
      ImGui::EndTable();
    }
  }
};

}  // namespace

VOXLAB_REGISTER_VISUALISER(OctreePickedNodeVisualiser, OutputKind::Buffer, svo::kOctreePickedNode.name());
VOXLAB_REGISTER_VISUALISER(OctreeNodesVisualiser, OutputKind::Buffer, svo::kOctreeNodes.name());
VOXLAB_REGISTER_VISUALISER(OctreeDescentVisualiser, OutputKind::Buffer, svo::kOctreeDescent.name());

}  // namespace voxlab
