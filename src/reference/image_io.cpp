#include "reference/image_io.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>

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
                bool halfFloat) {
  if (img.width <= 0 || img.height <= 0 || img.rgb.size() != img.pixelCount() * 3)
    throw Error("cannot write '" + path + "': image has no pixels or a wrong pixel count");
  std::string ext = lowerExtension(path);
  bool floatFile = ext == ".exr" || ext == ".hdr" || ext == ".tif" || ext == ".tiff";
  std::error_code ec;
  auto parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);  // open() reports failures
  auto out = OIIO::ImageOutput::create(path);
  if (!out)
    throw Error("cannot write '" + path + "': no image writer for extension '" + ext +
                "' (use .exr or .png)");
  OIIO::TypeDesc fileType = !floatFile                    ? OIIO::TypeDesc::UINT8
                            : halfFloat && ext == ".exr" ? OIIO::TypeDesc::HALF
                                                         : OIIO::TypeDesc::FLOAT;
  OIIO::ImageSpec spec(img.width, img.height, 3, fileType);
  spec.channelnames = {"R", "G", "B"};
  for (const auto& a : attributes) {
    if (a.isInt)
      spec.attribute(a.name, std::stoi(a.value));
    else
      spec.attribute(a.name, a.value);
  }
  if (ext == ".exr") spec.attribute("compression", "zip");
  if (!floatFile) spec.attribute("oiio:ColorSpace", "sRGB");
  if (!out->open(path, spec))
    throw Error("cannot write '" + path + "': " + out->geterror());
  bool ok;
  if (floatFile) {
    ok = out->write_image(OIIO::TypeDesc::FLOAT, img.rgb.data());
  } else {
    std::vector<uint8_t> bytes(img.rgb.size());
    for (size_t i = 0; i < bytes.size(); ++i)
      bytes[i] = static_cast<uint8_t>(std::lround(srgbEncode(img.rgb[i]) * 255.0f));
    ok = out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
  }
  if (!ok) throw Error("cannot write '" + path + "': " + out->geterror());
  if (!out->close()) throw Error("cannot write '" + path + "': " + out->geterror());
}

void writeExr(const std::string& path, const Image& img, const ImageAttributes& attributes,
              bool halfFloat) {
  if (lowerExtension(path) != ".exr")
    throw Error("'" + path + "' does not end in .exr; the reference image is written as EXR");
  writeImage(path, img, attributes, halfFloat);
}

Image readImage(const std::string& path, ImageAttributes* attributes) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    std::string why = OIIO::geterror();
    if (why.empty()) why = "not a readable image";
    auto nl = why.find('\n');
    if (nl != std::string::npos) why = why.substr(0, nl);
    throw Error("cannot read image '" + path + "': " + why);
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    throw Error("cannot read image '" + path + "': it has no pixels");
  Image img(spec.width, spec.height);
  int nc = spec.nchannels;
  std::vector<float> all(size_t(spec.width) * spec.height * nc);
  if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, all.data()))
    throw Error("cannot read image '" + path + "': " + in->geterror());
  for (size_t i = 0; i < img.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) img.rgb[i * 3 + c] = all[i * nc + std::min(c, nc - 1)];
  if (attributes) {
    attributes->clear();
    for (const auto& p : spec.extra_attribs) {
      std::string name = p.name().string();
      if (name.rfind("voxlab:", 0) != 0) continue;
      bool isInt = p.type() == OIIO::TypeDesc::INT;
      attributes->push_back({name, p.get_string(), isInt});
    }
  }
  in->close();
  return img;
}

}  // namespace voxlab::reference
