// Image files: EXR through OpenEXR, PNG/JPEG/TGA/BMP/HDR through stb (both Debian packages).
//
// voxlab uses these two small libraries instead of OpenImageIO in its binary: OpenImageIO 2.4 on
// Debian pulls in about 250 shared libraries, and resolving their symbols cost 0.4 to 0.7 s at
// every start of `voxlab` on this machine (measured with perf: 74 % of `voxlab --help` in the
// dynamic loader), which is a third of the 1.5 s budget for a whole run.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace voxlab {

struct ImageFileAttribute {
  std::string name;
  std::string value;
  bool isInt = false;  // written as an int attribute (EXR), else a string
};

struct ImageFileData {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> pixels;  // top row first, channels interleaved
  std::vector<ImageFileAttribute> attributes;
  bool eightBit = false;      // read from an 8-bit file, or an EXR of an 8-bit texture: values are k/255
  std::string attribute(const std::string& name, const std::string& fallback = "") const;
};

// Lossless either way. Zip: zlib at its fastest level, the smaller file. Rle: runs of equal bytes
// only, about half of Zip's time on a large volume level and two to four times its size.
enum class ExrCompression { Zip, Rle };
// Writes 1..4 channels as EXR (ZIP compression, or RLE where asked), channels Y / R,G / R,G,B / R,G,B,A, float or
// half. Throws Error naming the path.
void writeExrFile(const std::string& path, const ImageFileData& image, bool half = false,
                  ExrCompression compression = ExrCompression::Zip);
// The same from values already laid out: width x height pixels, top row first, 'channels'
// interleaved, as 32-bit floats or as the bits of half floats (toHalfBits).
enum class ExrPixels { Float, Half };
void writeExrFile(const std::string& path, int width, int height, int channels,
                  const std::vector<ImageFileAttribute>& attributes, ExrPixels type, const void* pixels,
                  ExrCompression compression = ExrCompression::Zip);
// IEEE 754 binary16 bits of each value (OpenEXR's half), rounded to nearest, ties to even.
void toHalfBits(const float* in, uint16_t* out, size_t count);
// Writes 8-bit PNG (1..4 channels, top row first). Throws Error naming the path.
void writePngFile(const std::string& path, int width, int height, int channels, const uint8_t* data);
// The bytes of that PNG file (for a page that embeds the image); throws Error on a bad size.
std::string encodePng(int width, int height, int channels, const uint8_t* data);
// An animated PNG (APNG: acTL, then per frame an fcTL and its pixels, the first frame as the IDAT
// every PNG reader shows, the others as fdAT) of frames of one size, each shown 'frameMs', looping
// forever. Throws Error on a bad size, no frames or a delay outside 1..65535 ms.
std::string encodeAnimatedPng(int width, int height, int channels, const std::vector<const uint8_t*>& frames,
                              int frameMs);
// Reads EXR (any channels; R,G,B,A or Y first) or an 8-bit format stb reads. Throws Error.
ImageFileData readImageFile(const std::string& path);

}  // namespace voxlab
