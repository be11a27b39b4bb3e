#include "gpu/resources.h"

#include <algorithm>

#include "core/error.h"
#include "core/log.h"
#include "gpu/gl_debug.h"

namespace voxlab {

// --- Formats -------------------------------------------------------------------------------------

FormatInfo formatInfo(GLenum f) {
  switch (f) {
    case GL_R8: return {1, 1, false, false, false, GL_RED};
    case GL_RG8: return {2, 2, false, false, false, GL_RG};
    case GL_RGBA8: case GL_SRGB8_ALPHA8: return {4, 4, false, false, false, GL_RGBA};
    case GL_R16F: return {1, 2, false, true, false, GL_RED};
    case GL_RG16F: return {2, 4, false, true, false, GL_RG};
    case GL_RGBA16F: return {4, 8, false, true, false, GL_RGBA};
    case GL_R32F: return {1, 4, false, true, false, GL_RED};
    case GL_RG32F: return {2, 8, false, true, false, GL_RG};
    case GL_RGBA32F: return {4, 16, false, true, false, GL_RGBA};
    case GL_R11F_G11F_B10F: return {3, 4, false, true, false, GL_RGB};
    case GL_RGB10_A2: return {4, 4, false, false, false, GL_RGBA};
    case GL_RGBA16: return {4, 8, false, false, false, GL_RGBA};
    case GL_R32UI: return {1, 4, true, false, false, GL_RED_INTEGER};
    case GL_RG32UI: return {2, 8, true, false, false, GL_RG_INTEGER};
    case GL_RGBA32UI: return {4, 16, true, false, false, GL_RGBA_INTEGER};
    case GL_R8UI: return {1, 1, true, false, false, GL_RED_INTEGER};
    case GL_DEPTH_COMPONENT32F: return {1, 4, false, true, true, GL_DEPTH_COMPONENT};
    case GL_DEPTH_COMPONENT24: return {1, 4, false, false, true, GL_DEPTH_COMPONENT};
    default: throw Error("unsupported texture format 0x" + std::to_string(f));
  }
}

const char* formatName(GLenum f) {
  switch (f) {
    case GL_R8: return "r8";
    case GL_RG8: return "rg8";
    case GL_RGBA8: return "rgba8";
    case GL_SRGB8_ALPHA8: return "srgb8_alpha8";
    case GL_R16F: return "r16f";
    case GL_RG16F: return "rg16f";
    case GL_RGBA16F: return "rgba16f";
    case GL_R32F: return "r32f";
    case GL_RG32F: return "rg32f";
    case GL_RGBA32F: return "rgba32f";
    case GL_R11F_G11F_B10F: return "r11f_g11f_b10f";
    case GL_RGB10_A2: return "rgb10_a2";
    case GL_RGBA16: return "rgba16";
    case GL_R32UI: return "r32ui";
    case GL_RG32UI: return "rg32ui";
    case GL_RGBA32UI: return "rgba32ui";
    case GL_R8UI: return "r8ui";
    case GL_DEPTH_COMPONENT32F: return "depth32f";
    case GL_DEPTH_COMPONENT24: return "depth24";
    default: return "unknown";
  }
}

// --- Texture -------------------------------------------------------------------------------------

static int fullMipCount(glm::ivec3 s) {
  int m = std::max(s.x, std::max(s.y, s.z)), n = 1;
  while (m > 1) { m >>= 1; ++n; }
  return n;
}

Texture::Texture(const std::string& label, const TextureDesc& desc) : desc_(desc), label_(label) {
  GLDebugScope scope("texture '" + label + "'");
  if (desc_.levels <= 0) desc_.levels = fullMipCount(desc_.size);
  GLuint id = 0;
  glCreateTextures(desc_.target, 1, &id);
  handle_ = GLHandle<TextureDeleter>(id);
  if (desc_.target == GL_TEXTURE_3D)
    glTextureStorage3D(id, desc_.levels, desc_.format, desc_.size.x, desc_.size.y, desc_.size.z);
  else
    glTextureStorage2D(id, desc_.levels, desc_.format, desc_.size.x, desc_.size.y);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, desc_.minFilter);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, desc_.magFilter);
  glTextureParameteri(id, GL_TEXTURE_WRAP_S, desc_.wrap);
  glTextureParameteri(id, GL_TEXTURE_WRAP_T, desc_.wrap);
  glTextureParameteri(id, GL_TEXTURE_WRAP_R, desc_.wrap);
  glTextureParameteri(id, GL_TEXTURE_MAX_LEVEL, desc_.levels - 1);
  glObjectLabel(GL_TEXTURE, id, -1, label.c_str());
}

glm::ivec3 Texture::levelSize(int level) const {
  glm::ivec3 s = desc_.size;
  for (int i = 0; i < level; ++i) s = glm::max(s / 2, glm::ivec3(1));
  if (!is3D()) s.z = 1;
  return s;
}

size_t textureBytes(const TextureDesc& d) {
  glm::ivec3 s = glm::max(d.size, glm::ivec3(1));
  if (d.target != GL_TEXTURE_3D) s.z = 1;
  int maxDim = std::max(s.x, std::max(s.y, s.z)), fullLevels = 1;
  while (maxDim > 1) { maxDim >>= 1; ++fullLevels; }
  const int levels = d.levels <= 0 ? fullLevels : std::min(d.levels, fullLevels);
  const size_t bpt = size_t(formatInfo(d.format).bytesPerTexel);
  size_t total = 0;
  for (int l = 0; l < levels; ++l) {
    total += size_t(s.x) * size_t(s.y) * size_t(s.z) * bpt;
    s = glm::max(s / 2, glm::ivec3(1));
    if (d.target != GL_TEXTURE_3D) s.z = 1;
  }
  return total;
}

size_t Texture::byteSize() const { return textureBytes(desc_); }

bool Texture::matches(const TextureDesc& d) const {
  int levels = d.levels <= 0 ? fullMipCount(d.size) : d.levels;
  return handle_ && d.target == desc_.target && d.format == desc_.format && d.size == desc_.size &&
         levels == desc_.levels && d.minFilter == desc_.minFilter && d.magFilter == desc_.magFilter &&
         d.wrap == desc_.wrap;
}

// --- Buffer --------------------------------------------------------------------------------------

Buffer::Buffer(const std::string& label, size_t bytes, const void* data, GLbitfield flags)
    : size_(bytes), label_(label) {
  GLDebugScope scope("buffer '" + label + "'");
  GLuint id = 0;
  glCreateBuffers(1, &id);
  handle_ = GLHandle<BufferDeleter>(id);
  glNamedBufferStorage(id, std::max<size_t>(bytes, 4), data, flags);
  glObjectLabel(GL_BUFFER, id, -1, label.c_str());
}

void Buffer::upload(const void* data, size_t bytes, size_t offset) {
  GLDebugScope scope("buffer '" + label_ + "' upload");
  glNamedBufferSubData(id(), offset, bytes, data);
}

std::vector<uint8_t> Buffer::download(size_t bytes, size_t offset) const {
  bytes = std::min(bytes, size_ - std::min(offset, size_));
  std::vector<uint8_t> out(bytes);
  if (bytes) {
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(id(), offset, bytes, out.data());
  }
  return out;
}

// --- Framebuffer / vertex array --------------------------------------------------------------------

Framebuffer::Framebuffer(const std::string& label) : label_(label) {
  GLuint id = 0;
  glCreateFramebuffers(1, &id);
  handle_ = GLHandle<FramebufferDeleter>(id);
  glObjectLabel(GL_FRAMEBUFFER, id, -1, label.c_str());
}

void Framebuffer::attach(GLenum attachment, const Texture& texture, int level) {
  GLDebugScope scope("framebuffer '" + label_ + "' attach '" + texture.label() + "'");
  glNamedFramebufferTexture(id(), attachment, texture.id(), level);
}

void Framebuffer::setDrawBuffers(int colorCount) {
  std::vector<GLenum> bufs;
  for (int i = 0; i < colorCount; ++i) bufs.push_back(GL_COLOR_ATTACHMENT0 + i);
  if (colorCount == 0)
    glNamedFramebufferDrawBuffer(id(), GL_NONE);
  else
    glNamedFramebufferDrawBuffers(id(), colorCount, bufs.data());
}

void Framebuffer::checkComplete() const {
  GLenum status = glCheckNamedFramebufferStatus(id(), GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw Error("framebuffer '" + label_ + "' is incomplete (status 0x" + std::to_string(status) + ")");
}

VertexArray::VertexArray(const std::string& label) {
  GLuint id = 0;
  glCreateVertexArrays(1, &id);
  handle_ = GLHandle<VertexArrayDeleter>(id);
  glObjectLabel(GL_VERTEX_ARRAY, id, -1, label.c_str());
}

// --- Timer ---------------------------------------------------------------------------------------

GpuTimer::GpuTimer(const std::string& label) {
  GLuint ids[2] = {0, 0};
  glCreateQueries(GL_TIMESTAMP, 2, ids);
  start_ = GLHandle<QueryDeleter>(ids[0]);
  stop_ = GLHandle<QueryDeleter>(ids[1]);
  glObjectLabel(GL_QUERY, ids[0], -1, (label + ".start").c_str());
  glObjectLabel(GL_QUERY, ids[1], -1, (label + ".stop").c_str());
}

void GpuTimer::begin() { glQueryCounter(start_.id(), GL_TIMESTAMP); }

void GpuTimer::end() {
  glQueryCounter(stop_.id(), GL_TIMESTAMP);
  pending_ = true;
}

double GpuTimer::milliseconds() {
  if (pending_) {
    GLuint64 t0 = 0, t1 = 0;
    glGetQueryObjectui64v(start_.id(), GL_QUERY_RESULT, &t0);
    glGetQueryObjectui64v(stop_.id(), GL_QUERY_RESULT, &t1);
    last_ = t1 > t0 ? double(t1 - t0) * 1e-6 : 0.0;
    pending_ = false;
  }
  return last_;
}

}  // namespace voxlab
