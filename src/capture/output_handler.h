// Output handlers: the headless half of a visualiser. `voxlab run`'s writers, the manifest's
// statistics, the snapshot suite's golden comparison and the display mapping of PNGs look up the
// handler of an output by (kind, semantic), falling back to the handler of its kind; none of them
// names a semantic. Handlers are registered by the visualisers in src/inspect/visualisers (one file
// each, VOXLAB_REGISTER_VISUALISER), which add the viewer's views on top; see
// docs/architecture.md, "Adding a visualiser".
//
// Texel mappings (how one texel of a semantic looks: sRGB colour, tonemapped radiance, normals,
// grey fractions, false colour) are a second, smaller registry keyed by semantic alone, because
// images and volumes of one semantic look the same (src/capture/texel_mappings.cpp).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "capture/capture.h"
#include "graph/output.h"

namespace voxlab {

// --- Texel mappings --------------------------------------------------------------------------------

struct TexelMapping {
  // Maps one texel (v[0..channels-1]) to 8-bit RGB. exposure multiplies the values first; lo/hi are
  // the level's range of channel 0 when 'normalise' is set.
  void (*map)(const float* v, int channels, float exposure, float lo, float hi, uint8_t* rgb) = nullptr;
  bool normalise = false;       // needs lo/hi: shown min..max of the whole level
  bool alphaIsOpacity = false;  // a 4-channel volume texel is non-empty (and as opaque) as its alpha
  bool exact = false;           // integer/structural values: the snapshot suite compares them exactly
};
// The mapping of a semantic; the normalised false-colour ramp for semantics without one.
const TexelMapping& texelMapping(Semantic semantic);
void registerTexelMapping(Semantic semantic, const TexelMapping& mapping);

// A normalised value in [0,1] through the viewer's dark-blue -> teal -> green -> yellow ramp.
void falseColourRamp(float t, uint8_t* rgb);
uint8_t unitToByte(float v);
float srgbEncode(float linear);

// --- Golden comparison ----------------------------------------------------------------------------

struct GoldenTolerance {
  double maxAbs = 0.0;       // per value
  double maxFraction = 0.0;  // of values allowed above maxAbs
  // Exact-tier record lists: the RGBA8 colour fields (FieldType::UnormRGBA8) may differ by up to
  // this many steps per channel while every other field, and the record count, stay exact; 0
  // compares whole records exactly. For colours sampled from textures, which llvmpipe filters with
  // the CPU's approximate reciprocal instructions (they differ between processor makers).
  int recordColourSteps = 0;
  double recordColourFraction = 0.0;  // of records allowed beyond recordColourSteps (a record whose
                                      // colour moved past a neighbour's pairs with that neighbour)
};

// What the snapshot suite asks a handler to do with one output.
struct GoldenRequest {
  std::string goldenDir;   // tests/golden/<technique>/<scene>
  std::string prefix;      // "<stage>.<output>"
  std::string failureDir;  // where actual and difference files go on a failure
  std::string failurePrefix;  // "<technique>.<stage>.<output>"
  CaptureTier tier = CaptureTier::Tolerance;  // resolved (never Default)
  GoldenTolerance tolerance;  // ignored for the exact tier
  bool update = false;     // write the goldens instead of comparing
};
struct GoldenResult {
  bool ok = true;
  std::string message;  // on failure: what differs, and the files written
};

// --- Handlers --------------------------------------------------------------------------------------

class OutputHandler {
 public:
  virtual ~OutputHandler() = default;
  virtual const char* name() const = 0;  // "image", "volume", "cone-samples", ...
  // The tier the snapshot suite uses when the output does not declare one.
  virtual CaptureTier defaultTier(const OutputDesc& desc) const = 0;
  // Statistics for the manifest, the viewer's statistics table and the snapshot suite.
  virtual nlohmann::json statistics(const CapturedOutput& out) const = 0;
  // Writes the output's files into 'dir' as "<prefix>[@L].<ext>" and returns the manifest entry
  // (kind, semantic, format, statistics, files).
  virtual nlohmann::json writeFiles(const CapturedOutput& out, const std::string& dir, const std::string& prefix) const = 0;
  // Compares the output with its golden files (or writes them).
  virtual GoldenResult compareGolden(const CapturedOutput& out, const GoldenRequest& request) const = 0;
};

// The handler registered for (kind, semantic), else the one for (kind, any semantic). Throws Error
// when neither exists (a kind with no visualiser).
const OutputHandler& outputHandler(OutputKind kind, Semantic semantic);
inline const OutputHandler& outputHandler(const OutputDesc& d) { return outputHandler(d.kind, d.semantic); }
// semantic == nullptr: the fallback for the kind.
void registerOutputHandler(OutputKind kind, const char* semantic, const OutputHandler* handler);
// The tier an output is compared with: its declared one, else its handler's default.
CaptureTier captureTier(const OutputDesc& desc);

// --- Building blocks the handlers share (by kind; capture.cpp) ----------------------------------------

nlohmann::json levelStatistics(const CapturedOutput& out);   // images and volumes
nlohmann::json recordStatistics(const CapturedOutput& out);  // buffers
// PNG (display mapping) + EXR (values) per level.
void writeLevelFiles(const CapturedOutput& out, const std::string& dir, const std::string& prefix, nlohmann::json& files);
// JSON summary (first records decoded) + raw .bin.
void writeRecordFiles(const CapturedOutput& out, const std::string& dir, const std::string& prefix,
                      const nlohmann::json& statistics, nlohmann::json& files);
nlohmann::json manifestEntry(const CapturedOutput& out, const nlohmann::json& statistics);
GoldenResult compareLevelsWithGolden(const CapturedOutput& out, const GoldenRequest& request);
GoldenResult compareRecordsWithGolden(const CapturedOutput& out, const GoldenRequest& request);

}  // namespace voxlab
