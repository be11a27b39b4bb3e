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
  // or closest up to sign (two-sided: the surface blocks both ways), empty channels skipped.
  glm::vec3 best(0.0f);
  float bestDot = -1e30f;
  for (int c = 0; c < 4; ++c) {
    uint32_t m = v->normals[c];
    if (m == 0u) continue;
    glm::vec3 n = decodeNormalMask(m);
    float t = (n.x * travel.x + n.y * travel.y) + n.z * travel.z;
    if (s.occlusion == Occlusion::TwoSided && t < 0.0f) { n = -n; t = -t; }
    if (t > bestDot) { bestDot = t; best = n; }
  }
  float blocked = s.occlusionAmplifier * shEvaluate(shLobe(best), d);
  return 1.0f - std::fmin(std::fmax(blocked, 0.0f), 1.0f);
}

static void gatherNeighbour(const ShField& source, const std::vector<gpu::LpvVoxel>& voxels, glm::ivec3 cell, int i,
                            const PropagationSettings& s, int step, std::array<SH, 3>& acc) {
  glm::ivec3 n = cell + faceOffset(i);
  if (!source.inside(n)) return;
  const auto& src = source.at(n);
  const gpu::LpvVoxel* v = voxels.empty() ? nullptr : &voxels[source.index(n)];
  glm::vec3 travel = -glm::vec3(faceOffset(i));
  for (int j = 0; j < 6; ++j) {
    if (j == i) continue;
    glm::vec3 d = faceDirection(i, j);
    float omega = faceSolidAngle(i, j);
    float occ = faceTransmission(v, travel, d, s, step);
    SH lobe = shLobe(glm::vec3(faceOffset(j)));
    for (int ch = 0; ch < 3; ++ch) {
      float e = shEvaluate(src[ch], d);
      if (s.clampFaces) e = std::fmax(e, 0.0f);
      float f = ((e * omega) * occ) * s.weightScale;
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
