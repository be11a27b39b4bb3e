// Capture: reads any declared output back from the GPU and turns it into files and statistics,
// driven only by its OutputDesc (kind, semantic, layout). Used by `voxlab run`, the snapshot
// suite, the viewer's export and the benchmark.
#pragma once
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "graph/blackboard.h"
#include "graph/output.h"

namespace voxlab {

// One level of an image or volume, as floats (integers converted exactly up to 2^24).
struct LevelData {
  glm::ivec3 size{0};  // depth 1 for images
  int channels = 0;
  std::vector<float> values;  // x fastest, then y (row 0 = bottom, GL order), then z; channels interleaved
  // Integer formats only: the same texels as read (values holds them as float, exact below 2^24;
  // a 32-bit mask needs these).
  std::vector<uint32_t> integers;
  size_t texelCount() const { return size_t(size.x) * size.y * size.z; }
  float at(int x, int y, int z, int c) const {
    return values[((size_t(z) * size.y + y) * size.x + x) * channels + c];
  }
};

struct CapturedOutput {
  OutputDesc desc;
  std::string format;              // "rgba8", "r32f", ... or "records" for buffers
  std::vector<LevelData> levels;   // images and volumes
  uint32_t recordCount = 0;        // buffers
  std::vector<uint8_t> records;    // buffers: recordCount * layout.stride bytes
  std::optional<WorldBox> world;   // volumes (and placed images): where level 0 sits in the scene (Blackboard::placementOf)
};

CapturedOutput captureOutput(Blackboard& board, const OutputDesc& desc);

// Per-level statistics: min/max/mean per channel, non-empty texel count; buffers: count and
// per-field ranges. The manifest and the snapshot suite use these.
nlohmann::json outputStatistics(const CapturedOutput& out);

// A texel is non-empty when any channel is non-zero (for the Opacity/Color semantics of an
// RGBA volume: when alpha is non-zero).
bool texelNonEmpty(const CapturedOutput& out, const LevelData& level, size_t texel);

// Display mapping by semantic: returns 8-bit RGB of 'level' as a top-row-first image.
// Volumes become a montage of z slices (at most 64 slices, evenly spaced, with 1-pixel gaps).
struct DisplayImage {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
};
DisplayImage displayImage(const CapturedOutput& out, int level);
// 'left' and 'right' side by side, 'gap' black columns between them, top-aligned (the taller sets
// the height; the shorter is padded black): the viewer's side-by-side compare view as one picture.
constexpr int kBesideGap = 8;
DisplayImage besideImage(const DisplayImage& left, const DisplayImage& right, int gap = kBesideGap);
// Buffers with a Position field, as splats from a fixed three-quarter view. 'pick' (optional)
// receives, per pixel (top row first), the index of the record drawn there or -1.
DisplayImage pointView(const CapturedOutput& out, int size = 512, std::vector<int32_t>* pick = nullptr);
// Record 'index' of a buffer, decoded by its layout (as one element of recordsJson).
nlohmann::json recordJson(const CapturedOutput& out, uint32_t index);

// Records of a buffer with a Position field as points: position (times layout.positionScale) and
// the Color field's first three components (linear; 0.9 grey without one), the Normal field (zero
// without one). Empty without a Position field.
struct RecordPoint {
  glm::vec3 position{0.0f};
  glm::vec3 color{0.9f};
  glm::vec3 normal{0.0f};
};
std::vector<RecordPoint> recordPoints(const CapturedOutput& out);

// Writes the output's files into 'dir' with names "<prefix>.<ext>" / "<prefix>@L.<ext>" and
// returns the manifest entry (files, statistics, format, levels).
nlohmann::json writeOutputFiles(const CapturedOutput& out, const std::string& dir, const std::string& prefix);

// Values of one level as an EXR (volumes unrolled: width x (height * depth), attribute
// voxlab:depth). Row order is top-row-first in the file. With the texture's format (attribute
// voxlab:format; writeLevelFiles passes it), 8-bit and 16-bit float textures are stored as half
// floats, which keep their values; without one (goldens, difference images), 32-bit floats.
void writeLevelExr(const LevelData& level, const std::string& path, const std::string& semantic,
                   const std::string& textureFormat = "");
LevelData readLevelExr(const std::string& path);  // throws Error
void writePng(const DisplayImage& image, const std::string& path);

// Decoded records of a buffer output as JSON (first 'limit' records).
nlohmann::json recordsJson(const CapturedOutput& out, size_t limit);

// The records of a buffer output as structs of type T (a shared layout from shaders/*_shared.h):
// empty when the output's stride is not sizeof(T), else min(recordCount, what the bytes hold).
template <typename T>
std::vector<T> recordsAs(const CapturedOutput& out) {
  std::vector<T> v;
  if (out.desc.layout.stride != sizeof(T)) return v;
  v.resize(std::min<size_t>(out.recordCount, out.records.size() / sizeof(T)));
  if (!v.empty()) std::memcpy(static_cast<void*>(v.data()), out.records.data(), v.size() * sizeof(T));
  return v;
}

}  // namespace voxlab
