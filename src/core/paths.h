// Where voxlab finds its data folders (shaders/, scenes/, lessons/, tests/).
//
// The root is $VOXLAB_ROOT when set, else the source tree the binary was built from.
#pragma once
#include <string>

namespace voxlab {

std::string projectRoot();
std::string projectPath(const std::string& relative);  // projectRoot() + "/" + relative
std::string readTextFile(const std::string& path);      // throws Error naming the path
bool fileExists(const std::string& path);

}  // namespace voxlab
