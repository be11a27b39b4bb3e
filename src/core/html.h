// Text for HTML and SVG pages (handouts, the gallery, sweeps, figures).
#pragma once
#include <string>

namespace voxlab {

// 'text' with &, <, > and " replaced by their entities: safe inside an element or a quoted attribute.
std::string htmlEscape(const std::string& text);

}  // namespace voxlab
