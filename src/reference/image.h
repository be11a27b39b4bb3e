// A float RGB image as the reference renderer and the image tools see it.
//
// Pixels are stored top row first (row 0 is the top of the picture, as in EXR and PNG files),
// three floats per pixel, linear radiance (or a visible fraction for ambient occlusion).
#pragma once
#include <cstddef>
#include <vector>

namespace voxlab::reference {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;     // width * height * 3, top row first
  std::vector<float> stdErr;  // per-pixel standard error of the mean, same layout; may be empty

  Image() = default;
  Image(int w, int h) : width(w), height(h), rgb(size_t(w) * size_t(h) * 3, 0.0f) {}
  size_t pixelCount() const { return size_t(width) * size_t(height); }
  float* at(int x, int y) { return &rgb[(size_t(y) * size_t(width) + size_t(x)) * 3]; }
  const float* at(int x, int y) const { return &rgb[(size_t(y) * size_t(width) + size_t(x)) * 3]; }
};

// Rec. 709 / sRGB luminance of linear RGB.
inline float luminance(const float* rgb) {
  return 0.2126f * rgb[0] + 0.7152f * rgb[1] + 0.0722f * rgb[2];
}

}  // namespace voxlab::reference
