// Parameters: the knobs a stage declares. Everything else (the viewer's widgets, `--set` on the
// command line, lesson steps, bench sweeps) is generated from these declarations.
#pragma once
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace voxlab {

enum class ParamType { Int, Float, Bool, Choice };

struct ParamDesc {
  std::string name;  // dotted, e.g. "voxel.resolution"; shared by every stage that declares it
  ParamType type = ParamType::Float;
  double defaultValue = 0.0;
  double minValue = 0.0;  // inclusive (Int/Float)
  double maxValue = 1.0;  // inclusive (Int/Float)
  std::vector<std::string> choices;  // Choice: the value is the index into this list
  std::string unit;                  // "voxels", "degrees", "px", ...
  std::string help;                  // one line
  bool powerOfTwo = false;           // Int: must also be a power of two
  // Float: the value may also be "scene" (stored as NaN, the default): the stage takes the value
  // from the loaded scene (e.g. the light's direction). Static declarations cannot know a scene.
  bool sceneDefault = false;
  // The value is part of the scene's physics (its light, the sky), not of the technique: the
  // checked-in reference images are of the default, so a run with any other value is not
  // compared with them (`voxlab run` says so in its manifest).
  bool changesGroundTruth = false;

  static ParamDesc integer(std::string name, int def, int lo, int hi, std::string help, std::string unit = "");
  static ParamDesc real(std::string name, double def, double lo, double hi, std::string help, std::string unit = "");
  static ParamDesc boolean(std::string name, bool def, std::string help);
  static ParamDesc choice(std::string name, std::vector<std::string> choices, int def, std::string help);
  // A Float whose default is "scene" (see sceneDefault); any value in lo..hi overrides it.
  static ParamDesc fromScene(std::string name, double lo, double hi, std::string help, std::string unit = "");
  static bool isSceneValue(double v);  // the "scene" value (NaN)
  static bool sameValue(double a, double b) { return a == b || (isSceneValue(a) && isSceneValue(b)); }
  ParamDesc& pow2() { powerOfTwo = true; return *this; }
  ParamDesc& groundTruth() { changesGroundTruth = true; return *this; }

  const char* typeName() const;
  std::string format(double value) const;         // "128", "0.5", "true", "fragment-parallel"
  std::string rangeText() const;                  // "16..512 (power of two)", "one of a, b"
  double parse(const std::string& text) const;    // throws Error naming the param and valid range
  void validate(double value) const;              // throws Error naming the param and valid range
};

// The current value of every parameter a technique declares.
class ParamSet {
 public:
  void declare(const ParamDesc& desc);  // keeps the first declaration; throws on a conflicting one
  bool has(const std::string& name) const { return descs_.count(name) != 0; }
  const ParamDesc& desc(const std::string& name) const;  // throws Error listing valid names
  const std::map<std::string, ParamDesc>& descs() const { return descs_; }

  double value(const std::string& name) const;
  int getInt(const std::string& name) const { return int(value(name)); }
  float getFloat(const std::string& name) const { return float(value(name)); }
  bool getBool(const std::string& name) const { return value(name) != 0.0; }
  const std::string& getChoice(const std::string& name) const;

  void set(const std::string& name, double value);             // validates
  // Parses + validates. 'name' may also be a vector parameter (below): "1.5,0,-2" sets its three
  // components, all or none.
  void setText(const std::string& name, const std::string& text);
  void setAssignment(const std::string& nameEqualsValue);      // "voxel.resolution=64"
  // A vector parameter is a name that is not declared itself but whose components NAME.x, NAME.y
  // and NAME.z are (clipmap.path-step, light.0): --set, lessons, scripts and bench sweeps may set
  // it as "X,Y,Z". Returns the component names, or nothing when 'name' is not one.
  std::vector<std::string> vectorComponents(const std::string& name) const;
  // What setText(name, text) would set: one (name, value), or the three components of a vector
  // parameter. Throws Error (one line naming the parameter and the valid form) on bad text.
  std::vector<std::pair<std::string, double>> parseText(const std::string& name, const std::string& text) const;
  void resetToDefaults();
  std::map<std::string, std::string> formatted() const;       // name -> formatted value

 private:
  std::map<std::string, ParamDesc> descs_;
  std::map<std::string, double> values_;
};

}  // namespace voxlab
