// Buffers of records: the record table, statistics per field, the point view of records with a
// Position field (2D: a fixed three-quarter splat view; 3D: points shaded by their normal, or one
// cube per record). Files: <prefix>.json (count, statistics, first records), .bin (raw records),
// .points.png. Golden: raw records with a per-value tolerance (points.cpp: exact sorted sets).
#include "inspect/visualisers/buffer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <imgui.h>

#include "inspect/view3d.h"

namespace voxlab {

namespace {
const glm::vec3 kPointLight = glm::normalize(glm::vec3(0.45f, 0.8f, 0.4f));
}

bool BufferVisualiser::hasPositions(const OutputDesc& d) {
  return std::any_of(d.layout.fields.begin(), d.layout.fields.end(),
                     [](const BufferField& f) { return f.role == FieldRole::Position; });
}

nlohmann::json BufferVisualiser::statistics(const CapturedOutput& out) const { return recordStatistics(out); }

nlohmann::json BufferVisualiser::writeFiles(const CapturedOutput& out, const std::string& dir,
                                            const std::string& prefix) const {
  nlohmann::json stats = statistics(out);
  nlohmann::json entry = manifestEntry(out, stats);
  nlohmann::json files = nlohmann::json::array();
  writeRecordFiles(out, dir, prefix, stats, files);
  if (hasPositions(out.desc)) {
    files.push_back(prefix + ".points.png");
    writePng(pointView(out), dir + "/" + prefix + ".points.png");
  }
  entry["files"] = files;
  return entry;
}

GoldenResult BufferVisualiser::compareGolden(const CapturedOutput& out, const GoldenRequest& request) const {
  return compareRecordsWithGolden(out, request);
}

SliceImage BufferVisualiser::image2D(const VisualiserContext& ctx) const {
  SliceImage img;
  if (!hasPositions(ctx.out.desc)) return img;
  DisplayImage pv = pointView(ctx.out, 512, &img.pick);
  img.width = pv.width;
  img.height = pv.height;
  img.rgba.resize(size_t(pv.width) * pv.height * 4);
  for (size_t i = 0; i < size_t(pv.width) * pv.height; ++i) {
    for (int c = 0; c < 3; ++c) img.rgba[i * 4 + c] = pv.rgb[i * 3 + c];
    img.rgba[i * 4 + 3] = 255;
  }
  return img;
}

std::string BufferVisualiser::describeElement(const VisualiserContext& ctx, const glm::ivec3& element) const {
  if (element.x < 0 || uint32_t(element.x) >= ctx.out.recordCount) return "";
  std::string s = "record " + std::to_string(element.x) + ":";
  nlohmann::json r = recordJson(ctx.out, uint32_t(element.x));
  for (auto it = r.begin(); it != r.end(); ++it) {
    std::string v;
    char buf[32];
    for (const auto& c : it.value().is_array() ? it.value() : nlohmann::json::array({it.value()})) {
      std::snprintf(buf, sizeof buf, "%s%.4g", v.empty() ? "" : ", ", c.get<double>());
      v += buf;
    }
    s += " " + it.key() + " (" + v + ")";
  }
  return s;
}

std::string BufferVisualiser::caption(const VisualiserContext& ctx) const {
  return std::to_string(ctx.out.recordCount) + " records" +
         (hasPositions(ctx.out.desc) ? " (point view; hover or click a point for its record)" : "");
}

Content3D BufferVisualiser::build3D(const VisualiserContext& ctx, View3D& view) const {
  Content3D c;
  std::vector<RecordPoint> pts = recordPoints(ctx.out);
  bool integer = false;
  for (const auto& f : ctx.out.desc.layout.fields)
    if (f.role == FieldRole::Position)
      integer = f.type == FieldType::Packed10_10_10 || f.type == FieldType::U32 || f.type == FieldType::I32;
  std::vector<ViewInstance> points, cubes;
  glm::vec3 plo(1e30f), phi(-1e30f);
  for (const auto& r : pts) {
    glm::vec3 p = r.position + (integer ? 0.5f : 0.0f);  // integer positions name voxels: show their centres
    glm::vec4 col(srgbEncode(r.color.x), srgbEncode(r.color.y), srgbEncode(r.color.z), 1.0f);
    // Points have no faces: shade them by their normal (when the layout has one) from a fixed
    // direction, so surfaces of one albedo stay apart. Cubes are shaded by face instead.
    float shade = glm::length(r.normal) > 0.1f ? 0.45f + 0.55f * std::abs(glm::dot(glm::normalize(r.normal), kPointLight)) : 1.0f;
    points.push_back({glm::vec4(p, 1.0f), glm::vec4(glm::vec3(col) * shade, 1.0f)});
    cubes.push_back({glm::vec4(p - 0.5f, 1.0f), col});
    plo = glm::min(plo, p - 0.5f);
    phi = glm::max(phi, p + 0.5f);
  }
  view.setPoints(std::move(points));
  view.setCubes(std::move(cubes));
  if (!pts.empty()) c.lo = glm::floor(plo), c.hi = glm::ceil(phi);
  c.info = std::to_string(pts.size()) + " records";
  if (pts.empty()) c.message = "no records";
  return c;
}

void BufferVisualiser::drawInspector(const VisualiserContext& ctx) const {
  ImGui::Text("%u records, stride %u bytes", ctx.out.recordCount, ctx.out.desc.layout.stride);
  drawRecordsTable("records", ctx.records, 300.0f);
}

VOXLAB_REGISTER_VISUALISER(BufferVisualiser, OutputKind::Buffer, kAnySemantic);

}  // namespace voxlab
