#include "capture/image_files.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>

#include <Imath/half.h>
#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
#include <immintrin.h>
#endif
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <stb_image.h>
#include <zlib.h>

#include <fstream>

#include "core/error.h"

namespace voxlab {

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

void writeExrFile(const std::string& path, int width, int height, int channels,
                  const std::vector<ImageFileAttribute>& attributes, ExrPixels type, const void* pixels,
                  ExrCompression compression) {
  try {
    Imf::Header header(width, height);
    header.compression() = compression == ExrCompression::Rle ? Imf::RLE_COMPRESSION : Imf::ZIP_COMPRESSION;
    header.zipCompressionLevel() = 1;  // lossless either way; level 1 writes a run's files in half the time
    auto names = channelNames(channels);
    const bool half = type == ExrPixels::Half;
    const Imf::PixelType pixelType = half ? Imf::HALF : Imf::FLOAT;
    for (const auto& n : names) header.channels().insert(n, Imf::Channel(pixelType));
    for (const auto& a : attributes) {
      if (a.isInt)
        header.insert(a.name, Imf::IntAttribute(std::stoi(a.value)));
      else
        header.insert(a.name, Imf::StringAttribute(a.value));
    }
    Imf::FrameBuffer fb;
    const size_t valueBytes = half ? sizeof(::half) : sizeof(float);
    const size_t xStride = valueBytes * channels, yStride = xStride * width;
    for (int c = 0; c < channels; ++c)
      fb.insert(names[c], Imf::Slice(pixelType, (char*)pixels + c * valueBytes, xStride, yStride));
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(height);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error("cannot write '" + path + "': " + oneLine(e.what()));
  }
}

void writeExrFile(const std::string& path, const ImageFileData& img, bool half, ExrCompression compression) {
  if (!half) {
    writeExrFile(path, img.width, img.height, img.channels, img.attributes, ExrPixels::Float, img.pixels.data(),
                 compression);
    return;
  }
  // OpenEXR converts pixel types only when reading: a HALF channel needs half values.
  std::vector<uint16_t> halves(img.pixels.size());
  toHalfBits(img.pixels.data(), halves.data(), halves.size());
  writeExrFile(path, img.width, img.height, img.channels, img.attributes, ExrPixels::Half, halves.data(),
               compression);
}

#if defined(__x86_64__) || defined(__i386__)
// Eight values per instruction where the CPU has F16C (x86 since 2012): a 128^3 RGBA level is
// 8.4 M values, 24 ms through Imath's scalar conversion. Both round to nearest, ties to even.
__attribute__((target("avx,f16c"))) static void toHalfBitsF16c(const float* in, uint16_t* out, size_t count) {
  size_t i = 0;
  for (; i + 8 <= count; i += 8)
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i), _mm256_cvtps_ph(_mm256_loadu_ps(in + i), _MM_FROUND_TO_NEAREST_INT));
  for (; i < count; ++i) out[i] = ::half(in[i]).bits();
}
#endif

void toHalfBits(const float* in, uint16_t* out, size_t count) {
#if defined(__x86_64__) || defined(__i386__)
  static const bool f16c = [] {  // CPUID leaf 1, ECX bit 29 (Clang's __builtin_cpu_supports lacks "f16c")
    unsigned a = 0, b = 0, c = 0, d = 0;
    return __builtin_cpu_supports("avx") && __get_cpuid(1, &a, &b, &c, &d) && (c & (1u << 29)) != 0;
  }();
  if (f16c) {
    toHalfBitsF16c(in, out, count);
    return;
  }
#endif
  for (size_t i = 0; i < count; ++i) out[i] = ::half(in[i]).bits();
}

// PNG (8 bits per channel, grey, grey+alpha, RGB or RGBA): every row filtered with "Sub" (each byte
// minus the same channel of the pixel to its left), the rows deflated by zlib at its fastest level.
// stb_image_write's own deflate took a fifth of a whole `voxlab run` (perf, vct-grid on the Cornell
// box, 2026-12-02: 16 % in libstb of 6.1 s CPU); zlib's level 1 takes a fraction of that for files
// a little larger. PNG is lossless, so the pixels read back are the same either way.
static void appendBigEndian(std::string& out, uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(char((v >> shift) & 0xffu));
}
static void appendChunk(std::string& out, const char* type, const unsigned char* data, size_t size) {
  appendBigEndian(out, uint32_t(size));
  const size_t start = out.size();
  out.append(type, 4);
  if (size) out.append(reinterpret_cast<const char*>(data), size);
  uLong crc = crc32(0L, reinterpret_cast<const Bytef*>(out.data() + start), uInt(4 + size));
  appendBigEndian(out, uint32_t(crc));
}

namespace {

void checkPngShape(int width, int height, int channels) {
  if (width <= 0 || height <= 0 || channels < 1 || channels > 4)
    throw Error(std::to_string(width) + "x" + std::to_string(height) + "x" + std::to_string(channels) +
                " is not an image PNG can hold");
}

// The image's rows, each "Sub"-filtered behind its filter byte, deflated: an IDAT's (or fdAT's) data.
std::vector<unsigned char> deflatedRows(int width, int height, int channels, const uint8_t* data) {
  const size_t stride = size_t(width) * channels;
  std::vector<unsigned char> filtered((stride + 1) * size_t(height));
  for (int y = 0; y < height; ++y) {
    const uint8_t* row = data + size_t(y) * stride;
    unsigned char* out = &filtered[size_t(y) * (stride + 1)];
    out[0] = 1;  // filter type Sub
    for (size_t i = 0; i < stride; ++i) out[1 + i] = uint8_t(row[i] - (i >= size_t(channels) ? row[i - channels] : 0));
  }
  uLongf packedSize = compressBound(uLong(filtered.size()));
  std::vector<unsigned char> packed(packedSize);
  if (compress2(packed.data(), &packedSize, filtered.data(), uLong(filtered.size()), Z_BEST_SPEED) != Z_OK)
    throw Error("zlib could not compress the image");
  packed.resize(packedSize);
  return packed;
}

void putBigEndian(unsigned char* at, uint32_t v) {
  for (int i = 0; i < 4; ++i) at[i] = uint8_t(v >> (24 - 8 * i));
}

std::string pngSignatureAndHeader(int width, int height, int channels) {
  static const unsigned char kColourType[5] = {0, 0, 4, 2, 6};  // by channel count: grey, grey+alpha, RGB, RGBA
  unsigned char header[13];
  putBigEndian(header, uint32_t(width));
  putBigEndian(header + 4, uint32_t(height));
  header[8] = 8;  // bits per channel
  header[9] = kColourType[channels];
  header[10] = header[11] = header[12] = 0;  // deflate, adaptive filtering, no interlace
  std::string file("\x89PNG\r\n\x1a\n", 8);
  appendChunk(file, "IHDR", header, sizeof header);
  return file;
}

}  // namespace

std::string encodePng(int width, int height, int channels, const uint8_t* data) {
  checkPngShape(width, height, channels);
  const std::vector<unsigned char> packed = deflatedRows(width, height, channels, data);
  std::string file = pngSignatureAndHeader(width, height, channels);
  appendChunk(file, "IDAT", packed.data(), packed.size());
  appendChunk(file, "IEND", nullptr, 0);
  return file;
}

std::string encodeAnimatedPng(int width, int height, int channels, const std::vector<const uint8_t*>& frames,
                              int frameMs) {
  checkPngShape(width, height, channels);
  if (frames.empty()) throw Error("an animated PNG needs at least one frame");
  if (frameMs < 1 || frameMs > 65535) throw Error("a frame lasts 1..65535 ms, got " + std::to_string(frameMs));
  std::string file = pngSignatureAndHeader(width, height, channels);
  unsigned char control[8];
  putBigEndian(control, uint32_t(frames.size()));
  putBigEndian(control + 4, 0);  // plays: 0 = forever
  appendChunk(file, "acTL", control, sizeof control);
  uint32_t sequence = 0;  // fcTL and fdAT chunks share one sequence
  for (size_t k = 0; k < frames.size(); ++k) {
    unsigned char frame[26];
    putBigEndian(frame, sequence++);
    putBigEndian(frame + 4, uint32_t(width));
    putBigEndian(frame + 8, uint32_t(height));
    putBigEndian(frame + 12, 0);  // x offset
    putBigEndian(frame + 16, 0);  // y offset
    frame[20] = uint8_t(frameMs >> 8);  // delay numerator ...
    frame[21] = uint8_t(frameMs & 0xff);
    frame[22] = uint8_t(1000 >> 8);  // ... over 1000: milliseconds
    frame[23] = uint8_t(1000 & 0xff);
    frame[24] = 0;  // dispose: none (the next frame covers the whole image)
    frame[25] = 0;  // blend: source (replace)
    appendChunk(file, "fcTL", frame, sizeof frame);
    const std::vector<unsigned char> packed = deflatedRows(width, height, channels, frames[k]);
    if (k == 0) {  // the default image: what a viewer without APNG support shows
      appendChunk(file, "IDAT", packed.data(), packed.size());
    } else {
      std::vector<unsigned char> data(4 + packed.size());
      putBigEndian(data.data(), sequence++);
      std::copy(packed.begin(), packed.end(), data.begin() + 4);
      appendChunk(file, "fdAT", data.data(), data.size());
    }
  }
  appendChunk(file, "IEND", nullptr, 0);
  return file;
}

void writePngFile(const std::string& path, int width, int height, int channels, const uint8_t* data) {
  std::string file;
  try {
    file = encodePng(width, height, channels, data);
  } catch (const Error& e) {
    throw Error("cannot write '" + path + "': " + e.what());
  }
  std::ofstream f(path, std::ios::binary);
  if (!f || !f.write(file.data(), std::streamsize(file.size())))
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
  // Written from an 8-bit texture as half floats (capture.cpp, writeLevelExr): each value is within
  // 2^-12 of its byte k's k/255, and reads back as the float the texture's readback gave, k times
  // the float 1/255 (llvmpipe's conversion; GL allows this or k/255 rounded once, which differ by
  // one ulp for 126 of the 256 bytes).
  const std::string format = img.attribute("voxlab:format");
  if (format == "r8" || format == "rg8" || format == "rgba8") {
    for (float& v : img.pixels) v = float(std::lround(v * 255.0f)) * (1.0f / 255.0f);
    img.eightBit = true;
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
