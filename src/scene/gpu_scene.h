// GpuScene: a Scene uploaded once for every stage that rasterizes it: one interleaved vertex
// buffer (position, normal, uv), one index buffer, the materials as an SSBO, base colour and
// emissive textures, the alpha coverage of MASK materials. draw() issues one draw per material
// range.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "gpu/resources.h"
#include "scene/alpha_coverage.h"
#include "scene/scene.h"

namespace voxlab {

class GpuScene {
 public:
  explicit GpuScene(const Scene& scene);
  // Binds the vertex array and the material SSBO, then for each draw range sets the uniform
  // "u_materialIndex" (and "u_firstTriangle", the range's first triangle, where the program has
  // it), binds that material's textures and draws its triangles.
  void draw(GLuint program) const;
  // The same for the given ranges of the index buffer instead of the scene's (each a run of
  // triangles of one material, e.g. those a pass keeps out of a larger range).
  void draw(GLuint program, const std::vector<DrawRange>& ranges) const;
  // The same with a program per material kind (materialKindDefines): 'programFor' returns the
  // program for a kind's defines, its own uniforms set; the ranges are drawn in their order.
  using ProgramForKind = std::function<GLuint(const std::string& materialKindDefines)>;
  void draw(const ProgramForKind& programFor, const std::vector<DrawRange>& ranges) const;
  const Buffer& materials() const { return materials_; }
  // The alpha coverage pyramids of MASK materials (scene/alpha_coverage.h) and their GPU copies
  // (bound by draw(); compute passes bind them with bindCoverage()).
  const AlphaCoverage& coverage() const { return coverage_; }
  void bindCoverage() const;
  // Binds material 'material's base colour and emissive textures (white where it has none).
  void bindMaterialTextures(uint32_t material) const;
  // The defines of a program built for material 'material's kind (shaders/common/material.glsl):
  // which textures it has and whether it is alpha-masked. A pass that runs per draw range builds
  // one program per kind, so a material without textures or mask runs none of their code
  // (llvmpipe runs both sides of every branch); the results are those of the general program.
  std::string materialKindDefines(uint32_t material) const;
  const Buffer& vertices() const { return vertices_; }
  const Buffer& indices() const { return indices_; }
  GLuint vertexArray() const { return vao_.id(); }
  size_t triangleCount() const { return triangleCount_; }

 private:
  const Scene& scene_;
  AlphaCoverage coverage_;
  Buffer vertices_, indices_, materials_, coverageBits_, coverageLevels_;
  VertexArray vao_;
  std::vector<Texture> textures_;
  Texture white_;
  size_t triangleCount_ = 0;
};

}  // namespace voxlab
