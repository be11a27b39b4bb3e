#include "reference/image_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>

#include "capture/image_files.h"
#include "core/error.h"

namespace voxlab::reference {

namespace {

std::string lowerExtension(const std::string& path) {
  auto slash = path.find_last_of('/');
  auto dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot);
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

float srgbEncode(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

}  // namespace

std::string stdErrPathFor(const std::string& path) {
  std::string ext = lowerExtension(path);
  std::string stem = ext.empty() ? path : path.substr(0, path.size() - ext.size());
  return stem + ".stderr" + (ext.empty() ? std::string(".exr") : path.substr(path.size() - ext.size()));
}

void writeImage(const std::string& path, const Image& img, const ImageAttributes& attributes,
                bool halfFloat, ExrCompression compression) {
  if (img.width <= 0 || img.height <= 0 || img.rgb.size() != img.pixelCount() * 3)
    throw Error("cannot write '" + path + "': image has no pixels or a wrong pixel count");
  std::string ext = lowerExtension(path);
  std::error_code ec;
  auto parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);  // the writer reports failures
  if (ext == ".exr") {
    ImageFileData file;
    file.width = img.width;
    file.height = img.height;
    file.channels = 3;
    file.pixels = img.rgb;
    for (const auto& a : attributes) file.attributes.push_back({a.name, a.value, a.isInt});
    writeExrFile(path, file, halfFloat, compression);
    return;
  }
  if (ext != ".png")
    throw Error("cannot write '" + path + "': no image writer for extension '" + ext + "' (use .exr or .png)");
  std::vector<uint8_t> bytes(img.rgb.size());
  for (size_t i = 0; i < bytes.size(); ++i)
    bytes[i] = static_cast<uint8_t>(std::lround(srgbEncode(img.rgb[i]) * 255.0f));
  writePngFile(path, img.width, img.height, 3, bytes.data());
}

void writeExr(const std::string& path, const Image& img, const ImageAttributes& attributes,
              bool halfFloat) {
  if (lowerExtension(path) != ".exr")
    throw Error("'" + path + "' does not end in .exr; the reference image is written as EXR");
  writeImage(path, img, attributes, halfFloat);
}

Image readImage(const std::string& path, ImageAttributes* attributes) {
  ImageFileData file = readImageFile(path);
  if (file.width <= 0 || file.height <= 0 || file.channels <= 0)
    throw Error("cannot read image '" + path + "': it has no pixels");
  Image img(file.width, file.height);
  int nc = file.channels;
  for (size_t i = 0; i < img.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) img.rgb[i * 3 + c] = file.pixels[i * nc + std::min(c, nc - 1)];
  if (attributes) {
    attributes->clear();
    for (const auto& a : file.attributes)
      if (a.name.rfind("voxlab:", 0) == 0) attributes->push_back({a.name, a.value, a.isInt});
  }
  return img;
}

}  // namespace voxlab::reference
