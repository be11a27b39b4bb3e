// OutputDesc: what a stage writes that can be looked at. The kind says how it is read back and
// saved; the semantic says how it is shown (the visualiser and the display mapping).
#pragma once
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace voxlab {

enum class OutputKind {
  Image2D,   // a 2D texture (one or more levels)
  Volume3D,  // a 3D texture (one or more mip/clip levels)
  Buffer,    // an array of records in a buffer, described by a BufferLayout
};

// The semantic names what the values mean; it picks the visualiser (src/inspect/visualisers) and
// the display mapping. It is an open set: a name, compared by its text, so a new kind of data (or a
// test) adds one with `inline constexpr Semantic kMine{"mine"};` and no change here. The shared
// ones:
class Semantic {
 public:
  constexpr explicit Semantic(const char* name) : name_(name) {}
  constexpr const char* name() const { return name_; }
  bool operator==(const Semantic& o) const { return std::strcmp(name_, o.name_) == 0; }
  bool operator!=(const Semantic& o) const { return !(*this == o); }
  bool operator<(const Semantic& o) const { return std::strcmp(name_, o.name_) < 0; }

  static const Semantic Color;        // linear RGB in [0,1], shown sRGB-encoded
  static const Semantic RadianceHDR;  // linear RGB, unbounded, shown tonemapped (Reinhard) and sRGB-encoded
  static const Semantic Normal;       // unit vectors, shown as n * 0.5 + 0.5
  static const Semantic Depth;        // scalar distance or depth, shown normalised min..max in false colour
  static const Semantic Scalar;       // any scalar, shown normalised min..max in false colour
  static const Semantic Occupancy;    // non-zero means occupied; shown white on black
  static const Semantic Opacity;      // alpha channel of a radiance volume, shown grey
  static const Semantic Fraction;     // a scalar in [0,1] (visibility, occlusion), shown grey
  static const Semantic Points;       // a buffer of records with a position field, shown as a point view
  static const Semantic ConeSamples;  // a buffer of cone-trace samples for one probed pixel
  // One record explaining one probed pixel step by step: fields named "section: label [unit]", in
  // the order the value is built; the Addend fields sum to the Sum field, and the Displayed field is
  // the value the final image holds at the pixel (FieldRole).
  static const Semantic ProbeChain;

 private:
  const char* name_;  // a string literal (or other text that outlives every OutputDesc)
};
inline constexpr Semantic Semantic::Color{"color"};
inline constexpr Semantic Semantic::RadianceHDR{"radiance-hdr"};
inline constexpr Semantic Semantic::Normal{"normal"};
inline constexpr Semantic Semantic::Depth{"depth"};
inline constexpr Semantic Semantic::Scalar{"scalar"};
inline constexpr Semantic Semantic::Occupancy{"occupancy"};
inline constexpr Semantic Semantic::Opacity{"opacity"};
inline constexpr Semantic Semantic::Fraction{"fraction"};
inline constexpr Semantic Semantic::Points{"points"};
inline constexpr Semantic Semantic::ConeSamples{"cone-samples"};
inline constexpr Semantic Semantic::ProbeChain{"probe-chain"};

const char* kindName(OutputKind kind);
const char* semanticName(Semantic semantic);

// One field of a buffer record.
enum class FieldType { U32, I32, F32, Vec2, Vec3, Vec4, UnormRGBA8, SnormRGBA8, Packed10_10_10 };
// Addend, Sum, Displayed: a probe chain's parts, their total, and the value shown at the pixel.
enum class FieldRole { Other, Position, Color, Normal, Addend, Sum, Displayed };

struct BufferField {
  std::string name;
  FieldType type = FieldType::U32;
  uint32_t offset = 0;  // bytes from the record start
  FieldRole role = FieldRole::Other;
};

struct BufferLayout {
  uint32_t stride = 0;               // bytes per record
  std::vector<BufferField> fields;
  std::string countResource;         // a buffer whose first uint32 is the record count ("" = capacity)
  uint32_t countOffset = 0;          // byte offset of that uint32
  float positionScale = 1.0f;        // Position field units -> display units (voxels)
};

// How the snapshot suite compares an output with its golden (the numbers live in
// tests/golden/tolerances.json; this is only the tier).
enum class CaptureTier {
  Default,    // the visualiser's tier for the output's kind and semantic (capture/output_handler.h)
  Exact,      // integer/structural: sets and counts compared exactly (canonicalised)
  Tolerance,  // float images/volumes: max abs difference + fraction of texels allowed above it
  None,       // not compared (e.g. nondeterministic debug views)
};

struct OutputDesc {
  std::string name;      // unique within the stage; address "technique/stage/name@level"
  OutputKind kind = OutputKind::Image2D;
  Semantic semantic = Semantic::Color;
  std::string resource;  // blackboard resource it shows ("" = same as name)
  std::string help;      // one line for the inspector and `voxlab list`
  BufferLayout layout;   // Buffer kind only
  CaptureTier tier = CaptureTier::Default;
  // A probe record: what a stage recorded for the element its probe parameters point at (cone
  // samples of a pixel, the path of an octree descent, ...). The viewer's Probe tab shows every
  // probe record of the stages that declare a probe, through the record's visualiser.
  bool probeRecord = false;
  // "" none; else the reference path tracer mode this output approximates ("full", "direct",
  // "indirect", "indirect-1", ... see reference/path_tracer.h). `voxlab run` compares an Image2D
  // output in linear radiance with tests/golden/reference/<scene>/<mode>.exr when one exists for
  // the same scene, camera and size (app/reference_error.h).
  std::string referenceMode;
  // "" always real; else "param=value" or "param>=number": when the parameter's value is not that
  // (not at least that) the stage writes only a placeholder here (one empty texel), e.g. the
  // anisotropic volumes under isotropic mips, a bounce's grid when fewer bounces are gathered.
  // The snapshot suite then checks it is empty instead of comparing it with a golden
  // (isPlaceholderUnder).
  std::string placeholderUnless;
  // Computed on demand: the stage computes (and allocates) it only when the run needs it
  // (StageContext::wants), e.g. a soft-shadow cone the composite does not read, a dense view of
  // octree data kept for the viewer. Outputs without it are computed whenever their stage runs.
  bool onDemand = false;
  // Written alongside what the final image needs, by the same pass, at no cost worth skipping: a
  // raster pass's depth attachment, the composite's direct and combined terms, a probe record of
  // one pixel. A --final-only run keeps these (the on-demand test lists them); anything else the
  // final image does not read is not computed by such a run.
  bool alongside = false;

  const std::string& resourceName() const { return resource.empty() ? name : resource; }
};

class ParamSet;
// Whether 'desc' is only a placeholder under 'params' (OutputDesc::placeholderUnless); throws Error
// on a condition that names no parameter of 'params' or is neither form.
bool isPlaceholderUnder(const OutputDesc& desc, const ParamSet& params);
// Whether "param=value", "param>=number" or "param>number" holds under 'params' ("" holds); throws
// Error naming 'what' (the output or read it conditions) on a condition of none of these forms.
bool conditionHolds(const std::string& condition, const ParamSet& params, const std::string& what);

// "technique/stage/output@level" (level optional, -1 = all levels).
struct OutputAddress {
  std::string technique, stage, output;
  int level = -1;
  static OutputAddress parse(const std::string& text);  // throws Error naming the expected form
  std::string str() const;
};

}  // namespace voxlab
