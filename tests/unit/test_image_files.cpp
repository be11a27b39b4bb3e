// The PNG writer (src/capture/image_files.cpp: zlib deflate of "Sub"-filtered rows) read back by
// an independent decoder (stb_image) gives the same bytes, for every channel count, at sizes that
// are not multiples of anything, and with values that make the Sub filter wrap around 0 and 255.
#include <gtest/gtest.h>
#include <stb_image.h>

#include <cstdio>
#include <random>
#include <vector>

#include "capture/image_files.h"
#include "core/error.h"

namespace voxlab {
namespace {

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

}  // namespace
}  // namespace voxlab
