// Script verbs that check image files the script saved (screenshots, saved views): whole images
// equal or different by a fraction of their pixels, and regions of them (text drawn, a panel
// changed or not). They read PNGs only; nothing here touches the viewer's state.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "capture/image_files.h"
#include "inspect/script_verbs.h"
#include "inspect/viewer_state.h"

namespace voxlab {

namespace {

// An 8-bit image (PNG) as bytes, channels as stored.
struct ImageBytes {
  int width = 0, height = 0;
  std::vector<uint8_t> pixels;
  size_t channels() const { return pixels.size() / std::max(size_t(width) * height, size_t(1)); }
  const uint8_t* at(int x, int y) const { return &pixels[(size_t(y) * width + x) * channels()]; }
};

ImageBytes readImageBytes(const std::string& path) {
  ImageFileData img = readImageFile(path);
  ImageBytes bytes{img.width, img.height, std::vector<uint8_t>(img.pixels.size())};
  for (size_t i = 0; i < bytes.pixels.size(); ++i)
    bytes.pixels[i] = uint8_t(std::lround(std::clamp(img.pixels[i], 0.0f, 1.0f) * 255.0f));
  return bytes;
}

void compareImages(Viewer&, const ScriptCall& call) {
  const ImageBytes p = readImageBytes(call.arg(0)), q = readImageBytes(call.arg(1));
  const ImageDifference d = imageDifference(p.pixels, p.width, p.height, q.pixels, q.width, q.height);
  std::printf("%s vs %s: %zu of %zu pixels differ (%.4f)\n", call.arg(0).c_str(), call.arg(1).c_str(), d.differing,
              d.pixels, d.fraction());
  if (call.verb() == "expect-images-equal") {
    if (d.differing != 0) call.fail(std::to_string(d.differing) + " pixels differ");
    return;
  }
  const double atLeast = call.floatArg(2);
  if (!(atLeast >= 0.0 && atLeast < 1.0)) call.badArgument("MIN_FRACTION must be in 0..1, not " + call.arg(2));
  if (!(d.fraction() > atLeast))
    call.fail(std::to_string(d.differing) + " of " + std::to_string(d.pixels) + " pixels differ (" +
              std::to_string(d.fraction()) + "), expected more than " + call.arg(2));
}

// A region of an image given in fractions of its size by the words from 'first' on (X0 Y0 X1 Y1),
// in pixels.
struct PixelRegion {
  int x0, y0, x1, y1;
  size_t pixels() const { return size_t(x1 - x0) * size_t(y1 - y0); }
};

PixelRegion regionOf(const ImageBytes& img, const ScriptCall& call, size_t first) {
  const PixelRegion r{int(std::floor(call.floatArg(first) * img.width)), int(std::floor(call.floatArg(first + 1) * img.height)),
                      int(std::ceil(call.floatArg(first + 2) * img.width)), int(std::ceil(call.floatArg(first + 3) * img.height))};
  if (!(0 <= r.x0 && r.x0 < r.x1 && r.x1 <= img.width && 0 <= r.y0 && r.y0 < r.y1 && r.y1 <= img.height))
    call.badArgument("the region must lie in 0..1 with X0 < X1 and Y0 < Y1");
  return r;
}

// Text on a background: pixels further than 48 of 255 in any channel from the region's most common
// colour (anti-aliased glyph edges below that are not counted).
void expectRegionInk(Viewer&, const ScriptCall& call) {
  const ImageBytes img = readImageBytes(call.arg(0));
  const PixelRegion r = regionOf(img, call, 1);
  const size_t c = img.channels();
  auto colour = [&](const uint8_t* px) {
    return uint32_t(px[0]) << 16 | uint32_t(px[std::min<size_t>(1, c - 1)]) << 8 | px[std::min<size_t>(2, c - 1)];
  };
  std::map<uint32_t, size_t> frequency;
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x) ++frequency[colour(img.at(x, y))];
  const uint32_t bg = std::max_element(frequency.begin(), frequency.end(),
                                       [](const auto& a, const auto& b) { return a.second < b.second; })->first;
  const int background[3] = {int(bg >> 16), int((bg >> 8) & 255), int(bg & 255)};
  size_t ink = 0;
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x) {
      const uint8_t* px = img.at(x, y);
      for (size_t k = 0; k < std::min<size_t>(c, 3); ++k)
        if (std::abs(int(px[k]) - background[k]) > 48) {
          ++ink;
          break;
        }
    }
  const double fraction = double(ink) / double(r.pixels());
  std::printf("%s region (%d, %d)-(%d, %d): %.4f of the pixels differ from the most common colour (need > %s)\n",
              call.arg(0).c_str(), r.x0, r.y0, r.x1, r.y1, fraction, call.arg(5).c_str());
  if (!(fraction > call.floatArg(5))) call.fail("only " + std::to_string(fraction) + " of the region's pixels stand out");
}

void compareRegions(Viewer&, const ScriptCall& call) {
  const ImageBytes p = readImageBytes(call.arg(0)), q = readImageBytes(call.arg(1));
  if (p.width != q.width || p.height != q.height || p.pixels.size() != q.pixels.size())
    call.fail("the images differ in size");
  const PixelRegion r = regionOf(p, call, 2);
  const size_t c = p.channels();
  size_t count = 0;
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x)
      if (!std::equal(p.at(x, y), p.at(x, y) + c, q.at(x, y))) ++count;
  std::printf("%s vs %s region (%d, %d)-(%d, %d): %zu of %zu pixels differ\n", call.arg(0).c_str(), call.arg(1).c_str(),
              r.x0, r.y0, r.x1, r.y1, count, r.pixels());
  if (call.verb() == "expect-regions-differ" && count == 0) call.fail("the region is identical in both images");
  if (call.verb() == "expect-regions-equal" && count != 0)
    call.fail(std::to_string(count) + " pixels of the region differ");
}

}  // namespace

VOXLAB_REGISTER_SCRIPT_VERBS(image_checks, 130,
  {"expect-images-differ", 3, 3,
   "expect-images-differ A.png B.png MIN_FRACTION (more than MIN_FRACTION of the pixels differ; images of different "
   "sizes differ everywhere)",
   compareImages},
  {"expect-images-equal", 2, 2, "expect-images-equal A.png B.png", compareImages},
  {"expect-region-ink", 6, 6,
   "expect-region-ink A.png X0 Y0 X1 Y1 MIN_FRACTION (in the region, in fractions of the image, more than "
   "MIN_FRACTION of the pixels differ from its most common colour)",
   expectRegionInk},
  {"expect-regions-differ", 6, 6,
   "expect-regions-differ A.png B.png X0 Y0 X1 Y1 (the region, in fractions of the images, differs between them)",
   compareRegions},
  {"expect-regions-equal", 6, 6, "expect-regions-equal A.png B.png X0 Y0 X1 Y1 (the region is the same in both)",
   compareRegions});

}  // namespace voxlab
