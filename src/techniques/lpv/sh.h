// SH L1 maths and the voxel encodings of lpv on the CPU: the twin of shaders/common/sh.glsl and
// of the encodings in shaders/lpv/encoding.glsl, written in the same order so the CPU reference
// propagation (reference.h) and the GPU agree bit for bit. Conventions: see sh.glsl.
#pragma once
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

namespace voxlab::lpv {

constexpr float kY00 = 0.282094792f;
constexpr float kY1 = 0.488602512f;
constexpr float kLobe0 = 0.886226925f;
constexpr float kLobe1 = 1.023326708f;
constexpr float kBeam1 = 1.534990061f;  // pi kY1: band 1 of a narrow beam of a lobe's flux (sh.glsl, shBeam)
constexpr float kFluxPerC00 = 3.544907702f;
constexpr float kSolidAngleFar = 0.4006696846f;
constexpr float kSolidAngleSide = 0.4234313544f;
constexpr float kSideAlong = 0.894427191f;
constexpr float kSideAcross = 0.4472135955f;
constexpr float kInv255 = 0.003921568627f;   // 1/255 (multiplied, never divided, on both sides)
constexpr float kDotFieldScale = 0.244094488f;  // 31/127: the 5-bit dot field from a dot of snorm integers
constexpr double kPi = 3.14159265358979323846;

using SH = glm::vec4;  // (c00, c1-1, c10, c11)

inline SH shBasis(const glm::vec3& d) { return {kY00, -kY1 * d.y, kY1 * d.z, -kY1 * d.x}; }
inline SH shLobe(const glm::vec3& n) { return {kLobe0, -kLobe1 * n.y, kLobe1 * n.z, -kLobe1 * n.x}; }
inline SH shBeam(const glm::vec3& d) { return {kLobe0, -kBeam1 * d.y, kBeam1 * d.z, -kBeam1 * d.x}; }
inline float shEvaluate(const SH& sh, const glm::vec3& d) {
  float a = sh.x * kY00, b = sh.y * (-kY1 * d.y), c = sh.z * (kY1 * d.z), e = sh.w * (-kY1 * d.x);
  return ((a + b) + c) + e;
}
inline float shDotLobe(const SH& sh, const glm::vec3& n) {
  float a = sh.x * kLobe0, b = sh.y * (-kLobe1 * n.y), c = sh.z * (kLobe1 * n.z), e = sh.w * (-kLobe1 * n.x);
  return ((a + b) + c) + e;
}
inline glm::vec3 shBand1(const SH& sh) { return {-sh.w, -sh.y, sh.z}; }

inline glm::ivec3 faceOffset(int i) {
  int axis = i >> 1, s = (i & 1) == 0 ? 1 : -1;
  return {axis == 0 ? s : 0, axis == 1 ? s : 0, axis == 2 ? s : 0};
}
inline glm::vec3 faceDirection(int i, int j) {
  glm::vec3 oi(faceOffset(i)), oj(faceOffset(j));
  if (j == (i ^ 1)) return -oi;
  return -oi * kSideAlong + oj * kSideAcross;
}
inline float faceSolidAngle(int i, int j) { return j == (i ^ 1) ? kSolidAngleFar : kSolidAngleSide; }

// --- Voxel encodings (seed 000 Listings 4.27-4.29) ----------------------------------------------

// The four regular-tetrahedron face directions of Listing 4.29 (pairwise dot -1/3).
inline glm::vec3 tetraDirection(int k) {
  const float a = 0.57735027f, b = 0.81649658f;
  switch (k) {
    case 0: return {0.0f, -a, b};
    case 1: return {0.0f, -a, -b};
    case 2: return {-b, a, 0.0f};
    default: return {b, a, 0.0f};
  }
}

// 8-bit linear colour, 7-bit contrast, occupancy bit; atomicMax keeps the most saturated fragment.
// Contrast = |(r-g, r-b, g-b)| / (sqrt 2 + r + g + b) in [0, 2 - sqrt 2], from the 8-bit values.
inline uint32_t encodeColorOcclusion(glm::uvec3 rgb8) {
  float r = float(rgb8.x) * kInv255, g = float(rgb8.y) * kInv255, b = float(rgb8.z) * kInv255;
  float dx = r - g, dy = r - b, dz = g - b;
  float len = std::sqrt((dx * dx + dy * dy) + dz * dz);
  float denom = (1.41421356f + r) + (g + b);
  uint32_t contrast = uint32_t(127.0f * len / denom);
  return 0x80000000u | (contrast << 24) | (rgb8.x << 16) | (rgb8.y << 8) | rgb8.z;
}
inline glm::vec3 decodeColor(uint32_t mask) {
  return glm::vec3(float((mask >> 16) & 255u), float((mask >> 8) & 255u), float(mask & 255u)) * kInv255;
}
inline uint32_t decodeContrast(uint32_t mask) { return (mask >> 24) & 127u; }
inline bool decodeOccupied(uint32_t mask) { return (mask >> 31) != 0u; }

// Normal from a voxel fragment's packSnorm4x8 word: components k/127, k in -127..127.
inline glm::ivec3 snormComponents(uint32_t word) {
  auto c = [&](int s) { int k = int(int8_t((word >> s) & 255u)); return k < -127 ? -127 : k; };
  return {c(0), c(8), c(16)};
}
// Tetrahedron channel of a snorm normal k/127 (argmax of k.f, ties to the lowest channel) and its
// 5-bit dot field uint(31 clamp(n.f, 0, 1)), computed on the integers.
inline int tetraChannel(glm::ivec3 k, uint32_t* dotField = nullptr) {
  int best = 0;
  float bestDot = -1e30f;
  glm::vec3 n(k);
  for (int c = 0; c < 4; ++c) {
    glm::vec3 f = tetraDirection(c);
    float d = (n.x * f.x + n.y * f.y) + n.z * f.z;
    if (d > bestDot) { bestDot = d; best = c; }
  }
  if (dotField) *dotField = uint32_t(std::fmin(std::fmax(bestDot, 0.0f), 127.0f) * kDotFieldScale);
  return best;
}
// The area one voxel fragment stands for, in 'units' per fragment voxel^2 (the twin of
// shaders/lpv/encoding.glsl's fragmentAreaUnits: its voxel holds 'count' fragments, and a voxel
// holds voxel^2 / |n|_1 of a conservatively voxelized plane).
inline uint32_t fragmentAreaUnits(glm::ivec3 k, uint32_t count, float units) {
  float l1 = float(std::abs(k.x) + std::abs(k.y) + std::abs(k.z));
  float l2 = std::sqrt(float(k.x * k.x + k.y * k.y + k.z * k.z));
  float perVoxel = l1 > 0.0f ? (units * l2) / l1 : units;
  float w = perVoxel / float(count > 0 ? count : 1u);
  return uint32_t(w + 0.5f);
}
// Normal mask of Listing 4.28: |x|*255 at bits 18-25 (sign 26), |y| at 9-16 (sign 17), |z| at
// 0-7 (sign 8), dot field at 27-31. Magnitudes round(|k| * 255 / 127) in integers.
inline uint32_t encodeNormalMask(glm::ivec3 k, uint32_t dotField) {
  auto mag = [](int v) { int a = v < 0 ? -v : v; return uint32_t((a * 510 + 127) / 254); };
  return (dotField << 27) | (mag(k.x) << 18) | (k.x < 0 ? 1u << 26 : 0u) | (mag(k.y) << 9) |
         (k.y < 0 ? 1u << 17 : 0u) | mag(k.z) | (k.z < 0 ? 1u << 8 : 0u);
}
inline glm::vec3 decodeNormalMask(uint32_t m) {
  auto comp = [&](int shift, int signBit) {
    float v = float((m >> shift) & 255u) * kInv255;
    return ((m >> signBit) & 1u) ? -v : v;
  };
  return {comp(18, 26), comp(9, 17), comp(0, 8)};
}

}  // namespace voxlab::lpv
