#include "capture/image_files.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <memory>

#include <Imath/half.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include "core/error.h"

namespace voxlab {

// stb's PNG deflate level (its default is 8): lossless either way; 2 writes a run's PNGs several
// times faster. Set once before main, since files are written from several threads.
static const bool kPngLevelSet = (stbi_write_png_compression_level = 2, true);

std::string ImageFileData::attribute(const std::string& name, const std::string& fallback) const {
  for (const auto& a : attributes)
    if (a.name == name) return a.value;
  return fallback;
}

// Library messages can span lines; voxlab's errors are one line.
static std::string oneLine(std::string s) {
  for (auto& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

static std::vector<std::string> channelNames(int channels) {
  switch (channels) {
    case 1: return {"Y"};
    case 2: return {"R", "G"};
    case 3: return {"R", "G", "B"};
    case 4: return {"R", "G", "B", "A"};
  }
  throw Error("EXR images need 1 to 4 channels, not " + std::to_string(channels));
}

static bool hasExtension(const std::string& path, const char* ext) {
  std::string lower = path;
  std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
  size_t n = std::strlen(ext);
  return lower.size() >= n && lower.compare(lower.size() - n, n, ext) == 0;
}

void writeExrFile(const std::string& path, const ImageFileData& img, bool half) {
  try {
    Imf::Header header(img.width, img.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    header.zipCompressionLevel() = 1;  // lossless either way; level 1 writes a run's files in half the time
    auto names = channelNames(img.channels);
    Imf::PixelType type = half ? Imf::HALF : Imf::FLOAT;
    for (const auto& n : names) header.channels().insert(n, Imf::Channel(type));
    for (const auto& a : img.attributes) {
      if (a.isInt)
        header.insert(a.name, Imf::IntAttribute(std::stoi(a.value)));
      else
        header.insert(a.name, Imf::StringAttribute(a.value));
    }
    // OpenEXR converts pixel types only when reading: a HALF channel needs a HALF slice.
    Imf::FrameBuffer fb;
    std::vector<::half> halves;  // (the parameter 'half' hides the type's name here)
    if (half) {
      halves.reserve(img.pixels.size());
      for (float v : img.pixels) halves.push_back(::half(v));
      size_t xStride = sizeof(::half) * img.channels, yStride = xStride * img.width;
      for (int c = 0; c < img.channels; ++c)
        fb.insert(names[c], Imf::Slice(Imf::HALF, (char*)(halves.data() + c), xStride, yStride));
    } else {
      size_t xStride = sizeof(float) * img.channels, yStride = xStride * img.width;
      for (int c = 0; c < img.channels; ++c)
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, (char*)(img.pixels.data() + c), xStride, yStride));
    }
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(img.height);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error("cannot write '" + path + "': " + oneLine(e.what()));
  }
}

void writePngFile(const std::string& path, int width, int height, int channels, const uint8_t* data) {
  if (!stbi_write_png(path.c_str(), width, height, channels, data, width * channels))
    throw Error("cannot write '" + path + "' (folder missing or not writable?)");
}

static ImageFileData readExr(const std::string& path) {
  ImageFileData img;
  try {
    Imf::InputFile file(path.c_str());
    const Imf::Header& h = file.header();
    Imath::Box2i dw = h.dataWindow();
    img.width = dw.max.x - dw.min.x + 1;
    img.height = dw.max.y - dw.min.y + 1;
    std::vector<std::string> present;
    for (auto it = h.channels().begin(); it != h.channels().end(); ++it) present.push_back(it.name());
    std::vector<std::string> order;
    for (const char* n : {"R", "G", "B", "A", "Y"})
      if (std::find(present.begin(), present.end(), n) != present.end()) order.push_back(n);
    for (const auto& n : present)
      if (std::find(order.begin(), order.end(), n) == order.end()) order.push_back(n);
    img.channels = int(order.size());
    img.pixels.assign(size_t(img.width) * img.height * img.channels, 0.0f);
    Imf::FrameBuffer fb;
    size_t xStride = sizeof(float) * img.channels, yStride = xStride * img.width;
    char* base = (char*)img.pixels.data() - (size_t(dw.min.x) * xStride + size_t(dw.min.y) * yStride);
    for (int c = 0; c < img.channels; ++c)
      fb.insert(order[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xStride, yStride));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    for (auto it = h.begin(); it != h.end(); ++it) {
      if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
        img.attributes.push_back({it.name(), s->value(), false});
      else if (const auto* i = dynamic_cast<const Imf::IntAttribute*>(&it.attribute()))
        img.attributes.push_back({it.name(), std::to_string(i->value()), true});
    }
  } catch (const std::exception& e) {
    throw Error("cannot read image '" + path + "': " + oneLine(e.what()));
  }
  return img;
}

ImageFileData readImageFile(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw Error("cannot read image '" + path + "': no such file");
  if (hasExtension(path, ".exr")) return readExr(path);
  int w = 0, h = 0, n = 0;
  std::unique_ptr<unsigned char, void (*)(void*)> data(stbi_load(path.c_str(), &w, &h, &n, 0), stbi_image_free);
  if (!data) {
    const char* why = stbi_failure_reason();
    throw Error("cannot read image '" + path + "': " + (why ? why : "unknown format") +
                " (readable: .exr, .png, .jpg, .tga, .bmp, .hdr)");
  }
  ImageFileData img;
  img.width = w;
  img.height = h;
  img.channels = n;
  img.eightBit = true;
  img.pixels.resize(size_t(w) * h * n);
  for (size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = float(data.get()[i]) / 255.0f;
  return img;
}

}  // namespace voxlab
