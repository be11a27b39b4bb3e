// CPU reference of lpv (see reference.h). Every loop visits neighbours, faces and channels in the
// order the shaders do (shaders/lpv/propagate.comp.glsl), so fp32 sums are identical.
#include "techniques/lpv/reference.h"

#include <algorithm>
#include <cmath>

namespace voxlab::lpv {

glm::dvec3 ShField::flux() const {
  glm::dvec3 sum(0.0);
  for (const auto& c : cells)
    for (int ch = 0; ch < 3; ++ch) sum[ch] += double(c[ch].x);
  return sum * double(kFluxPerC00);
}

float faceTransmission(const gpu::LpvVoxel* v, const glm::vec3& travel, const glm::vec3& d,
                       const PropagationSettings& s, int step) {
  if (s.occlusion == Occlusion::None || !v || !decodeOccupied(v->colorOcclusion)) return 1.0f;
  if (step == 0 && s.firstStepUnoccluded) return 1.0f;
  // The stored normal closest to the travel direction (thesis: blocks light travelling along it),
  // or closest up to sign (two-sided: the surface blocks both ways), or the one facing the light
  // most (front: a surface blocks light arriving at its front, not the light it sends), empty
  // channels skipped.
  glm::vec3 best(0.0f);
  float bestDot = -1e30f;
  for (int c = 0; c < 4; ++c) {
    uint32_t m = v->normals[c];
    if (m == 0u) continue;
    glm::vec3 n = decodeNormalMask(m);
    float t = (n.x * travel.x + n.y * travel.y) + n.z * travel.z;
    if ((s.occlusion == Occlusion::TwoSided && t < 0.0f) || s.occlusion == Occlusion::Front) { n = -n; t = -t; }
    if (t > bestDot) { bestDot = t; best = n; }
  }
  // front: no stored surface faces the light (it leaves the fronts of all of them): nothing blocks.
  if (s.occlusion == Occlusion::Front && !(bestDot > 0.0f)) return 1.0f;
  float blocked = s.occlusionAmplifier * shEvaluate(shLobe(best), d);
  return 1.0f - std::fmin(std::fmax(blocked, 0.0f), 1.0f);
}

// lpv.clamp-conserves: per channel, the factor on a source cell's clamped face fluxes that makes the
// 30 faces it lights carry the flux of the unclamped 30, sum omega e (0 where that is not
// positive); 1 when off. The twin of conserveScale in propagate.comp.glsl, in the same order.
static glm::vec3 conserveScales(const std::array<SH, 3>& src, const PropagationSettings& s) {
  if (!s.clampConserves || !s.clampFaces) return glm::vec3(1.0f);
  glm::vec3 scale;
  for (int ch = 0; ch < 3; ++ch) {
    float signedFlux = 0.0f, clampedFlux = 0.0f;
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) {
        if (j == i) continue;
        float e = shEvaluate(src[ch], faceDirection(i, j)), omega = faceSolidAngle(i, j);
        signedFlux = signedFlux + e * omega;
        clampedFlux = clampedFlux + std::fmax(e, 0.0f) * omega;
      }
    scale[ch] = clampedFlux > 0.0f ? std::fmax(signedFlux, 0.0f) / clampedFlux : 0.0f;
  }
  return scale;
}

static void gatherNeighbour(const ShField& source, const std::vector<gpu::LpvVoxel>& voxels, glm::ivec3 cell, int i,
                            const PropagationSettings& s, int step, std::array<SH, 3>& acc) {
  glm::ivec3 n = cell + faceOffset(i);
  if (!source.inside(n)) return;
  const auto& src = source.at(n);
  const gpu::LpvVoxel* v = voxels.empty() ? nullptr : &voxels[source.index(n)];
  glm::vec3 travel = -glm::vec3(faceOffset(i));
  const glm::vec3 scale = conserveScales(src, s);
  for (int j = 0; j < 6; ++j) {
    if (j == i) continue;
    glm::vec3 d = faceDirection(i, j);
    float omega = faceSolidAngle(i, j);
    float occ = faceTransmission(v, travel, d, s, step);
    SH lobe = s.reprojection == Reprojection::Beam     ? shBeam(d)
              : s.reprojection == Reprojection::Travel ? shLobe(d)
                                                       : shLobe(glm::vec3(faceOffset(j)));
    for (int ch = 0; ch < 3; ++ch) {
      float e = shEvaluate(src[ch], d);
      if (s.clampFaces) e = std::fmax(e, 0.0f);
      float f = (((e * omega) * occ) * s.weightScale) * scale[ch];
      acc[ch] = acc[ch] + f * lobe;
    }
  }
}

std::array<SH, 3> gatherFrom(const ShField& source, const std::vector<gpu::LpvVoxel>& voxels, glm::ivec3 cell,
                             int i, const PropagationSettings& s, int step) {
  std::array<SH, 3> acc{SH(0.0f), SH(0.0f), SH(0.0f)};
  gatherNeighbour(source, voxels, cell, i, s, step, acc);
  return acc;
}

void propagateStep(const ShField& source, const ShField& totalIn, const std::vector<gpu::LpvVoxel>& voxels,
                   const PropagationSettings& s, int step, ShField& wave, ShField& total) {
  const int res = source.res;
  wave = ShField(res);
  total = ShField(res);
  for (int z = 0; z < res; ++z)
    for (int y = 0; y < res; ++y)
      for (int x = 0; x < res; ++x) {
        glm::ivec3 c(x, y, z);
        std::array<SH, 3> acc{SH(0.0f), SH(0.0f), SH(0.0f)};
        for (int i = 0; i < 6; ++i) gatherNeighbour(source, voxels, c, i, s, step, acc);
        wave.at(c) = acc;
        for (int ch = 0; ch < 3; ++ch) total.at(c)[ch] = totalIn.at(c)[ch] + acc[ch];
      }
}

PropagationResult propagate(const ShField& injected, const std::vector<gpu::LpvVoxel>& voxels,
                            const PropagationSettings& s, int steps) {
  PropagationResult r;
  r.total = injected;
  r.wave = injected;
  r.waveFlux.push_back(injected.flux());
  r.totalFlux.push_back(injected.flux());
  for (int k = 0; k < steps; ++k) {
    ShField wave, total;
    propagateStep(s.scheme == Scheme::Thesis ? r.total : r.wave, r.total, voxels, s, k, wave, total);
    r.wave = std::move(wave);
    r.total = std::move(total);
    r.waveFlux.push_back(r.wave.flux());
    r.totalFlux.push_back(r.total.flux());
  }
  return r;
}

std::array<FaceTerm, 5> faceTerms(const ShField& source, const std::vector<gpu::LpvVoxel>& voxels, glm::ivec3 cell,
                                  int i, const PropagationSettings& s, int step) {
  std::array<FaceTerm, 5> terms{};
  for (int k = 0; k < 5; ++k) terms[k].face = k < i ? k : k + 1;
  glm::ivec3 n = cell + faceOffset(i);
  if (!source.inside(n)) return terms;
  const auto& src = source.at(n);
  if (src[0] == SH(0.0f) && src[1] == SH(0.0f) && src[2] == SH(0.0f)) return terms;
  const gpu::LpvVoxel* v = voxels.empty() ? nullptr : &voxels[source.index(n)];
  glm::vec3 travel = -glm::vec3(faceOffset(i));
  const glm::vec3 scale = conserveScales(src, s);
  for (FaceTerm& t : terms) {
    glm::vec3 d = faceDirection(i, t.face);
    t.solidAngle = faceSolidAngle(i, t.face);
    t.transmission = faceTransmission(v, travel, d, s, step);
    for (int ch = 0; ch < 3; ++ch) {
      float e = shEvaluate(src[ch], d);
      if (s.clampFaces) e = std::fmax(e, 0.0f);
      t.intensity[ch] = e;
      t.flux[ch] = (((e * t.solidAngle) * t.transmission) * s.weightScale) * scale[ch];
    }
  }
  return terms;
}

std::vector<gpu::LpvVoxel> binFragments(const std::vector<FragmentRecord>& fragments, glm::vec3 fragOrigin,
                                        float fragVoxel, int fragRes, glm::vec3 gridOrigin, float cellSize,
                                        int res, float areaUnits) {
  std::vector<gpu::LpvVoxel> grid(size_t(res) * res * res);
  auto voxelIndex = [&](uint32_t pos) {
    return (size_t((pos >> 20) & 1023u) * fragRes + ((pos >> 10) & 1023u)) * fragRes + (pos & 1023u);
  };
  std::vector<uint32_t> sharing(size_t(fragRes) * fragRes * fragRes, 0u);
  for (const auto& f : fragments) ++sharing[voxelIndex(f.position)];
  for (int z = 0; z < res; ++z)
    for (int y = 0; y < res; ++y)
      for (int x = 0; x < res; ++x) {
        auto& v = grid[(size_t(z) * res + y) * res + x];
        v = gpu::LpvVoxel{};
        v.cell = uint32_t(x) | (uint32_t(y) << 10) | (uint32_t(z) << 20);
      }
  for (const auto& f : fragments) {
    glm::vec3 vox(float(f.position & 1023u), float((f.position >> 10) & 1023u), float((f.position >> 20) & 1023u));
    glm::vec3 p = fragOrigin + (vox + 0.5f) * fragVoxel;
    glm::vec3 u = (p - gridOrigin) / cellSize;
    glm::ivec3 c(std::floor(u.x), std::floor(u.y), std::floor(u.z));
    if (glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c, glm::ivec3(res)))) continue;
    auto& v = grid[(size_t(c.z) * res + c.y) * res + c.x];
    glm::uvec3 rgb8(f.albedo & 255u, (f.albedo >> 8) & 255u, (f.albedo >> 16) & 255u);
    v.colorOcclusion = std::max(v.colorOcclusion, encodeColorOcclusion(rgb8));
    v.fragmentCount += 1;
    glm::ivec3 k = snormComponents(f.normal);
    v.area += fragmentAreaUnits(k, sharing[voxelIndex(f.position)], areaUnits);
    uint32_t dotField = 0;
    int channel = tetraChannel(k, &dotField);
    v.normals[channel] = std::max(v.normals[channel], encodeNormalMask(k, dotField));
  }
  return grid;
}

glm::vec3 directionToLight(const voxlab::gpu::GpuLight& l, glm::vec3 p) {
  if (int(l.positionType.w) == VOXLAB_LIGHT_DIRECTIONAL) return -glm::vec3(l.directionRange);
  glm::vec3 d = glm::vec3(l.positionType) - p;
  return d / std::fmax(glm::length(d), 1e-4f);
}

glm::vec3 lightIrradiance(const voxlab::gpu::GpuLight& l, glm::vec3 p) {
  const glm::vec3 radiance(l.radiance);
  if (int(l.positionType.w) == VOXLAB_LIGHT_DIRECTIONAL) return radiance;
  glm::vec3 d = glm::vec3(l.positionType) - p;
  float dist = std::fmax(glm::length(d), 1e-4f);
  float falloff = 1.0f / std::fmax(dist * dist, 1e-8f);
  if (l.directionRange.w > 0.0f) {
    float r = dist / l.directionRange.w;
    float w = std::clamp(1.0f - r * r * r * r, 0.0f, 1.0f);
    falloff *= w * w;
  }
  if (int(l.positionType.w) == VOXLAB_LIGHT_SPOT) {
    float cosA = glm::dot(glm::vec3(l.directionRange), -d / dist);
    float t = std::clamp((cosA - l.spot.y) / std::fmax(l.spot.x - l.spot.y, 1e-4f), 0.0f, 1.0f);
    falloff *= t * t;
  }
  return radiance * falloff;
}

// The face of a point light's cube-face atlas that sees p, -1 for one view (lightMapFace in
// shaders/common/lights.glsl).
static int lightMapFace(const voxlab::gpu::GpuLight& g, glm::vec3 p) {
  if (g.positionType.w != VOXLAB_LIGHT_POINT) return -1;
  const glm::vec3 d = p - glm::vec3(g.positionType), a = glm::abs(d);
  if (a.x >= a.y && a.x >= a.z) return d.x >= 0.0f ? 0 : 1;
  if (a.y >= a.z) return d.y >= 0.0f ? 2 : 3;
  return d.z >= 0.0f ? 4 : 5;
}

float shadowVisibility(const ShadowedLight& l, glm::vec3 p, glm::vec3 n, bool* marginal) {
  const voxlab::gpu::GpuLight& g = l.light;
  if (g.spot.w < 0.5f) return 1.0f;
  auto viewProj = [&g](int face) { return face < 0 ? g.shadowViewProj : g.faceViewProj[face]; };
  float w = (viewProj(lightMapFace(g, p)) * glm::vec4(p, 1.0f)).w;
  const glm::vec3 q = p + n * (g.spot.z * w);
  const int face = lightMapFace(g, q);
  glm::vec4 clip = viewProj(face) * glm::vec4(q, 1.0f);
  glm::vec3 uvz = glm::vec3(clip) / clip.w * 0.5f + 0.5f;
  if (clip.w <= 0.0f || glm::any(glm::lessThan(uvz, glm::vec3(0.0f))) || glm::any(glm::greaterThan(uvz, glm::vec3(1.0f))))
    return 1.0f;
  // The face's tile of the atlas (lightMapTile): the whole map for one view.
  glm::vec2 tileLo(0.0f), tileHi(1.0f);
  if (face >= 0) {
    const glm::vec2 tile(float(l.width / 3), float(l.height / 2));
    tileLo = glm::vec2(float(face % 3), float(face / 3)) * tile / glm::vec2(float(l.width), float(l.height));
    tileHi = tileLo + tile / glm::vec2(float(l.width), float(l.height));
  }
  uvz = glm::vec3(glm::mix(tileLo, tileHi, glm::vec2(uvz)), uvz.z);
  const glm::vec2 texel = 1.0f / glm::vec2(float(l.width), float(l.height));
  const float threshold = uvz.z - 1e-4f;
  int lit = 0;
  for (int y = -1; y <= 1; ++y)
    for (int x = -1; x <= 1; ++x) {
      const glm::vec2 uv = glm::clamp(glm::vec2(uvz) + glm::vec2(float(x), float(y)) * texel, tileLo + 0.5f * texel,
                                      tileHi - 0.5f * texel);
      glm::vec2 t = uv * glm::vec2(float(l.width), float(l.height));
      glm::ivec2 i = glm::clamp(glm::ivec2(glm::floor(t)), glm::ivec2(0), glm::ivec2(l.width - 1, l.height - 1));
      float depth = l.depth[size_t(i.y) * l.width + i.x];
      lit += depth >= threshold;
      glm::vec2 edge = glm::abs(t - glm::round(t));
      if (marginal && (std::fmin(edge.x, edge.y) < 1e-4f || std::fabs(depth - threshold) < 1e-6f)) *marginal = true;
    }
  return float(lit) / 9.0f;
}

static glm::dvec4 lobeD(glm::vec3 n) { return glm::dvec4(shLobe(n)); }

Injected injectPerCell(const std::vector<gpu::LpvVoxel>& voxels, const gpu::LpvGrid& grid, const ShadowedLight& l,
                       float fragmentArea, float areaUnits) {
  Injected out;
  out.sh.assign(voxels.size(), {glm::dvec4(0.0), glm::dvec4(0.0), glm::dvec4(0.0)});
  out.marginal.assign(voxels.size(), 0.0);
  const int res = int(grid.centreRes.w);
  const float cellSize = grid.originCell.w;
  for (size_t i = 0; i < voxels.size(); ++i) {
    const gpu::LpvVoxel& v = voxels[i];
    if (!decodeOccupied(v.colorOcclusion)) continue;
    glm::ivec3 c(int(i % res), int(i / res % res), int(i / (size_t(res) * res)));
    glm::vec3 p = glm::vec3(grid.originCell) + (glm::vec3(c) + 0.5f) * cellSize;
    glm::vec3 toLight = directionToLight(l.light, p), n(0.0f);
    float best = -2.0f;
    for (int k = 0; k < 4; ++k) {
      if (v.normals[k] == 0u) continue;
      glm::vec3 m = glm::normalize(decodeNormalMask(v.normals[k]));
      float d = glm::dot(m, toLight);
      if (d > best) best = d, n = m;
    }
    if (!(best > 0.0f)) continue;
    bool unsure = false;
    double visibility = shadowVisibility(l, p + n * (0.5f * cellSize), n, &unsure);
    glm::dvec3 full = glm::dvec3(decodeColor(v.colorOcclusion)) * glm::dvec3(lightIrradiance(l.light, p)) * double(best) *
                      (double(v.area) / areaUnits * fragmentArea) / kPi;
    for (int ch = 0; ch < 3; ++ch) out.sh[i][ch] = full[ch] * visibility * lobeD(n);
    if (unsure) {
      out.marginal[i] = std::max({full.x, full.y, full.z}) * double(kLobe1);
      ++out.marginalCells;
    }
  }
  return out;
}

Injected injectPerFragment(const std::vector<FragmentRecord>& fragments, glm::vec3 fragOrigin, float fragVoxel,
                           int fragRes, const gpu::LpvGrid& grid, const ShadowedLight& l, float areaUnits,
                           float shift) {
  const int res = int(grid.centreRes.w);
  Injected out;
  out.sh.assign(size_t(res) * res * res, {glm::dvec4(0.0), glm::dvec4(0.0), glm::dvec4(0.0)});
  out.marginal.assign(out.sh.size(), 0.0);
  out.fragments.assign(out.sh.size(), 0u);
  auto voxelIndex = [&](uint32_t pos) {
    return (size_t((pos >> 20) & 1023u) * fragRes + ((pos >> 10) & 1023u)) * fragRes + (pos & 1023u);
  };
  std::vector<uint32_t> sharing(size_t(fragRes) * fragRes * fragRes, 0u);
  for (const auto& f : fragments) ++sharing[voxelIndex(f.position)];
  std::vector<char> counted(out.sh.size(), 0);
  for (const auto& f : fragments) {
    glm::vec3 vox(float(f.position & 1023u), float((f.position >> 10) & 1023u), float((f.position >> 20) & 1023u));
    glm::vec3 p = fragOrigin + (vox + 0.5f) * fragVoxel;
    glm::ivec3 k = snormComponents(f.normal);
    glm::vec3 n = glm::normalize(glm::vec3(k) / 127.0f);
    glm::vec3 u = (p - glm::vec3(grid.originCell)) / grid.originCell.w + shift * n;
    glm::ivec3 c(std::floor(u.x), std::floor(u.y), std::floor(u.z));
    if (glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c, glm::ivec3(res)))) continue;
    float cosine = glm::dot(n, directionToLight(l.light, p));
    if (!(cosine > 0.0f)) continue;
    glm::dvec3 albedo(double(f.albedo & 255u), double((f.albedo >> 8) & 255u), double((f.albedo >> 16) & 255u));
    albedo *= double(kInv255);
    double area = double(fragmentAreaUnits(k, sharing[voxelIndex(f.position)], areaUnits)) / areaUnits * fragVoxel * fragVoxel;
    float behind = 0.5f * fragVoxel * (std::fabs(n.x) + std::fabs(n.y) + std::fabs(n.z));
    bool unsure = false;
    double visibility = shadowVisibility(l, p + n * behind, n, &unsure);
    glm::dvec3 full = albedo * glm::dvec3(lightIrradiance(l.light, p)) * double(cosine) * area / kPi;
    const size_t cell = (size_t(c.z) * res + c.y) * res + c.x;
    ++out.fragments[cell];
    for (int ch = 0; ch < 3; ++ch) out.sh[cell][ch] += full[ch] * visibility * lobeD(n);
    if (unsure) {
      out.marginal[cell] += std::max({full.x, full.y, full.z}) * double(kLobe1);
      out.marginalCells += !counted[cell];
      counted[cell] = 1;
    }
  }
  return out;
}

std::array<SH, 3> sampleTrilinear(const ShField& f, glm::vec3 cellPos) {
  glm::vec3 u = glm::clamp(cellPos - 0.5f, glm::vec3(0.0f), glm::vec3(float(f.res - 1)));
  glm::ivec3 b = glm::min(glm::ivec3(glm::floor(u)), glm::ivec3(f.res - 2 < 0 ? 0 : f.res - 2));
  glm::vec3 t = u - glm::vec3(b);
  std::array<SH, 3> out{SH(0.0f), SH(0.0f), SH(0.0f)};
  for (int corner = 0; corner < 8; ++corner) {
    glm::ivec3 o(corner & 1, (corner >> 1) & 1, corner >> 2);
    glm::ivec3 c = glm::min(b + o, glm::ivec3(f.res - 1));
    float w = (o.x ? t.x : 1 - t.x) * (o.y ? t.y : 1 - t.y) * (o.z ? t.z : 1 - t.z);
    for (int ch = 0; ch < 3; ++ch) out[ch] += w * f.at(c)[ch];
  }
  return out;
}

}  // namespace voxlab::lpv
