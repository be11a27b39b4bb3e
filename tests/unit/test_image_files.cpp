// The PNG writer (src/capture/image_files.cpp: zlib deflate of "Sub"-filtered rows) read back by
// an independent decoder (stb_image) gives the same bytes, for every channel count, at sizes that
// are not multiples of anything, and with values that make the Sub filter wrap around 0 and 255.
// The half floats of a run's EXRs: the conversion against a reference written here, and what a
// run's level files read back as.
#include <gtest/gtest.h>
#include <stb_image.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <vector>

#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <zlib.h>

#include "capture/capture.h"
#include "capture/image_files.h"
#include "capture/output_handler.h"
#include "core/error.h"

namespace voxlab {
namespace {

// An animated PNG: its chunks in the order APNG requires (acTL before the first IDAT, fcTL before
// each frame's pixels, one sequence over fcTL and fdAT from 0), its first frame the image another
// decoder (stb) reads, and every later frame's fdAT inflating to that frame's filtered rows.
TEST(ImageFiles, AnimatedPngHoldsEveryFrameInSequence) {
  const int w = 5, h = 3, c = 3;
  std::vector<std::vector<uint8_t>> frames(3, std::vector<uint8_t>(size_t(w * h * c)));
  for (size_t k = 0; k < frames.size(); ++k)
    for (size_t i = 0; i < frames[k].size(); ++i) frames[k][i] = uint8_t(i * 7 + k * 50);
  const std::string file = encodeAnimatedPng(w, h, c, {frames[0].data(), frames[1].data(), frames[2].data()}, 125);
  auto be32 = [&](size_t at) {
    return uint32_t(uint8_t(file[at])) << 24 | uint32_t(uint8_t(file[at + 1])) << 16 |
           uint32_t(uint8_t(file[at + 2])) << 8 | uint32_t(uint8_t(file[at + 3]));
  };
  std::vector<std::string> types;
  std::vector<uint32_t> sequence;
  std::vector<std::string> fdats;
  for (size_t at = 8; at < file.size();) {
    const uint32_t size = be32(at);
    const std::string type = file.substr(at + 4, 4);
    types.push_back(type);
    ASSERT_EQ(be32(at + 8 + size), uint32_t(crc32(0L, reinterpret_cast<const Bytef*>(file.data() + at + 4), 4 + size)))
        << type;
    if (type == "acTL") {
      EXPECT_EQ(be32(at + 8), 3u);  // frames
      EXPECT_EQ(be32(at + 12), 0u);  // plays forever
    }
    if (type == "fcTL") {
      sequence.push_back(be32(at + 8));
      EXPECT_EQ(be32(at + 12), uint32_t(w));
      EXPECT_EQ(be32(at + 16), uint32_t(h));
      EXPECT_EQ((uint8_t(file[at + 28]) << 8) | uint8_t(file[at + 29]), 125);   // delay numerator
      EXPECT_EQ((uint8_t(file[at + 30]) << 8) | uint8_t(file[at + 31]), 1000);  // over 1000: ms
    }
    if (type == "fdAT") {
      sequence.push_back(be32(at + 8));
      fdats.push_back(file.substr(at + 12, size - 4));
    }
    at += 12 + size;
  }
  EXPECT_EQ(types, (std::vector<std::string>{"IHDR", "acTL", "fcTL", "IDAT", "fcTL", "fdAT", "fcTL", "fdAT", "IEND"}));
  EXPECT_EQ(sequence, (std::vector<uint32_t>{0, 1, 2, 3, 4}));
  int rw = 0, rh = 0, rc = 0;
  unsigned char* first = stbi_load_from_memory(reinterpret_cast<const stbi_uc*>(file.data()), int(file.size()), &rw, &rh, &rc, 3);
  ASSERT_NE(first, nullptr);
  EXPECT_EQ(std::vector<uint8_t>(first, first + w * h * c), frames[0]);
  stbi_image_free(first);
  ASSERT_EQ(fdats.size(), 2u);
  for (size_t k = 1; k < 3; ++k) {
    std::vector<unsigned char> rows(size_t((w * c + 1) * h));
    uLongf size = uLongf(rows.size());
    ASSERT_EQ(uncompress(rows.data(), &size, reinterpret_cast<const Bytef*>(fdats[k - 1].data()), uLong(fdats[k - 1].size())), Z_OK);
    for (int y = 0; y < h; ++y) {  // undo the Sub filter
      const unsigned char* row = &rows[size_t(y * (w * c + 1))];
      ASSERT_EQ(row[0], 1);
      for (int i = 0; i < w * c; ++i) {
        const uint8_t left = i >= c ? frames[k][size_t(y * w * c + i - c)] : 0;
        EXPECT_EQ(uint8_t(row[1 + i] + left), frames[k][size_t(y * w * c + i)]) << "frame " << k;
      }
    }
  }
  EXPECT_THROW(encodeAnimatedPng(w, h, c, {}, 125), Error);
  EXPECT_THROW(encodeAnimatedPng(w, h, c, {frames[0].data()}, 0), Error);
}

TEST(ImageFiles, PngRoundTripsEveryChannelCountThroughAnotherDecoder) {
  std::mt19937 rng(7);
  const std::string path = ::testing::TempDir() + "voxlab-png-roundtrip.png";
  for (int channels = 1; channels <= 4; ++channels)
    for (auto [w, h] : {std::pair{1, 1}, std::pair{3, 5}, std::pair{257, 31}}) {
      std::vector<uint8_t> pixels(size_t(w) * h * channels);
      for (size_t i = 0; i < pixels.size(); ++i)  // noise, with runs of 0 and 255 next to each other
        pixels[i] = (i / 7) % 3 == 0 ? uint8_t(rng()) : ((i / 5) % 2 ? 255 : 0);
      writePngFile(path, w, h, channels, pixels.data());
      int rw = 0, rh = 0, rc = 0;
      unsigned char* back = stbi_load(path.c_str(), &rw, &rh, &rc, channels);
      ASSERT_NE(back, nullptr) << stbi_failure_reason() << " (" << w << "x" << h << "x" << channels << ")";
      EXPECT_EQ(rw, w);
      EXPECT_EQ(rh, h);
      EXPECT_EQ(rc, channels);
      EXPECT_EQ(std::vector<uint8_t>(back, back + pixels.size()), pixels) << w << "x" << h << "x" << channels;
      stbi_image_free(back);
    }
  std::remove(path.c_str());
}

TEST(ImageFiles, PngWriterRefusesWhatPngCannotHoldAndMissingFolders) {
  const uint8_t pixel[4] = {1, 2, 3, 4};
  EXPECT_THROW(writePngFile(::testing::TempDir() + "x.png", 1, 1, 5, pixel), Error);
  EXPECT_THROW(writePngFile(::testing::TempDir() + "x.png", 0, 1, 3, pixel), Error);
  EXPECT_THROW(writePngFile(::testing::TempDir() + "no-such-folder/x.png", 1, 1, 3, pixel), Error);
}

// float -> binary16, round to nearest, ties to even, written from the format's definition.
uint16_t referenceHalf(float f) {
  uint32_t x;
  std::memcpy(&x, &f, 4);
  const uint16_t sign = uint16_t((x >> 16) & 0x8000u);
  const uint32_t e = (x >> 23) & 0xffu, m = x & 0x7fffffu;
  if (e == 0xffu) return uint16_t(sign | 0x7c00u | (m ? 0x200u | (m >> 13) : 0u));
  const int E = int(e) - 127 + 15;  // the half's biased exponent
  if (E >= 31) return uint16_t(sign | 0x7c00u);
  auto roundShift = [](uint32_t v, int shift) {  // v / 2^shift, to nearest, ties to even
    if (shift > 24) return 0u;
    uint32_t q = v >> shift, r = v & ((1u << shift) - 1u), half = 1u << (shift - 1);
    return q + ((r > half || (r == half && (q & 1u))) ? 1u : 0u);
  };
  if (e == 0) return sign;  // a float denormal is far below half the smallest half denormal
  if (E <= 0) return uint16_t(sign | roundShift(m | 0x800000u, 14 - E));  // a half denormal (2^-24 units)
  return uint16_t(sign | roundShift((uint32_t(E) << 23) | m, 13));
}

TEST(ImageFiles, HalfBitsRoundToNearestEvenLikeTheFormatsDefinition) {
  std::vector<float> values;
  for (uint64_t bits = 0; bits <= 0xffffffffull; bits += 4093) {  // every sign, exponent and mantissa region
    uint32_t b = uint32_t(bits);
    float f;
    std::memcpy(&f, &b, 4);
    values.push_back(f);
  }
  // Ties and edges: 1 + 2^-11 (a tie, to 1), 1 + 3 * 2^-11 (a tie, up), the largest half and the
  // first value that rounds to infinity, the smallest denormal and half of it (a tie, to 0).
  for (float f : {1.0f + std::ldexp(1.0f, -11), 1.0f + 3 * std::ldexp(1.0f, -11), 65504.0f, 65519.99f, 65520.0f,
                  std::ldexp(1.0f, -24), std::ldexp(1.0f, -25), 1.5f * std::ldexp(1.0f, -25), 0.0f, -0.0f,
                  std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(), 1.0f / 255.0f})
    values.push_back(f);
  // Any length: the vector path takes eight at a time, the rest one by one.
  values.resize(values.size() / 8 * 8 + 5);
  std::vector<uint16_t> halves(values.size());
  toHalfBits(values.data(), halves.data(), values.size());
  size_t wrong = 0;
  for (size_t i = 0; i < values.size(); ++i) {
    if (std::isnan(values[i])) {
      wrong += (halves[i] & 0x7c00u) != 0x7c00u || (halves[i] & 0x3ffu) == 0;  // any NaN
      continue;
    }
    if (halves[i] != referenceHalf(values[i]) && wrong++ < 5)
      ADD_FAILURE() << values[i] << ": 0x" << std::hex << halves[i] << ", expected 0x" << referenceHalf(values[i]);
  }
  EXPECT_EQ(wrong, 0u) << "of " << values.size();
}

// A run writes textures of 8-bit and 16-bit float formats as half floats: an 8-bit texture's
// values read back as exactly its k/255, a 16-bit float's exactly; a 32-bit float texture stays
// 32-bit (its values here have 17 significant bits). Small levels are deflated (ZIP); a volume
// level of 4 Mi values or more (128 x 128 x 64 RGBA) is written RLE, and keeps its values as well.
TEST(ImageFiles, LevelFilesKeepEveryValueOfTheirTextureFormat) {
  std::mt19937 rng(3);
  const std::string dir = ::testing::TempDir() + "voxlab-volume-files";
  std::filesystem::create_directories(dir);
  for (const glm::ivec3 size : {glm::ivec3(5, 3, 4), glm::ivec3(128, 128, 64)})
  for (const char* format : {"rgba8", "rgba16f", "r32f"}) {
    CapturedOutput out;
    out.desc.kind = OutputKind::Volume3D;
    out.desc.semantic = Semantic::Color;
    out.format = format;
    LevelData level;
    level.size = size;
    level.channels = std::string(format) == "r32f" ? 1 : 4;
    level.values.resize(size_t(size.x) * size.y * size.z * level.channels);
    for (float& v : level.values)
      v = std::string(format) == "rgba8" ? float(rng() % 256) * (1.0f / 255.0f)  // as llvmpipe reads bytes back
                                         : std::ldexp(float(rng() % 100000) / 100000.0f, int(rng() % 20) - 10);
    if (std::string(format) == "rgba16f") {  // round the values to halves: what such a texture holds
      std::vector<uint16_t> h(level.values.size());
      toHalfBits(level.values.data(), h.data(), h.size());
      for (size_t i = 0; i < h.size(); ++i) {
        const int e = (h[i] >> 10) & 31, m = h[i] & 1023;
        level.values[i] = e ? std::ldexp(float(1024 + m), e - 25) : std::ldexp(float(m), -24);
      }
    }
    out.levels = {level};
    nlohmann::json files = nlohmann::json::array();
    writeLevelFiles(out, dir, std::string("v-") + format, files);
    LevelData back = readLevelExr(dir + "/v-" + std::string(format) + ".exr");
    ASSERT_EQ(back.size, level.size) << format;
    ASSERT_EQ(back.values.size(), level.values.size()) << format;
    size_t wrong = 0;
    for (size_t i = 0; i < level.values.size(); ++i) wrong += back.values[i] != level.values[i];
    EXPECT_EQ(wrong, 0u) << format;
    EXPECT_EQ(readImageFile(dir + "/v-" + std::string(format) + ".exr").attribute("voxlab:format"), format);
    const bool large = level.values.size() >= (size_t(4) << 20);
    Imf::InputFile file((dir + "/v-" + std::string(format) + ".exr").c_str());
    EXPECT_EQ(file.header().compression(), large ? Imf::RLE_COMPRESSION : Imf::ZIP_COMPRESSION)
        << format << " " << level.values.size() << " values";
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace voxlab
