#include "scene/alpha_coverage.h"

#include <algorithm>

namespace voxlab {

AlphaCoverage AlphaCoverage::build(const Scene& scene) {
  AlphaCoverage cov;
  cov.firstLevel.assign(scene.materials.size(), 0);
  cov.levelCount.assign(scene.materials.size(), 0);
  uint32_t totalBits = 0;
  std::vector<std::vector<uint8_t>> levelBits;  // one byte per texel while building
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    const Material& mat = scene.materials[m];
    if (mat.alphaMode != AlphaMode::Mask) continue;
    const TextureImage* tex = mat.baseColorTexture >= 0 && size_t(mat.baseColorTexture) < scene.textures.size()
                                  ? &scene.textures[size_t(mat.baseColorTexture)]
                                  : nullptr;
    uint32_t w = tex ? uint32_t(tex->width) : 1, h = tex ? uint32_t(tex->height) : 1;
    std::vector<uint8_t> level(size_t(w) * h);
    for (size_t i = 0; i < level.size(); ++i) {
      float alpha = mat.baseColor.w * (tex ? float(tex->rgba8[i * 4 + 3]) / 255.0f : 1.0f);
      level[i] = alpha >= mat.alphaCutoff ? 1 : 0;
    }
    cov.firstLevel[m] = uint32_t(cov.levels.size());
    while (true) {
      cov.levels.push_back({totalBits, w, h});
      totalBits += w * h;
      levelBits.push_back(level);
      ++cov.levelCount[m];
      if (w == 1 && h == 1) break;
      uint32_t nw = (w + 1) / 2, nh = (h + 1) / 2;
      std::vector<uint8_t> next(size_t(nw) * nh, 0);
      for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) next[size_t(y / 2) * nw + x / 2] |= level[size_t(y) * w + x];
      level.swap(next);
      w = nw;
      h = nh;
    }
  }
  cov.bits.assign(std::max<uint32_t>(1, (totalBits + 31) / 32), 0u);
  for (size_t l = 0; l < cov.levels.size(); ++l) {
    const CoverageLevel& L = cov.levels[l];
    for (uint32_t i = 0; i < L.width * L.height; ++i)
      if (levelBits[l][i]) cov.bits[(L.bitOffset + i) >> 5] |= 1u << ((L.bitOffset + i) & 31u);
  }
  if (cov.levels.empty()) cov.levels.push_back({});  // keeps the GPU buffer non-empty
  return cov;
}

}  // namespace voxlab
