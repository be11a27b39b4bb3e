// Categories of a ray's RSM lookup (semantic `rsm-lookup-category`): an R32UI image whose texel
// is the outcome of the last ray traced from that pixel (NF_CAT_* in
// shaders/near_field/near_field_shared.h): valid, no hit, not in the RSM (behind the light or
// outside its map), too far from the RSM's surface, wrong facing, step budget spent, dropped,
// no receiver. A category is a name, not a magnitude, so it gets one distinct colour each (the
// viewer and the PNGs `voxlab run` writes), a legend with each category's pixel count in the
// inspector and in a caption, the category's name under the cursor, and per-category pixel
// counts in the statistics (`categories`), which the tests compare with the stage's counters.
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include <imgui.h>

#include "inspect/visualisers/levels.h"
#include "near_field/near_field_shared.h"
#include "techniques/near_field/stages.h"
#include "techniques/near_field/views/ray_category.h"

namespace voxlab {
namespace {

struct Category {
  const char* key;    // statistics key
  const char* name;   // legend and hover
  const char* means;  // one line of explanation
  uint8_t rgb[3];
};

constexpr Category kCategories[NF_CATEGORIES] = {
    {"valid", "valid", "hit; the RSM sees that surface, facing the receiver: its radiance counts", {70, 200, 90}},
    {"no_hit", "no hit", "no voxel within the radius (or the ray left the volume)", {90, 90, 105}},
    {"not_in_rsm", "behind light / not in RSM", "the hit is behind the light or outside its map", {160, 95, 225}},
    {"too_far", "too far", "the RSM sees another surface there: distance > threshold", {245, 150, 35}},
    {"wrong_facing", "wrong facing", "the sender faces away from the receiver", {230, 55, 55}},
    {"budget_spent", "step budget spent", "the walk ran out of steps (counted, would silently be a miss)", {245, 235, 60}},
    {"dropped", "dropped", "the start offset used up the ray's radius", {50, 175, 235}},
    {"no_receiver", "no receiver", "no geometry at the pixel: no ray", {0, 0, 0}},
};
constexpr uint8_t kUnknown[3] = {255, 0, 255};  // a value outside 0..7: a bug, shown magenta

int categoryOf(float v) {
  const int k = int(std::lround(v));
  return k >= 0 && k < NF_CATEGORIES && float(k) == v ? k : -1;
}

void categoryColour(const float* v, int, float, float, float, uint8_t* o) {
  const int k = categoryOf(v[0]);
  const uint8_t* c = k >= 0 ? kCategories[k].rgb : kUnknown;
  o[0] = c[0], o[1] = c[1], o[2] = c[2];
}

struct Registration {
  //                                                              mapping     normalise alphaIsOpacity exact
  Registration() { registerTexelMapping(nearfield::kRayCategory, {&categoryColour, false, false, true}); }
} registration;

// Pixels per category of level 0 (index NF_CATEGORIES: values outside the categories).
std::array<size_t, NF_CATEGORIES + 1> countCategories(const CapturedOutput& out) {
  std::array<size_t, NF_CATEGORIES + 1> n{};
  if (out.levels.empty()) return n;
  const LevelData& L = out.levels[0];
  for (size_t i = 0; i < L.texelCount(); ++i) {
    const int k = categoryOf(L.values[i * size_t(L.channels)]);
    ++n[k >= 0 ? size_t(k) : size_t(NF_CATEGORIES)];
  }
  return n;
}

class RayCategoryVisualiser : public ImageVisualiser {
 public:
  const char* name() const override { return "rsm-lookup-category"; }

  nlohmann::json statistics(const CapturedOutput& out) const override {
    nlohmann::json s = LevelVisualiser::statistics(out);
    const auto n = countCategories(out);
    nlohmann::json c = nlohmann::json::object();
    for (int k = 0; k < NF_CATEGORIES; ++k) c[kCategories[k].key] = n[size_t(k)];
    c["unknown"] = n[NF_CATEGORIES];
    s["categories"] = c;
    return s;
  }

  std::string describeElement(const VisualiserContext& ctx, const glm::ivec3& t) const override {
    const LevelData* L = shownLevel(ctx);
    if (!L || t.x < 0 || t.y < 0 || t.x >= L->size.x || t.y >= L->size.y) return "";
    const float v = L->at(t.x, t.y, 0, 0);
    const int k = categoryOf(v);
    char buf[200];
    if (k < 0)
      std::snprintf(buf, sizeof buf, "pixel (%d, %d) = %g: not a category (0..%d)", t.x, L->size.y - 1 - t.y, v, NF_CATEGORIES - 1);
    else
      std::snprintf(buf, sizeof buf, "pixel (%d, %d) = %d: %s (%s)", t.x, L->size.y - 1 - t.y, k, kCategories[k].name,
                    kCategories[k].means);
    return buf;
  }

  std::string caption(const VisualiserContext& ctx) const override {
    const auto n = countCategories(ctx.out);
    std::string s = "the last ray's lookup per pixel:";
    static const char* colourNames[NF_CATEGORIES] = {"green", "grey", "purple", "orange", "red", "yellow", "blue", "black"};
    for (int k = 0; k < NF_CATEGORIES; ++k)
      if (n[size_t(k)] > 0) s += std::string(" ") + colourNames[k] + " " + kCategories[k].name + " (" + std::to_string(n[size_t(k)]) + ");";
    if (n[NF_CATEGORIES] > 0) s += " magenta: not a category (" + std::to_string(n[NF_CATEGORIES]) + ")";
    return s;
  }

  void drawInspector(const VisualiserContext& ctx) const override {
    const auto n = countCategories(ctx.out);
    size_t total = 0;
    for (size_t c : n) total += c;
    ImGui::TextUnformatted("legend: the last ray's RSM lookup per pixel");
    if (ImGui::BeginTable("categories", 4, ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit)) {
      for (const char* h : {"", "category", "pixels", "meaning"}) ImGui::TableSetupColumn(h);
      ImGui::TableHeadersRow();
      for (int k = 0; k <= NF_CATEGORIES; ++k) {
        if (k == NF_CATEGORIES && n[size_t(k)] == 0) break;
        const uint8_t* c = k < NF_CATEGORIES ? kCategories[k].rgb : kUnknown;
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        ImGui::PushID(k);
        ImGui::ColorButton("##swatch", ImVec4(c[0] / 255.0f, c[1] / 255.0f, c[2] / 255.0f, 1.0f),
                           ImGuiColorEditFlags_NoTooltip | ImGuiColorEditFlags_NoBorder, ImVec2(14, 14));
        ImGui::PopID();
        ImGui::TableNextColumn();
        if (k < NF_CATEGORIES) ImGui::Text("%d %s", k, kCategories[k].name);
        else ImGui::TextUnformatted("not a category");
        ImGui::TableNextColumn();
        ImGui::Text("%zu (%.1f %%)", n[size_t(k)], total ? 100.0 * double(n[size_t(k)]) / double(total) : 0.0);
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(k < NF_CATEGORIES ? kCategories[k].means : "a bug in the stage");
      }
      ImGui::EndTable();
    }
    ImageVisualiser::drawInspector(ctx);
  }
};

}  // namespace

const char* rsmLookupCategoryName(int k) { return k >= 0 && k < NF_CATEGORIES ? kCategories[k].name : "not a category"; }
const char* rsmLookupCategoryMeaning(int k) { return k >= 0 && k < NF_CATEGORIES ? kCategories[k].means : "a bug in the stage"; }

VOXLAB_REGISTER_VISUALISER(RayCategoryVisualiser, OutputKind::Image2D, nearfield::kRayCategory.name());

}  // namespace voxlab
