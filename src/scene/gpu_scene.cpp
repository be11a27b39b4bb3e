#include "scene/gpu_scene.h"

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "scene/animation.h"

namespace voxlab {

namespace {
struct Vertex {
  glm::vec3 position;
  glm::vec3 normal;
  glm::vec2 uv;
};
}  // namespace

GpuScene::GpuScene(const Scene& scene) : scene_(scene) {
  std::vector<Vertex> verts(scene.positions.size());
  for (size_t i = 0; i < verts.size(); ++i)
    verts[i] = {scene.positions[i], scene.normals[i], i < scene.uvs.size() ? scene.uvs[i] : glm::vec2(0)};
  vertices_ = Buffer("scene.vertices", verts.size() * sizeof(Vertex), verts.data(), 0);
  indices_ = Buffer("scene.indices", scene.indices.size() * 4, scene.indices.data(), 0);
  triangleCount_ = scene.triangleCount();

  coverage_ = AlphaCoverage::build(scene);
  std::vector<gpu::GpuMaterial> mats;
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    const bool masked = coverage_.masked(uint32_t(i));
    mats.push_back({m.baseColor, glm::vec4(m.emissive, m.emissiveTexture >= 0 ? 1.0f : 0.0f),
                    glm::vec4(m.alphaCutoff, masked ? 1.0f : 0.0f, float(coverage_.firstLevel[i]),
                              float(coverage_.levelCount[i]))});
  }
  coverageBits_ = Buffer("scene.coverage-bits", coverage_.bits.size() * 4, coverage_.bits.data(), 0);
  std::vector<glm::uvec4> levels;
  for (const CoverageLevel& L : coverage_.levels) levels.push_back({L.bitOffset, L.width, L.height, 0u});
  coverageLevels_ = Buffer("scene.coverage-levels", levels.size() * sizeof(glm::uvec4), levels.data(), 0);
  materials_ = Buffer("scene.materials", mats.size() * sizeof(gpu::GpuMaterial), mats.data(), 0);

  GLuint vao = vao_.id();
  glVertexArrayVertexBuffer(vao, 0, vertices_.id(), 0, sizeof(Vertex));
  glVertexArrayElementBuffer(vao, indices_.id());
  glEnableVertexArrayAttrib(vao, VOXLAB_ATTR_POSITION);
  glEnableVertexArrayAttrib(vao, VOXLAB_ATTR_NORMAL);
  glEnableVertexArrayAttrib(vao, VOXLAB_ATTR_UV);
  glVertexArrayAttribFormat(vao, VOXLAB_ATTR_POSITION, 3, GL_FLOAT, GL_FALSE, offsetof(Vertex, position));
  glVertexArrayAttribFormat(vao, VOXLAB_ATTR_NORMAL, 3, GL_FLOAT, GL_FALSE, offsetof(Vertex, normal));
  glVertexArrayAttribFormat(vao, VOXLAB_ATTR_UV, 2, GL_FLOAT, GL_FALSE, offsetof(Vertex, uv));
  glVertexArrayAttribBinding(vao, VOXLAB_ATTR_POSITION, 0);
  glVertexArrayAttribBinding(vao, VOXLAB_ATTR_NORMAL, 0);
  glVertexArrayAttribBinding(vao, VOXLAB_ATTR_UV, 0);
  glObjectLabel(GL_VERTEX_ARRAY, vao, -1, "scene.vao");

  for (const auto& img : scene.textures) {
    TextureDesc d;
    d.format = GL_SRGB8_ALPHA8;
    d.size = {img.width, img.height, 1};
    d.levels = 0;
    d.minFilter = GL_LINEAR_MIPMAP_LINEAR;
    d.wrap = GL_REPEAT;
    textures_.emplace_back("scene.texture." + img.name, d);
    glTextureSubImage2D(textures_.back().id(), 0, 0, 0, img.width, img.height, GL_RGBA,
                        GL_UNSIGNED_BYTE, img.rgba8.data());
    glGenerateTextureMipmap(textures_.back().id());
  }
  TextureDesc w;
  w.size = {1, 1, 1};
  white_ = Texture("scene.texture.white", w);
  const uint8_t one[4] = {255, 255, 255, 255};
  glTextureSubImage2D(white_.id(), 0, 0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, one);
}

void GpuScene::bindCoverage() const {
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_COVERAGE_BITS, coverageBits_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_COVERAGE_LEVELS, coverageLevels_.id());
}

void GpuScene::bindMaterialTextures(uint32_t material) const {
  const Material& m = scene_.materials[material];
  glBindTextureUnit(VOXLAB_UNIT_ALBEDO, m.baseColorTexture >= 0 ? textures_[m.baseColorTexture].id() : white_.id());
  glBindTextureUnit(VOXLAB_UNIT_EMISSIVE, m.emissiveTexture >= 0 ? textures_[m.emissiveTexture].id() : white_.id());
}

std::string GpuScene::materialKindDefines(uint32_t material) const {
  const Material& m = scene_.materials[material];
  std::string defines = "#define VOXLAB_MATERIAL_KIND 1\n";
  if (m.baseColorTexture >= 0) defines += "#define VOXLAB_MATERIAL_ALBEDO_TEXTURE 1\n";
  if (m.emissiveTexture >= 0) defines += "#define VOXLAB_MATERIAL_EMISSIVE_TEXTURE 1\n";
  if (coverage_.masked(material)) defines += "#define VOXLAB_MATERIAL_ALPHA_MASK 1\n";
  return defines;
}

void GpuScene::draw(GLuint program) const { draw(program, scene_.draws); }

void GpuScene::draw(GLuint program, const std::vector<DrawRange>& ranges) const {
  draw([program](const std::string&) { return program; }, ranges);
}

void GpuScene::draw(const ProgramForKind& programFor, const std::vector<DrawRange>& ranges) const {
  glBindVertexArray(vao_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_MATERIALS, materials_.id());
  bindCoverage();
  GLuint program = 0;
  GLint loc = -1, firstLoc = -1;
  std::string kind;
  for (const auto& d : ranges) {
    const std::string rangeKind = materialKindDefines(d.material);
    if (program == 0 || rangeKind != kind) {
      kind = rangeKind;
      program = programFor(kind);
      glUseProgram(program);
      loc = glGetUniformLocation(program, "u_materialIndex");
      firstLoc = glGetUniformLocation(program, "u_firstTriangle");  // optional: -1 when unused
    }
    glProgramUniform1i(program, loc, int(d.material));
    if (firstLoc >= 0) glProgramUniform1i(program, firstLoc, int(d.firstIndex / 3));
    bindMaterialTextures(d.material);
    glDrawElements(GL_TRIANGLES, GLsizei(d.indexCount), GL_UNSIGNED_INT,
                   reinterpret_cast<const void*>(uintptr_t(d.firstIndex) * 4));
  }
}

}  // namespace voxlab

namespace voxlab {

void uploadPosedVertices(const GpuScene& gpuScene, const Scene& scene, const SceneAnimation& animation) {
  // The vertex buffer's storage is immutable (no client updates): each moving range goes through
  // a staging buffer and a GPU copy into place.
  for (const MovingVertices& m : animation.moving) {
    if (m.count == 0) continue;
    std::vector<Vertex> verts(m.count);
    for (uint32_t i = 0; i < m.count; ++i) {
      const size_t v = m.first + i;
      verts[i] = {scene.positions[v], scene.normals[v], v < scene.uvs.size() ? scene.uvs[v] : glm::vec2(0)};
    }
    Buffer staging("scene.posed-vertices", verts.size() * sizeof(Vertex), verts.data(), 0);
    glCopyNamedBufferSubData(staging.id(), gpuScene.vertices().id(), 0, GLintptr(m.first * sizeof(Vertex)),
                             GLsizeiptr(verts.size() * sizeof(Vertex)));
  }
}

}  // namespace voxlab
