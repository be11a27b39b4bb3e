// OutputDesc: what a stage writes that can be looked at. The kind says how it is read back and
// saved; the semantic says how it is shown (the visualiser and the display mapping).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace voxlab {

enum class OutputKind {
  Image2D,   // a 2D texture (one or more levels)
  Volume3D,  // a 3D texture (one or more mip/clip levels)
  Buffer,    // an array of records in a buffer, described by a BufferLayout
};

enum class Semantic {
  Color,        // linear RGB in [0,1], shown sRGB-encoded
  RadianceHDR,  // linear RGB, unbounded, shown tonemapped (exposure 1, Reinhard) and sRGB-encoded
  Normal,       // unit vectors, shown as n * 0.5 + 0.5
  Depth,        // scalar distance or depth, shown normalised min..max in false colour
  Scalar,       // any scalar, shown normalised min..max in false colour
  Occupancy,    // non-zero means occupied; shown white on black
  Opacity,      // alpha channel of a radiance volume, shown grey
  Fraction,     // a scalar in [0,1] (visibility, occlusion), shown grey
  Points,       // a buffer of records with a position field, shown as a point view
  ConeSamples,  // a buffer of cone-trace samples for one probed pixel
};

const char* kindName(OutputKind kind);
const char* semanticName(Semantic semantic);

// One field of a buffer record.
enum class FieldType { U32, I32, F32, Vec2, Vec3, Vec4, UnormRGBA8, SnormRGBA8, Packed10_10_10 };
enum class FieldRole { Other, Position, Color, Normal };

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
  CaptureTier tier = CaptureTier::Tolerance;
  // "" none; else the reference path tracer mode this output approximates ("full", "direct",
  // "indirect", "indirect-1", ... see reference/path_tracer.h). `voxlab run` compares an Image2D
  // output in linear radiance with tests/golden/reference/<scene>/<mode>.exr when one exists for
  // the same scene, camera and size (app/reference_error.h).
  std::string referenceMode;
  // "" always real; else "param=value": under any other value of that parameter the stage writes
  // only a placeholder here (one empty texel), e.g. the anisotropic volumes under isotropic mips.
  // The snapshot suite then checks it is empty instead of comparing it with a golden.
  std::string placeholderUnless;

  const std::string& resourceName() const { return resource.empty() ? name : resource; }
};

// "technique/stage/output@level" (level optional, -1 = all levels).
struct OutputAddress {
  std::string technique, stage, output;
  int level = -1;
  static OutputAddress parse(const std::string& text);  // throws Error naming the expected form
  std::string str() const;
};

}  // namespace voxlab
