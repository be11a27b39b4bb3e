// Reading and writing float RGB images (EXR; PNG and other 8-bit formats) with
// voxlab's metadata attributes ("voxlab:spp", "voxlab:mode", ...).
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "capture/image_files.h"
#include "reference/image.h"

namespace voxlab::reference {

// One metadata attribute. Written as an int attribute when isInt, else as a string.
struct ImageAttribute {
  std::string name;
  std::string value;
  bool isInt = false;
};
using ImageAttributes = std::vector<ImageAttribute>;

// Writes img.rgb as 3-channel float (half-free, full 32-bit) EXR, or as 8-bit sRGB-encoded data
// when the extension is .png/.jpg (values clamped to [0,1] and encoded with the sRGB curve).
// Throws voxlab::Error naming the path when the file cannot be written. halfFloat: EXR pixels as
// 16-bit half floats (relative rounding error <= 2^-11, range up to 65504) instead of 32-bit float.
// compression: the EXR's (ZIP, or RLE for pixels that deflate barely shrinks).
void writeImage(const std::string& path, const Image& img, const ImageAttributes& attributes = {},
                bool halfFloat = false, ExrCompression compression = ExrCompression::Zip);
// Writes an EXR; the same as writeImage but insists on a .exr extension.
void writeExr(const std::string& path, const Image& img, const ImageAttributes& attributes = {},
              bool halfFloat = false);

// Reads the first three channels of the first subimage as float (a one-channel file is copied to
// all three). 8-bit files are returned as stored (0..1, not linearised). Attributes that start
// with "voxlab:" are returned in *attributes when given. Throws voxlab::Error naming the path.
Image readImage(const std::string& path, ImageAttributes* attributes = nullptr);
inline Image readExr(const std::string& path, ImageAttributes* attributes = nullptr) {
  return readImage(path, attributes);
}

// "out.exr" -> "out.stderr.exr": where the reference tracer writes its standard-error image.
std::string stdErrPathFor(const std::string& path);

}  // namespace voxlab::reference
