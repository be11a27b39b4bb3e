#include "capture/output_handler.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>

#include "core/error.h"

namespace voxlab {

using nlohmann::json;
namespace fs = std::filesystem;

// --- Registries ------------------------------------------------------------------------------------

namespace {

// Function-local statics: registration runs during static initialisation of other files.
std::map<std::pair<int, std::string>, const OutputHandler*>& handlers() {
  static std::map<std::pair<int, std::string>, const OutputHandler*> m;
  return m;
}
std::map<std::string, TexelMapping>& mappings() {
  static std::map<std::string, TexelMapping> m;
  return m;
}

void rampMap(const float* v, int, float, float lo, float hi, uint8_t* rgb) {
  falseColourRamp(hi > lo ? (v[0] - lo) / (hi - lo) : 0.0f, rgb);
}

}  // namespace

const OutputHandler& outputHandler(OutputKind kind, Semantic semantic) {
  auto& m = handlers();
  auto it = m.find({int(kind), semantic.name()});
  if (it == m.end()) it = m.find({int(kind), ""});
  if (it == m.end())
    throw Error(std::string("no visualiser handles ") + kindName(kind) + " outputs (semantic " + semantic.name() +
                "); register one with VOXLAB_REGISTER_VISUALISER");
  return *it->second;
}

void registerOutputHandler(OutputKind kind, const char* semantic, const OutputHandler* handler) {
  handlers()[{int(kind), semantic ? semantic : ""}] = handler;
}

CaptureTier captureTier(const OutputDesc& d) {
  return d.tier != CaptureTier::Default ? d.tier : outputHandler(d).defaultTier(d);
}

const TexelMapping& texelMapping(Semantic semantic) {
  static const TexelMapping fallback{&rampMap, true, false, false};
  auto it = mappings().find(semantic.name());
  return it == mappings().end() ? fallback : it->second;
}

void registerTexelMapping(Semantic semantic, const TexelMapping& mapping) { mappings()[semantic.name()] = mapping; }

uint8_t unitToByte(float v) { return uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

float srgbEncode(float x) {
  x = std::clamp(x, 0.0f, 1.0f);
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}

void falseColourRamp(float t, uint8_t* rgb) {
  // Dark blue -> teal -> green -> yellow (voxlab's own stops), brighter for larger values.
  static const float stops[4][3] = {{0.05f, 0.03f, 0.25f}, {0.10f, 0.45f, 0.55f}, {0.35f, 0.75f, 0.30f},
                                    {0.98f, 0.92f, 0.25f}};
  t = std::isfinite(t) ? std::clamp(t, 0.0f, 1.0f) * 3.0f : 0.0f;
  int i = std::min(int(t), 2);
  float f = t - float(i);
  for (int c = 0; c < 3; ++c) rgb[c] = unitToByte(stops[i][c] * (1 - f) + stops[i + 1][c] * f);
}

// --- Golden comparison -----------------------------------------------------------------------------

namespace {

std::vector<uint8_t> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void writeBytes(const std::string& path, const std::vector<uint8_t>& b) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
}

bool exists(const std::string& p) {
  std::error_code ec;
  return fs::exists(p, ec);
}

GoldenResult fail(std::string message) { return GoldenResult{false, std::move(message)}; }

// Whether two sorted record lists hold the same records up to 'steps' RGBA8 steps per channel in
// their colour fields (every other byte equal). Both are re-sorted by their other fields first and
// their colour second, so that a colour change cannot move a record past others of its kind.
bool recordsEqualUpToColour(const BufferLayout& layout, const std::vector<uint8_t>& a, const std::vector<uint8_t>& b,
                            int steps, double fraction, std::string& why) {
  const size_t stride = layout.stride;
  std::vector<bool> colour(stride, false);
  for (const BufferField& f : layout.fields)
    if (f.type == FieldType::UnormRGBA8)
      for (uint32_t i = 0; i < 4 && f.offset + i < stride; ++i) colour[f.offset + i] = true;
  auto canonical = [&](const std::vector<uint8_t>& bytes) {
    std::vector<std::vector<uint8_t>> recs(bytes.size() / stride);
    for (size_t r = 0; r < recs.size(); ++r) {
      std::vector<uint8_t>& key = recs[r];
      for (size_t i = 0; i < stride; ++i)
        if (!colour[i]) key.push_back(bytes[r * stride + i]);
      for (size_t i = 0; i < stride; ++i)
        if (colour[i]) key.push_back(bytes[r * stride + i]);
    }
    std::sort(recs.begin(), recs.end());
    return recs;
  };
  const auto ra = canonical(a), rb = canonical(b);
  size_t colourBytes = 0;
  for (bool c : colour) colourBytes += c;
  const size_t fixedBytes = stride - colourBytes;
  size_t structural = 0, colours = 0;
  int worst = 0;
  for (size_t r = 0; r < ra.size(); ++r) {
    if (!std::equal(ra[r].begin(), ra[r].begin() + long(fixedBytes), rb[r].begin())) {
      ++structural;
      continue;
    }
    int d = 0;
    for (size_t i = fixedBytes; i < stride; ++i) d = std::max(d, std::abs(int(ra[r][i]) - int(rb[r][i])));
    worst = std::max(worst, d);
    if (d > steps) ++colours;
  }
  if (structural == 0 && double(colours) <= fraction * double(ra.size())) return true;
  why = std::to_string(structural) + " of " + std::to_string(ra.size()) + " records differ outside their colour fields, " +
        std::to_string(colours) + " by more than " + std::to_string(steps) + " colour steps (worst " + std::to_string(worst) +
        ", allowed fraction " + std::to_string(fraction) + ")";
  return false;
}

// Records sorted as byte strings: the canonical form of an append-order-free list.
std::vector<uint8_t> sortedRecords(const CapturedOutput& c) {
  size_t stride = c.desc.layout.stride;
  std::vector<std::vector<uint8_t>> recs(c.recordCount);
  for (uint32_t i = 0; i < c.recordCount; ++i)
    recs[i].assign(c.records.begin() + i * stride, c.records.begin() + (i + 1) * stride);
  std::sort(recs.begin(), recs.end());
  std::vector<uint8_t> out;
  for (auto& r : recs) out.insert(out.end(), r.begin(), r.end());
  return out;
}

}  // namespace

GoldenResult compareRecordsWithGolden(const CapturedOutput& c, const GoldenRequest& q) {
  std::string golden = q.goldenDir + "/" + q.prefix + ".records";
  std::vector<uint8_t> actual = q.tier == CaptureTier::Exact ? sortedRecords(c) : c.records;
  if (q.update) {
    fs::create_directories(q.goldenDir);
    writeBytes(golden, actual);
    return {};
  }
  if (!exists(golden)) return fail("missing golden " + golden + " (run scripts/update-goldens.sh and review)");
  std::vector<uint8_t> expected = readBytes(golden);
  std::string actualPath = q.failureDir + "/" + q.failurePrefix + ".records";
  size_t stride = std::max<size_t>(c.desc.layout.stride, 1);
  if (expected.size() != actual.size()) {
    writeBytes(actualPath, actual);
    return fail(q.failurePrefix + ": " + std::to_string(actual.size() / stride) + " records, golden has " +
                std::to_string(expected.size() / stride) + " (actual written to " + actualPath + ")");
  }
  if (q.tier == CaptureTier::Exact && q.tolerance.recordColourSteps > 0) {
    if (expected == actual) return {};
    std::string why;
    if (recordsEqualUpToColour(c.desc.layout, actual, expected, q.tolerance.recordColourSteps,
                               q.tolerance.recordColourFraction, why)) return {};
    writeBytes(actualPath, actual);
    return fail(q.failurePrefix + ": " + why + " (actual written to " + actualPath + ")");
  }
  if (q.tier == CaptureTier::Exact) {
    if (expected == actual) return {};
    writeBytes(actualPath, actual);
    size_t differing = 0;
    for (size_t i = 0; i < actual.size(); i += stride)
      if (std::memcmp(&actual[i], &expected[i], stride) != 0) ++differing;
    return fail(q.failurePrefix + ": " + std::to_string(differing) + " of " + std::to_string(actual.size() / stride) +
                " sorted records differ (actual written to " + actualPath + ")");
  }
  // Tolerance tier: every 4-byte field read as float.
  size_t n = actual.size() / 4, over = 0;
  double worst = 0;
  for (size_t i = 0; i < n; ++i) {
    float a, e;
    std::memcpy(&a, &actual[i * 4], 4);
    std::memcpy(&e, &expected[i * 4], 4);
    double d = std::abs(double(a) - double(e));
    worst = std::max(worst, d);
    if (d > q.tolerance.maxAbs) ++over;
  }
  if (double(over) <= q.tolerance.maxFraction * double(n)) return {};
  writeBytes(actualPath, actual);
  char buf[512];
  std::snprintf(buf, sizeof buf, "%s: %zu of %zu values differ by more than %g (worst %g; allowed fraction %g; actual written to %s)",
                q.failurePrefix.c_str(), over, n, q.tolerance.maxAbs, worst, q.tolerance.maxFraction, actualPath.c_str());
  return fail(buf);
}

GoldenResult compareLevelsWithGolden(const CapturedOutput& c, const GoldenRequest& q) {
  const double maxAbs = q.tier == CaptureTier::Exact ? 0.0 : q.tolerance.maxAbs;
  const double maxFraction = q.tier == CaptureTier::Exact ? 0.0 : q.tolerance.maxFraction;
  for (size_t l = 0; l < c.levels.size(); ++l) {
    std::string name = q.prefix + (c.levels.size() > 1 ? "@" + std::to_string(l) : "") + ".exr";
    std::string golden = q.goldenDir + "/" + name;
    const LevelData& a = c.levels[l];
    if (q.update) {
      fs::create_directories(q.goldenDir);
      writeLevelExr(a, golden, semanticName(c.desc.semantic));
      continue;
    }
    if (!exists(golden)) return fail("missing golden " + golden + " (run scripts/update-goldens.sh and review)");
    LevelData e = readLevelExr(golden);
    if (a.size != e.size) return fail(name + ": size differs from the golden");
    if (a.channels != e.channels) return fail(name + ": channel count differs from the golden");
    size_t over = 0;
    double worst = 0;
    LevelData diff = a;
    for (size_t i = 0; i < a.values.size(); ++i) {
      double d = std::abs(double(a.values[i]) - double(e.values[i]));
      if (std::isnan(d)) d = INFINITY;
      diff.values[i] = float(d);
      worst = std::max(worst, d);
      if (d > maxAbs) ++over;
    }
    if (double(over) > maxFraction * double(a.values.size())) {
      std::string base = q.failureDir + "/" + q.failurePrefix + (c.levels.size() > 1 ? "@" + std::to_string(l) : "");
      writeLevelExr(a, base + ".actual.exr", semanticName(c.desc.semantic));
      writeLevelExr(diff, base + ".diff.exr", "scalar");
      char buf[1024];
      std::snprintf(buf, sizeof buf,
                    "%s: %zu of %zu values differ by more than %g (worst %g, allowed fraction %g); actual: %s.actual.exr, "
                    "difference: %s.diff.exr, golden: %s",
                    name.c_str(), over, a.values.size(), maxAbs, worst, maxFraction, base.c_str(), base.c_str(), golden.c_str());
      return fail(buf);
    }
  }
  return {};
}

}  // namespace voxlab
