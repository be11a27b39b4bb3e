// Command-line arguments for voxlab's sub-commands.
//
// Each command declares its options (name, whether it takes a value, whether it may repeat) and
// gets them back parsed; anything else is an Error naming the unknown option and the valid ones.
#pragma once
#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace voxlab {

struct OptionSpec {
  std::string name;         // "--scene"
  bool takesValue = true;   // false for flags such as "--json"
  bool repeatable = false;  // "--set" may be given several times
  std::string help;         // one line, shown by "voxlab help COMMAND"
};

class Args {
 public:
  // Parses args against specs; positional arguments are allowed up to maxPositional.
  Args(const std::string& command, const std::vector<std::string>& args,
       const std::vector<OptionSpec>& specs, size_t maxPositional = 0);

  bool has(const std::string& name) const;
  std::string get(const std::string& name, const std::string& fallback = "") const;
  std::optional<std::string> find(const std::string& name) const;
  std::vector<std::string> all(const std::string& name) const;  // every value of a repeatable
  const std::vector<std::string>& positional() const { return positional_; }
  std::string require(const std::string& name) const;  // throws Error "COMMAND needs NAME"

  // Parses "WxH" (e.g. 512x512), both in [1, 8192]; throws Error naming the expected form.
  static void parseSize(const std::string& text, int& width, int& height);
  // Parses an integer in [lo, hi] for option 'name'; throws Error naming the range.
  static int parseInt(const std::string& name, const std::string& text, int lo, int hi);
  // Parses "X,Y,Z" (three finite numbers) for option 'name'; throws Error naming the form.
  static std::array<float, 3> parseVec3(const std::string& name, const std::string& text);

 private:
  std::string command_;
  std::map<std::string, std::vector<std::string>> values_;
  std::vector<std::string> positional_;
};

}  // namespace voxlab
