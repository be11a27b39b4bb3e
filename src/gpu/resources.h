// RAII wrappers over GL 4.5 direct-state-access objects. Every object carries a label (shown by
// GL debuggers, named by GL debug messages: gpu/gl_debug.h, and used as its name on the
// blackboard) and knows its own shape, so outputs can be read back and described without
// stage-specific code.
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "gpu/gl.h"

namespace voxlab {

// Move-only owner of one GL object name.
template <typename Deleter>
class GLHandle {
 public:
  GLHandle() = default;
  explicit GLHandle(GLuint id) : id_(id) {}
  ~GLHandle() { reset(); }
  GLHandle(GLHandle&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
  GLHandle& operator=(GLHandle&& o) noexcept {
    if (this != &o) { reset(); id_ = std::exchange(o.id_, 0); }
    return *this;
  }
  GLHandle(const GLHandle&) = delete;
  GLHandle& operator=(const GLHandle&) = delete;
  GLuint id() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
  void reset() { if (id_) Deleter{}(id_); id_ = 0; }

 private:
  GLuint id_ = 0;
};

struct TextureDeleter { void operator()(GLuint id) const { glDeleteTextures(1, &id); } };
struct BufferDeleter { void operator()(GLuint id) const { glDeleteBuffers(1, &id); } };
struct FramebufferDeleter { void operator()(GLuint id) const { glDeleteFramebuffers(1, &id); } };
struct VertexArrayDeleter { void operator()(GLuint id) const { glDeleteVertexArrays(1, &id); } };
struct ProgramDeleter { void operator()(GLuint id) const { glDeleteProgram(id); } };
struct QueryDeleter { void operator()(GLuint id) const { glDeleteQueries(1, &id); } };

// A 2D or 3D texture (GL_TEXTURE_2D / GL_TEXTURE_3D) with immutable storage.
struct TextureDesc {
  GLenum target = GL_TEXTURE_2D;
  GLenum format = GL_RGBA8;  // sized internal format
  glm::ivec3 size{1, 1, 1};  // depth 1 for 2D
  int levels = 1;            // 0 = full mip chain
  GLenum minFilter = GL_LINEAR;
  GLenum magFilter = GL_LINEAR;
  GLenum wrap = GL_CLAMP_TO_EDGE;
};

// Bytes of a texture with this description, all levels (levels 0 = the full chain).
size_t textureBytes(const TextureDesc& desc);

class Texture {
 public:
  Texture() = default;
  Texture(const std::string& label, const TextureDesc& desc);
  GLuint id() const { return handle_.id(); }
  const TextureDesc& desc() const { return desc_; }
  const std::string& label() const { return label_; }
  glm::ivec3 levelSize(int level) const;
  int levels() const { return desc_.levels; }
  bool is3D() const { return desc_.target == GL_TEXTURE_3D; }
  size_t byteSize() const;  // all levels
  bool matches(const TextureDesc& d) const;

 private:
  GLHandle<TextureDeleter> handle_;
  TextureDesc desc_;
  std::string label_;
};

// Properties of a sized internal format that readback and statistics need.
struct FormatInfo {
  int channels = 4;
  int bytesPerTexel = 4;
  bool isInteger = false;  // r32ui etc.: read back as integers
  bool isFloat = false;    // r16f/r32f/rgba16f...
  bool isDepth = false;
  GLenum readFormat = GL_RGBA;  // for glGetTextureImage
};
FormatInfo formatInfo(GLenum internalFormat);
const char* formatName(GLenum internalFormat);

class Buffer {
 public:
  Buffer() = default;
  Buffer(const std::string& label, size_t bytes, const void* data = nullptr,
         GLbitfield flags = GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);
  GLuint id() const { return handle_.id(); }
  size_t size() const { return size_; }
  const std::string& label() const { return label_; }
  void upload(const void* data, size_t bytes, size_t offset = 0);
  std::vector<uint8_t> download(size_t bytes = SIZE_MAX, size_t offset = 0) const;

 private:
  GLHandle<BufferDeleter> handle_;
  size_t size_ = 0;
  std::string label_;
};

class Framebuffer {
 public:
  Framebuffer() = default;
  explicit Framebuffer(const std::string& label);
  GLuint id() const { return handle_.id(); }
  void attach(GLenum attachment, const Texture& texture, int level = 0);
  void setDrawBuffers(int colorCount);
  void checkComplete() const;  // throws Error

 private:
  GLHandle<FramebufferDeleter> handle_;
  std::string label_;
};

class VertexArray {
 public:
  VertexArray() : VertexArray("vertex-array") {}  // owners with a better name relabel it
  explicit VertexArray(const std::string& label);
  GLuint id() const { return handle_.id(); }

 private:
  GLHandle<VertexArrayDeleter> handle_;
};

// Measures one span of GPU work with two GL_TIMESTAMP queries (robust where GL_TIME_ELAPSED
// spans a synchronising readback), without stalling until the result is asked for.
class GpuTimer {
 public:
  explicit GpuTimer(const std::string& label);
  void begin();
  void end();
  double milliseconds();  // waits for the result

 private:
  GLHandle<QueryDeleter> start_, stop_;
  bool pending_ = false;
  double last_ = 0.0;
};

}  // namespace voxlab
