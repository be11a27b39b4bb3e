// Display mappings of the shared semantics (capture/output_handler.h, TexelMapping): how one texel
// of an image or a volume of that semantic looks, in the viewer and in the PNGs `voxlab run`
// writes. A semantic without one is shown normalised min..max through the false-colour ramp
// (depth and scalar use exactly that, by name, so that the tier below is declared too).
#include "capture/output_handler.h"

namespace voxlab {
namespace {

void colour(const float* v, int n, float x, float, float, uint8_t* o) {
  for (int k = 0; k < 3; ++k) o[k] = unitToByte(srgbEncode((k < n ? v[k] : v[0]) * x));
}

void radiance(const float* v, int n, float x, float, float, uint8_t* o) {
  for (int k = 0; k < 3; ++k) {
    float y = (k < n ? v[k] : v[0]) * x;
    o[k] = unitToByte(srgbEncode(y / (1.0f + y)));  // Reinhard
  }
}

void normal(const float* v, int n, float, float, float, uint8_t* o) {
  auto c = [&](int k) { return k < n ? v[k] : v[0]; };
  bool zero = c(0) == 0 && c(1) == 0 && c(2) == 0;
  for (int k = 0; k < 3; ++k) o[k] = zero ? 0 : unitToByte(c(k) * 0.5f + 0.5f);
}

void occupancy(const float* v, int n, float, float, float, uint8_t* o) {
  bool any = false;
  for (int k = 0; k < n; ++k) any = any || v[k] != 0.0f;
  o[0] = o[1] = o[2] = any ? 255 : 0;
}

void opacity(const float* v, int n, float x, float, float, uint8_t* o) {
  o[0] = o[1] = o[2] = unitToByte((n == 4 ? v[3] : v[0]) * x);
}

void fraction(const float* v, int, float x, float, float, uint8_t* o) { o[0] = o[1] = o[2] = unitToByte(v[0] * x); }

void ramp(const float* v, int, float, float lo, float hi, uint8_t* o) {
  falseColourRamp(hi > lo ? (v[0] - lo) / (hi - lo) : 0.0f, o);
}

struct Registration {
  Registration() {
    //                   mapping      normalise alphaIsOpacity exact
    registerTexelMapping(Semantic::Color, {&colour, false, true, false});
    registerTexelMapping(Semantic::RadianceHDR, {&radiance, false, true, false});
    registerTexelMapping(Semantic::Normal, {&normal, false, false, false});
    registerTexelMapping(Semantic::Occupancy, {&occupancy, false, false, true});
    registerTexelMapping(Semantic::Opacity, {&opacity, false, true, false});
    registerTexelMapping(Semantic::Fraction, {&fraction, false, false, false});
    registerTexelMapping(Semantic::Depth, {&ramp, true, false, false});
    registerTexelMapping(Semantic::Scalar, {&ramp, true, false, false});
  }
} registration;

}  // namespace
}  // namespace voxlab
