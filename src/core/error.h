// voxlab::Error: the one exception type user-facing code throws.
//
// Its message is a single line that names what is wrong and, where there is a set of valid
// values, what would be valid. Commands print it as "voxlab: <message>" and exit non-zero.
#pragma once
#include <stdexcept>
#include <string>
#include <vector>

namespace voxlab {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// "a, b, c": for messages that list the valid names.
std::string joinNames(const std::vector<std::string>& names, const char* separator = ", ");

}  // namespace voxlab
