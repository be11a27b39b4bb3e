// Bitmask columns (the near-field technique, src/techniques/near_field): RGBA32UI images whose
// texel holds 128 one-bit slices along the voxelization axis (z), MSB first in each channel
// (slice k is bit 31 - k % 32 of channel k / 32): the binary voxel grid, its 2D OR hierarchy and
// the OR / XOR / ray-mask tables. The 2D view is white where any slice is set. The value under the
// cursor names the set slices with their depth intervals in metres (z along the world axis, from the
// binary grid's placement; the tables take the grid's); the inspector draws the picked column as a
// 128-bit stack with each slice's depth interval (hover a slice) and, on a level above 0 of the
// hierarchy, its four children one level down and their OR, marking every slice where the OR
// differs from the column (it must not: the hierarchy's invariant).
//
// The traversal records of a probed ray (near-field's rays stage, TraversalStep in
// shaders/near_field/near_field_shared.h) get a record view and a check here too: per step the
// level, texel, slice range, ray mask, AND with the column and action, drawn as bit strips; the
// check asserts what the walk must keep: steps numbered from 0, the level one finer after a
// descend and one coarser (at most the top) after an advance, a descend only where the AND is
// non-empty and an advance only where it is empty, a hit only at level 0 and only as the last
// step, the ray mask exactly the slices first..last, the AND inside the ray mask, and t entering
// <= t leaving <= the segment's end. The probed ray's record (ProbeRay) gets a view of its hit voxel
// beside the true surface point on the same ray and the distance between them in voxels, and its
// RSM lookup (texel, the RSM's position and normal there, distance vs threshold, normal test,
// category by name), whose check asserts the category follows from the recorded values.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <imgui.h>

#include "inspect/visualisers/buffer.h"
#include "inspect/visualisers/levels.h"
#include "near_field/near_field_shared.h"
#include "techniques/common/binary_voxels_stage.h"
#include "techniques/near_field/stages.h"
#include "techniques/near_field/views/ray_category.h"

namespace voxlab {
namespace {

constexpr int kSlices = 128;
using Mask = std::array<uint32_t, 4>;

bool sliceSet(const Mask& m, int k) { return (m[k >> 5] >> (31 - (k & 31))) & 1u; }
int popcount(const Mask& m) {
  int n = 0;
  for (uint32_t c : m) n += __builtin_popcount(c);
  return n;
}

// The column at texel (x, y) of a level, exact from the integer readback (float values lose the
// low bits of a 32-bit mask; capture keeps the integers for integer formats).
bool columnAt(const LevelData& L, int x, int y, Mask& m) {
  if (x < 0 || y < 0 || x >= L.size.x || y >= L.size.y || L.channels < 4) return false;
  const size_t i = (size_t(y) * L.size.x + x) * L.channels;
  for (int c = 0; c < 4; ++c) m[c] = L.integers.empty() ? uint32_t(L.values[i + c]) : L.integers[i + c];
  return true;
}

// Where the slices lie along z in the world: slice k covers [z0 + k dz, z0 + (k + 1) dz).
struct SliceDepth {
  bool known = false;
  float z0 = 0.0f, dz = 0.0f;
};

// The columns' own placement (the binary grid and its hierarchy place themselves), else that of
// the binary grid the tables index (the ray-mask table's slices are the grid's slices).
SliceDepth sliceDepthOf(const VisualiserContext& ctx) {
  SliceDepth d;
  std::optional<WorldBox> box = ctx.out.world;
  if (!box && ctx.contextOutput) {
    CapturedOutput grid;
    if (ctx.contextOutput("binary-voxels", grid)) box = grid.world;
  }
  if (!box) return d;
  d.known = true;
  d.z0 = box->lo.z;
  d.dz = (box->hi.z - box->lo.z) / float(kSlices);
  return d;
}

// "0-3, 17, 20-40": the set slices as ranges; with depths "0-3 (z -0.512..-0.496 m), ...".
std::string sliceRanges(const Mask& m, const SliceDepth& depth = {}) {
  std::string s;
  for (int k = 0; k < kSlices; ++k) {
    if (!sliceSet(m, k)) continue;
    int e = k;
    while (e + 1 < kSlices && sliceSet(m, e + 1)) ++e;
    s += (s.empty() ? "" : ", ") + std::to_string(k) + (e > k ? "-" + std::to_string(e) : "");
    if (depth.known) {
      char buf[64];
      std::snprintf(buf, sizeof buf, " (z %.4g..%.4g m)", depth.z0 + k * depth.dz, depth.z0 + (e + 1) * depth.dz);
      s += buf;
    }
    k = e;
  }
  return s.empty() ? "none" : s;
}

// The picked (or last hovered) column per view, kept across frames.
std::map<const ViewSettings*, glm::ivec2>& picked() {
  static std::map<const ViewSettings*, glm::ivec2> p;
  return p;
}

// A vertical stack of 128 cells (slice 0 at the top), set slices filled; 'differs' outlines in red.
// Hovering a cell names its slice and, when the depth is known, the slice's z interval in metres.
void drawStack(const char* label, const Mask& m, const Mask* differs, float cellH, const SliceDepth& depth = {}) {
  ImGui::BeginGroup();
  ImGui::TextUnformatted(label);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImVec2 at = ImGui::GetCursorScreenPos();
  const float w = 28.0f;
  for (int k = 0; k < kSlices; ++k) {
    const ImVec2 a(at.x, at.y + k * cellH), b(at.x + w, at.y + (k + 1) * cellH);
    dl->AddRectFilled(a, b, sliceSet(m, k) ? IM_COL32(235, 235, 235, 255) : IM_COL32(40, 40, 48, 255));
    if (differs && sliceSet(*differs, k)) dl->AddRect(a, b, IM_COL32(255, 60, 60, 255));
  }
  ImGui::Dummy(ImVec2(w, kSlices * cellH));
  if (ImGui::IsItemHovered()) {
    const int k = std::clamp(int((ImGui::GetIO().MousePos.y - at.y) / cellH), 0, kSlices - 1);
    if (depth.known)
      ImGui::SetTooltip("slice %d (%s): z in [%.4g, %.4g) m", k, sliceSet(m, k) ? "set" : "empty", depth.z0 + k * depth.dz,
                        depth.z0 + (k + 1) * depth.dz);
    else
      ImGui::SetTooltip("slice %d (%s)", k, sliceSet(m, k) ? "set" : "empty");
  }
  ImGui::Text("%d set", popcount(m));
  ImGui::EndGroup();
}

class BitmaskColumnsVisualiser : public ImageVisualiser {
 public:
  const char* name() const override { return "bitmask-columns"; }

  std::string describeElement(const VisualiserContext& ctx, const glm::ivec3& t) const override {
    const LevelData* L = shownLevel(ctx);
    Mask m;
    if (!L || !columnAt(*L, t.x, t.y, m)) return "";
    picked()[&ctx.view] = {t.x, t.y};
    char head[96];
    std::snprintf(head, sizeof head, "column (%d, %d), level %d: %d of 128 slices set: ", t.x, t.y, ctx.view.level, popcount(m));
    return head + sliceRanges(m, sliceDepthOf(ctx));
  }

  void drawInspector(const VisualiserContext& ctx) const override {
    const LevelData* L = shownLevel(ctx);
    auto it = picked().find(&ctx.view);
    Mask m;
    if (L && it != picked().end() && columnAt(*L, it->second.x, it->second.y, m)) {
      const glm::ivec2 c = it->second;
      ImGui::Text("column (%d, %d) at level %d (hover or click a texel to pick)", c.x, c.y, ctx.view.level);
      const SliceDepth depth = sliceDepthOf(ctx);
      ImGui::TextWrapped("slices set: %s", sliceRanges(m, depth).c_str());
      if (depth.known)
        ImGui::TextDisabled("slice k covers z in [%.4g + k %.4g, %.4g + (k+1) %.4g) m (the volume spans z %.4g..%.4g m); "
                            "slice 0 at the top; hover a slice for its interval",
                            depth.z0, depth.dz, depth.z0, depth.dz, depth.z0, depth.z0 + kSlices * depth.dz);
      else
        ImGui::TextDisabled("slice k covers z in [k/128, (k+1)/128) of the volume's edge (no world placement); slice 0 at the top");
      const float cellH = 2.0f;
      drawStack("column", m, nullptr, cellH, depth);
      const int level = std::clamp(ctx.view.level, 0, int(ctx.out.levels.size()) - 1);
      if (level > 0) {
        const LevelData& F = ctx.out.levels[size_t(level - 1)];
        Mask orOfChildren{0, 0, 0, 0};
        for (int k = 0; k < 4; ++k) {
          Mask child;
          if (!columnAt(F, 2 * c.x + (k & 1), 2 * c.y + (k >> 1), child)) continue;
          for (int j = 0; j < 4; ++j) orOfChildren[j] |= child[j];
          char label[48];
          std::snprintf(label, sizeof label, "(%d,%d)", 2 * c.x + (k & 1), 2 * c.y + (k >> 1));
          ImGui::SameLine();
          drawStack(label, child, nullptr, cellH, depth);
        }
        Mask diff;
        for (int j = 0; j < 4; ++j) diff[j] = orOfChildren[j] ^ m[j];
        ImGui::SameLine();
        drawStack("OR", orOfChildren, &diff, cellH, depth);
        if (popcount(diff) == 0) ImGui::TextUnformatted("OR of the four children = the column");
        else ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "OR of the children differs in %d slices (%s)", popcount(diff),
                                sliceRanges(diff).c_str());
      }
    } else {
      ImGui::TextDisabled("hover or click a column to see its 128 slices");
    }
    ImageVisualiser::drawInspector(ctx);
  }
};

// White where any slice is set (as the occupancy semantic); compared exactly.
void anySliceColour(const float* v, int n, float, float, float, uint8_t* o) {
  bool any = false;
  for (int c = 0; c < n; ++c) any = any || v[c] != 0.0f;
  o[0] = o[1] = o[2] = any ? 255 : 0;
}

struct Registration {
  Registration() { registerTexelMapping(kBitmaskColumns, {&anySliceColour, false, false, true}); }
} registration;

// --- traversal records ---------------------------------------------------------------------------

constexpr uint32_t kHit = 0, kDescend = 8, kAdvance = 9;  // NF_END_HIT, NF_STEP_DESCEND, NF_STEP_ADVANCE

struct Step {
  uint32_t step, level, x, y, first, last, action, hitSlice;
  Mask ray, hit;
  float tEnter, tExit, tEnd, unused;
};
static_assert(sizeof(Step) == 80, "TraversalStep is 80 bytes");

std::vector<Step> decodeSteps(const CapturedOutput& out) { return recordsAs<Step>(out); }

Mask sliceRange(int first, int last) {
  Mask m{0, 0, 0, 0};
  for (int k = first; k <= last; ++k) m[k >> 5] |= 1u << (31 - (k & 31));
  return m;
}

const char* actionName(uint32_t a) { return a == kHit ? "hit" : a == kDescend ? "descend" : a == kAdvance ? "advance" : "?"; }

// "step 3: level 2, texel (5, 7), slices 10..14, t 0.1..0.2 of 0.5 -> descend" (t in fractions of the segment).
std::string stepLine(const Step& s) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "step %u: level %u, texel (%u, %u), slices %u..%u, t %.4f..%.4f of %.4f -> %s", s.step,
                s.level, s.x, s.y, s.first, s.last, s.tEnter, s.tExit, s.tEnd, actionName(s.action));
  std::string line = buf;
  if (s.action == kHit) line += " slice " + std::to_string(s.hitSlice);
  return line;
}

class TraversalVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "near-field-traversal"; }

  RecordCheck checkRecords(const CapturedOutput& out) const override {
    RecordCheck c;
    const auto steps = decodeSteps(out);
    c.elements = steps.size();
    uint32_t topLevel = 0;
    for (const Step& s : steps) topLevel = std::max(topLevel, s.level);
    char buf[200];
    auto fail = [&](size_t i, const char* what) {
      if (!c.error.empty()) return;
      std::snprintf(buf, sizeof buf, "step %zu: %s", i, what);
      c.error = buf;
    };
    int descends = 0, advances = 0;
    for (size_t i = 0; i < steps.size(); ++i) {
      const Step& s = steps[i];
      bool andEmpty = true, inside = true;
      for (int j = 0; j < 4; ++j) {
        andEmpty = andEmpty && s.hit[j] == 0;
        inside = inside && (s.hit[j] & ~s.ray[j]) == 0;
      }
      if (s.step != i) fail(i, "steps are not numbered 0, 1, 2, ...");
      if (s.first > s.last || s.last >= uint32_t(kSlices)) fail(i, "slice range first > last or beyond 127");
      else if (s.ray != sliceRange(int(s.first), int(s.last))) fail(i, "the ray mask is not the slices first..last");
      if (!inside) fail(i, "the AND has slices outside the ray mask");
      if (!(s.tEnter <= s.tExit && s.tExit <= s.tEnd)) fail(i, "t entering > t leaving or t leaving > the segment's end");
      if (s.action == kHit) {
        if (s.level != 0) fail(i, "a hit above level 0");
        if (i + 1 != steps.size()) fail(i, "a hit is not the last step");
        if (andEmpty || s.hitSlice < s.first || s.hitSlice > s.last) fail(i, "a hit with an empty AND or outside the slice range");
      } else if (s.action == kDescend) {
        ++descends;
        if (andEmpty || s.level == 0) fail(i, "a descend with an empty AND or at level 0");
        if (i + 1 < steps.size() && steps[i + 1].level + 1 != s.level) fail(i, "the level after a descend is not one finer");
      } else if (s.action == kAdvance) {
        ++advances;
        if (!andEmpty) fail(i, "an advance past a texel whose AND is not empty");
        // One coarser, or the same at the top level (the highest level the walk shows).
        if (i + 1 < steps.size() && steps[i + 1].level != s.level + 1 &&
            !(steps[i + 1].level == s.level && s.level == topLevel))
          fail(i, "the level after an advance is not one coarser (or the top)");
      } else {
        fail(i, "unknown action");
      }
    }
    std::snprintf(buf, sizeof buf, "%zu steps (%d descend, %d advance), %s", steps.size(), descends, advances,
                  steps.empty() ? "no walk" : steps.back().action == kHit ? "ends in a hit" : "ends without a hit");
    c.summary = buf;
    return c;
  }

  size_t recordSteps(const CapturedOutput& out) const override { return decodeSteps(out).size(); }
  std::string describeRecordStep(const CapturedOutput& out, size_t k) const override {
    const auto steps = decodeSteps(out);
    return k < steps.size() ? stepLine(steps[k]) : "";
  }

  void drawRecordView(const VisualiserContext& ctx) const override {
    const auto steps = decodeSteps(ctx.out);
    const RecordCheck check = checkRecords(ctx.out);
    ImGui::Text("%s", check.summary.c_str());
    if (!check.error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", check.error.c_str());
    // Step through the walk one step at a time: the chosen step's ray mask and AND as stacks. The
    // slider's value is the viewer's (ctx.recordStep: the script verb record-step moves it too).
    static std::map<const ViewSettings*, int> chosen;
    int& k = ctx.recordStep ? *ctx.recordStep : chosen[&ctx.view];
    if (!steps.empty()) {
      k = std::clamp(k, 0, int(steps.size()) - 1);
      ImGui::SliderInt("step", &k, 0, int(steps.size()) - 1);
      ImGui::SameLine();
      if (ImGui::ArrowButton("prev", ImGuiDir_Left)) k = std::max(k - 1, 0);
      ImGui::SameLine();
      if (ImGui::ArrowButton("next", ImGuiDir_Right)) k = std::min(k + 1, int(steps.size()) - 1);
      const Step& s = steps[size_t(k)];
      ImGui::TextUnformatted(stepLine(s).c_str());
      drawStack("ray mask", s.ray, nullptr, 1.5f);
      ImGui::SameLine();
      drawStack("AND column", s.hit, nullptr, 1.5f);
    }
    ImGui::TextDisabled("bit strips: 128 slices left to right; grey = ray mask, white = ray mask AND column");
    if (!ImGui::BeginTable("walk", 7, ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg | ImGuiTableFlags_ScrollY | ImGuiTableFlags_ScrollX | ImGuiTableFlags_SizingFixedFit,
                           ImVec2(0, 320)))
      return;
    for (const char* h : {"step", "level", "texel", "slices", "t in / out", "masks", "action"}) ImGui::TableSetupColumn(h);
    ImGui::TableHeadersRow();
    for (const Step& s : steps) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::Text("%u", s.step);
      ImGui::TableNextColumn();
      ImGui::Text("%u", s.level);
      ImGui::TableNextColumn();
      ImGui::Text("(%u, %u)", s.x, s.y);
      ImGui::TableNextColumn();
      ImGui::Text("%u..%u", s.first, s.last);
      ImGui::TableNextColumn();
      ImGui::Text("%.4f / %.4f", s.tEnter, s.tExit);
      ImGui::TableNextColumn();
      ImDrawList* dl = ImGui::GetWindowDrawList();
      const ImVec2 at = ImGui::GetCursorScreenPos();
      for (int k = 0; k < kSlices; ++k) {
        const ImU32 col = sliceSet(s.hit, k) ? IM_COL32(255, 255, 255, 255)
                          : sliceSet(s.ray, k) ? IM_COL32(120, 120, 130, 255)
                                               : IM_COL32(30, 30, 36, 255);
        dl->AddRectFilled(ImVec2(at.x + 2.0f * k, at.y + 2), ImVec2(at.x + 2.0f * k + 2.0f, at.y + 12), col);
      }
      ImGui::Dummy(ImVec2(2.0f * kSlices, 14));
      ImGui::TableNextColumn();
      if (s.action == kHit) ImGui::Text("hit slice %u", s.hitSlice);
      else ImGui::TextUnformatted(actionName(s.action));
    }
    ImGui::EndTable();
  }
};

// --- the brute-force DDA beside the walk ----------------------------------------------------------

struct DdaRecord {
  float cell[3], tEnter;
  uint32_t set, walkHit, pad[2];
};

std::vector<DdaRecord> decodeDda(const CapturedOutput& out) { return recordsAs<DdaRecord>(out); }

// The DDA visits face neighbours in order and stops at the first set cell; the walk's hit, when the
// DDA visits that cell, is that first set cell (the hierarchy finds what the DDA finds).
class DdaVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "near-field-dda"; }

  RecordCheck checkRecords(const CapturedOutput& out) const override {
    RecordCheck c;
    const auto r = decodeDda(out);
    c.elements = r.size();
    char buf[200];
    for (size_t i = 0; i < r.size() && c.error.empty(); ++i) {
      if (i > 0) {
        int moved = 0, by = 0;
        for (int a = 0; a < 3; ++a) {
          const int d = int(r[i].cell[a]) - int(r[i - 1].cell[a]);
          moved += d != 0;
          by += std::abs(d);
        }
        if (moved != 1 || by != 1 || r[i].tEnter < r[i - 1].tEnter) {
          std::snprintf(buf, sizeof buf, "cell %zu is not the face neighbour after cell %zu, or t went back", i, i - 1);
          c.error = buf;
        }
      }
      if ((r[i].set || r[i].walkHit) && i + 1 != r.size()) {
        std::snprintf(buf, sizeof buf, "cell %zu is set or the walk's hit but the DDA went on", i);
        c.error = buf;
      }
    }
    const bool hit = !r.empty() && r.back().set;
    const bool same = hit && r.back().walkHit;
    std::snprintf(buf, sizeof buf, "%zu cells, %s", r.size(),
                  !hit ? "no set cell on the segment" : same ? "first set cell = the walk's hit" : "first set cell (the walk hit another: a tie, or no hit)");
    c.summary = buf;
    return c;
  }

  void drawRecordView(const VisualiserContext& ctx) const override {
    const RecordCheck check = checkRecords(ctx.out);
    ImGui::Text("%s", check.summary.c_str());
    if (!check.error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", check.error.c_str());
    ImGui::TextDisabled("every level-0 cell the segment crosses; the hierarchical walk above skipped the empty runs");
    BufferVisualiser::drawRecordView(ctx);
  }
};

// --- the probed ray: its hit voxel beside the true surface point -----------------------------------

const char* endName(uint32_t e) {
  switch (e) {
    case NF_END_HIT: return "hit";
    case NF_END_LEFT: return "left the segment or the volume";
    case NF_END_BUDGET: return "step budget spent";
    case NF_END_OUTSIDE: return "origin outside the volume (guard)";
    case NF_END_DROPPED: return "dropped (start offset > radius)";
    default: return "?";
  }
}

bool decodeProbeRay(const CapturedOutput& out, gpu::ProbeRay& p) {
  if (out.desc.layout.stride != sizeof(gpu::ProbeRay) || out.recordCount < 1 || out.records.size() < sizeof(p)) return false;
  std::memcpy(&p, out.records.data(), sizeof(p));
  return true;
}

// The RSM lookup of the probed ray: the texel, what the RSM holds there, the distance against the
// threshold, the normal test, and the category they give (the order of ray_common.glsl's lookupRsm:
// distance first, then facing). Returns "" when the record is consistent, else what is not.
struct RsmLookupView {
  int category = -1;
  bool traced = false;     // the record was written (a ray of the probed index ran)
  bool looked = false;     // the walk hit and the hit has a texel in the RSM
  bool covered = false;    // that texel holds a surface
  bool normalCheck = false, plane = false;
  std::string error;
};

RsmLookupView rsmLookupOf(const gpu::ProbeRay& p) {
  RsmLookupView v;
  v.category = int(p.rsmRadiance.w);
  v.traced = !(p.receiver.w < 0.5f && v.category == 0);  // an all-zero record: the probed ray index has not run
  v.looked = p.result.w == NF_END_HIT && p.rsmSample.x >= 0.0f;
  v.covered = v.looked && p.rsmPosition.w > 0.0f;
  const int flags = int(p.rsmNormal.w);
  v.normalCheck = (flags & 1) != 0;
  v.plane = (flags & 2) != 0;
  if (!v.traced) return v;
  if (float(v.category) != p.rsmRadiance.w || v.category < 0 || v.category >= NF_CATEGORIES) {
    v.error = "the RSM lookup's category is not one of 0..7";
    return v;
  }
  const bool within = p.rsmSample.z <= p.rsmSample.w, faces = p.steps.z >= 0.0f;
  const bool looked = v.category == NF_CAT_VALID || v.category == NF_CAT_TOO_FAR || v.category == NF_CAT_WRONG_FACING;
  if (p.receiver.w < 0.5f) {
    if (v.category != NF_CAT_NO_RECEIVER) v.error = "a pixel without a receiver has a lookup category other than no receiver";
  } else if (looked && !v.covered) {
    v.error = "a lookup category that needs an RSM surface without a hit or a covered RSM texel";
  } else if (v.category == NF_CAT_TOO_FAR && within) {
    v.error = "category too far with the distance within the threshold";
  } else if ((v.category == NF_CAT_VALID || v.category == NF_CAT_WRONG_FACING) && !within) {
    v.error = "category valid or wrong facing with the distance beyond the threshold";
  } else if (v.category == NF_CAT_WRONG_FACING && !(v.normalCheck && !faces)) {
    v.error = "category wrong facing without a failed normal test";
  } else if (v.category == NF_CAT_VALID && v.normalCheck && !faces) {
    v.error = "category valid with a failed normal test";
  } else if (p.result.w == NF_END_HIT && !looked && v.category != NF_CAT_NOT_IN_RSM) {
    v.error = "a hit whose lookup category is not valid, not in the RSM, too far or wrong facing";
  } else if (p.result.w != NF_END_HIT && looked) {
    v.error = "an RSM lookup without a hit";
  } else if (looked && !v.plane) {
    // The distance is |hit - RSM position| of the same two points, both recorded in float (measured
    // equal to the shader's on the Cornell box); another rounding order moves it by about 1e-7
    // relative, so 1e-5 relative (Sponza's 30 m: 0.3 mm) is far below the voxel-sized threshold.
    const float d = glm::length(glm::vec3(p.hitPoint) - glm::vec3(p.rsmPosition));
    if (std::abs(d - p.rsmSample.z) > 1e-5f * std::max(1.0f, glm::length(glm::vec3(p.hitPoint))))
      v.error = "the recorded distance is not |hit point - RSM position|";
  }
  return v;
}

void drawRsmLookup(const gpu::ProbeRay& p) {
  const RsmLookupView v = rsmLookupOf(p);
  ImGui::Separator();
  ImGui::TextUnformatted("RSM lookup");
  if (!v.traced) {
    ImGui::TextDisabled("the probed ray index has not been traced yet");
    return;
  }
  if (p.result.w != NF_END_HIT) {
    ImGui::TextUnformatted("no lookup: the walk did not hit a voxel");
  } else if (!v.looked) {
    ImGui::TextUnformatted("no texel: the hit point is behind the light or outside its map");
  } else {
    ImGui::Text("texel (%.0f, %.0f) of the RSM", p.rsmSample.x, p.rsmSample.y);
    if (!v.covered) {
      ImGui::TextUnformatted("the texel is empty: the light's map sees no surface there");
    } else {
      ImGui::Text("RSM position (%.4f, %.4f, %.4f), texel footprint %.4f m", p.rsmPosition.x, p.rsmPosition.y,
                  p.rsmPosition.z, p.rsmPosition.w);
      ImGui::Text("RSM normal   (%.3f, %.3f, %.3f)", p.rsmNormal.x, p.rsmNormal.y, p.rsmNormal.z);
      const bool within = p.rsmSample.z <= p.rsmSample.w;
      if (p.rsmSample.z >= 1e29f)
        ImGui::Text("distance: the RSM surface lies beyond 4 voxel diagonals + the footprint along its plane -> too far");
      else
        ImGui::Text("distance %s = %.4f m vs threshold %.4f m -> %s",
                    v.plane ? "from the RSM surface's plane" : "|hit - RSM position|", p.rsmSample.z, p.rsmSample.w,
                    within ? "the same surface (within)" : "another surface (too far)");
      if (!within)
        ImGui::TextDisabled("normal test: not reached (the distance test failed first)");
      else if (!v.normalCheck)
        ImGui::Text("normal test: off (rsm.normal-check); cos(RSM normal, hit -> receiver) = %.3f", p.steps.z);
      else
        ImGui::Text("normal test: cos(RSM normal, hit -> receiver) = %.3f -> %s", p.steps.z,
                    p.steps.z >= 0.0f ? "faces the receiver (pass)" : "faces away (fail)");
    }
  }
  ImGui::Text("category %d: %s (%s)", v.category, rsmLookupCategoryName(v.category), rsmLookupCategoryMeaning(v.category));
  if (v.category == NF_CAT_VALID)
    ImGui::Text("reflected radiance L~ (%.4g, %.4g, %.4g)", p.rsmRadiance.x, p.rsmRadiance.y, p.rsmRadiance.z);
  if (!v.error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", v.error.c_str());
}

// The check holds what the record's CPU half must keep: the surface point lies on the recorded
// ray at its t, within the radius left; the gaps are set exactly when there are both a hit voxel
// and a surface point, and the largest axis distance is at most the Euclidean one and at least
// 1/sqrt(3) of it.
class ProbeRayVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "near-field-probe-ray"; }

  RecordCheck checkRecords(const CapturedOutput& out) const override {
    RecordCheck c;
    gpu::ProbeRay p;
    if (!decodeProbeRay(out, p)) {
      c.error = "no probe-ray record of the expected size";
      return c;
    }
    c.elements = 1;
    const bool surface = p.surface.w >= 0.0f, hit = p.result.w == NF_END_HIT;
    char buf[240];
    if (surface) {
      const glm::vec3 onRay = glm::vec3(p.origin) + glm::vec3(p.direction) * p.surface.w;
      const float err = glm::length(onRay - glm::vec3(p.surface));
      // float rounding of o + t d at scene scale: 1e-5 relative (Sponza's 30 m: 0.3 mm) is far below a voxel.
      if (!(err <= 1e-5f * std::max(1.0f, glm::length(onRay)))) c.error = "the surface point is not on the recorded ray at its t";
      if (!(p.surface.w > 0.0f && p.surface.w <= p.origin.w * (1.0f + 1e-6f))) c.error = "the surface's t is outside (0, radius left]";
    }
    const bool gapSet = p.surfaceGap.x >= 0.0f;
    if (gapSet != (surface && hit)) c.error = "the voxel gap is set without both a hit voxel and a surface point (or missing)";
    if (gapSet && !(p.surfaceGap.x <= p.surfaceGap.y * (1.0f + 1e-6f) && p.surfaceGap.y <= 1.7320509f * p.surfaceGap.x * (1.0f + 1e-6f) + 1e-6f))
      c.error = "the voxel gap's largest axis distance and Euclidean length disagree";
    const RsmLookupView lookup = rsmLookupOf(p);
    if (!lookup.error.empty()) c.error = lookup.error;
    if (!hit) std::snprintf(buf, sizeof buf, "walk: %s; %s", endName(p.result.w), surface ? "a surface lies within the radius" : "no surface within the radius");
    else if (!surface) std::snprintf(buf, sizeof buf, "hit voxel (%u, %u, %u); no surface within the radius", p.result.x, p.result.y, p.result.z);
    else std::snprintf(buf, sizeof buf, "hit voxel (%u, %u, %u), true surface %.3g voxels away (%s)", p.result.x, p.result.y, p.result.z,
                       p.surfaceGap.x, p.surfaceGap.x == 0.0f ? "inside it" : p.surfaceGap.x <= 1.0f ? "in a neighbour" : "farther");
    c.summary = buf;
    if (lookup.traced) c.summary += std::string("; RSM lookup: ") + rsmLookupCategoryName(lookup.category);
    return c;
  }

  void drawRecordView(const VisualiserContext& ctx) const override {
    const RecordCheck check = checkRecords(ctx.out);
    gpu::ProbeRay p;
    if (decodeProbeRay(ctx.out, p) && p.receiver.w > 0.5f) {
      ImGui::Text("receiver (%.4f, %.4f, %.4f), direction (%.4f, %.4f, %.4f), cos theta %.3f", p.receiver.x, p.receiver.y,
                  p.receiver.z, p.direction.x, p.direction.y, p.direction.z, p.direction.w);
      ImGui::Text("offset origin (%.4f, %.4f, %.4f), radius left %.4f m", p.origin.x, p.origin.y, p.origin.z, p.origin.w);
      ImGui::Text("walk: %s after %.0f of %.0f steps", endName(p.result.w), p.steps.x, p.steps.y);
      if (p.result.w == NF_END_HIT)
        ImGui::Text("hit voxel (%u, %u, slice %u), entered at t = %.4f m, point (%.4f, %.4f, %.4f)", p.result.x, p.result.y,
                    p.result.z, p.hitPoint.w, p.hitPoint.x, p.hitPoint.y, p.hitPoint.z);
      if (p.surface.w >= 0.0f)
        ImGui::Text("true surface: triangle %.0f at t = %.4f m, point (%.4f, %.4f, %.4f)", p.surfaceGap.w, p.surface.w,
                    p.surface.x, p.surface.y, p.surface.z);
      else
        ImGui::TextUnformatted("true surface: no triangle within the radius left");
      if (p.surfaceGap.x >= 0.0f) {
        ImGui::Text("hit voxel vs surface: %.3f voxels (largest axis), %.3f (Euclidean), %.3f voxel diagonals along the ray",
                    p.surfaceGap.x, p.surfaceGap.y, p.surfaceGap.z);
        ImGui::TextDisabled(p.surfaceGap.x == 0.0f  ? "the surface point lies in the hit voxel"
                            : p.surfaceGap.x <= 1.0f ? "the surface point lies in a voxel touching the hit voxel"
                                                     : "the walk stopped earlier: another surface's conservative voxel, or a grazing ray");
      }
    }
    if (decodeProbeRay(ctx.out, p)) drawRsmLookup(p);
    ImGui::Text("%s", check.summary.c_str());
    if (!check.error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", check.error.c_str());
    BufferVisualiser::drawRecordView(ctx);
  }
};

}  // namespace

VOXLAB_REGISTER_VISUALISER(ProbeRayVisualiser, OutputKind::Buffer, nearfield::kProbeRay.name());
VOXLAB_REGISTER_VISUALISER(BitmaskColumnsVisualiser, OutputKind::Image2D, kBitmaskColumns.name());
VOXLAB_REGISTER_VISUALISER(DdaVisualiser, OutputKind::Buffer, nearfield::kProbeDda.name());
VOXLAB_REGISTER_VISUALISER(TraversalVisualiser, OutputKind::Buffer, nearfield::kTraversalSteps.name());

}  // namespace voxlab
