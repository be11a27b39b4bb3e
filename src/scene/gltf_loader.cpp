// loadScene(): glTF 2.0 (.gltf / .glb) -> voxlab::Scene, flattened into world space.
//
// Loading happens in three passes, so that every defect is reported as one line naming the file:
//  1. our own structural check of the JSON (types, version, required extensions, references in
//     range, node cycles, external files present) - tinygltf is lenient about several of these
//     and its own messages span several lines (scene/gltf_json_check.cpp);
//  2. tinygltf parses the file, decodes buffers and images;
//  3. the animations are read (samplers checked against their accessors), the node hierarchy is
//     walked and every triangle primitive is read through range-checked accessors into the
//     world-space arrays; an animated scene keeps what it needs to be posed again (animation.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/log.h"
#include "scene/animation.h"
#include "scene/gltf_json_check.h"
#include "scene/scene.h"

#include "scene/tinygltf_config.h"

namespace voxlab {
namespace {

using Json = nlohmann::json;
using gltf::oneLine;

// An accessor without a buffer view is all zeros (sparse values may replace some): nothing in the
// file backs its count, so it is bounded (2^20 elements) rather than allocated as claimed.
constexpr size_t kMaxAccessorCountWithoutData = size_t(1) << 20;
// Vertices and triangles of the flattened, world-space scene: 2^23 (8.4 M) each, at most about
// 1 GiB while loading (Sponza has 0.26 M triangles).
constexpr size_t kMaxSceneElements = size_t(1) << 23;

class Loader {
 public:
  explicit Loader(std::string path) : path_(std::move(path)) {}
  Scene load();
  SceneAnimation& animation() { return animation_; }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw gltf::sceneError(path_, what);
  }

  // Pass 1
  void readFile();
  void selectImages(const Json& root);
  // Pass 2
  void parseWithTinygltf();
  // Pass 3
  void buildScene(Scene& scene);
  void readAnimations(Scene& scene);
  void extendBoundsOverAnimation(Scene& scene);
  void addNode(Scene& scene, int nodeIndex, const glm::mat4& world);
  void addPrimitive(Scene& scene, int meshIndex, int primIndex, const glm::mat4& world, int placement);
  std::vector<float> readAccessor(int accessorIndex, int wantType, const std::string& what);
  std::vector<uint32_t> readIndices(int accessorIndex, const std::string& what);
  uint32_t materialFor(Scene& scene, int gltfMaterial);
  int textureFor(Scene& scene, int gltfTexture);
  std::string meshLabel(int meshIndex, int primIndex) const;

  std::string path_;
  std::string baseDir_;
  std::vector<unsigned char> bytes_;
  bool binary_ = false;
  std::string jsonText_;
  tinygltf::Model model_;
  detail::ImageDecodeRequest images_;

  // Triangles collected per scene material before they are sorted into draw ranges.
  std::vector<std::vector<uint32_t>> trianglesByMaterial_;
  std::vector<int> materialMap_;  // glTF material -> scene material (-1 = not yet added)
  int defaultMaterial_ = -1;
  std::vector<int> textureMap_;  // glTF image -> scene texture
  size_t skippedPrimitives_ = 0;
  std::vector<bool> animatedNodes_;  // per glTF node: a channel targets it
  SceneAnimation animation_;  // read in pass 3, handed out by load()
};

// ---------------------------------------------------------------------------------------------
// Pass 1: the file and its JSON

void Loader::readFile() {
  std::error_code ec;
  if (std::filesystem::is_directory(path_, ec)) fail("is a directory, not a glTF file");
  std::ifstream in(path_, std::ios::binary);
  if (!in) fail(std::string("cannot read file (") + std::strerror(errno) + ")");
  bytes_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (in.bad()) fail("cannot read file (I/O error)");
  if (bytes_.empty()) fail("file is empty (0 bytes), expected glTF JSON or GLB data");
  baseDir_ = std::filesystem::path(path_).parent_path().string();

  if (bytes_.size() >= 4 && std::memcmp(bytes_.data(), "glTF", 4) == 0) {
    binary_ = true;
    auto u32 = [&](size_t offset) {
      uint32_t v = 0;
      std::memcpy(&v, bytes_.data() + offset, 4);
      return v;
    };
    if (bytes_.size() < 20) fail("GLB file is truncated (" + std::to_string(bytes_.size()) + " bytes)");
    uint32_t version = u32(4);
    if (version != 2) {
      fail("GLB container version " + std::to_string(version) +
           " is not supported (glTF 1.0 is not supported; only glTF 2.x)");
    }
    uint32_t length = u32(8);
    if (length > bytes_.size()) {
      fail("GLB header says " + std::to_string(length) + " bytes but the file has " +
           std::to_string(bytes_.size()));
    }
    uint32_t chunkLength = u32(12);
    uint32_t chunkType = u32(16);
    if (chunkType != 0x4E4F534Au) fail("GLB first chunk is not JSON");
    if (uint64_t(chunkLength) + 20 > length) fail("GLB JSON chunk extends past the end of the file");
    jsonText_.assign(reinterpret_cast<const char*>(bytes_.data()) + 20, chunkLength);
  } else {
    jsonText_.assign(reinterpret_cast<const char*>(bytes_.data()), bytes_.size());
  }
}


// Decode only the images that materials use as base colour or emissive textures (the only ones
// voxlab reads); remember every image's uri for messages. Pass 1 checked the references.
void Loader::selectImages(const Json& root) {
  auto images = root.find("images");
  if (images == root.end()) return;
  images_.wanted.assign(images->size(), false);
  images_.uris.assign(images->size(), std::string());
  for (size_t i = 0; i < images->size(); ++i) {
    auto uri = (*images)[i].find("uri");
    if (uri != (*images)[i].end() && uri->get<std::string>().rfind("data:", 0) != 0) images_.uris[i] = uri->get<std::string>();
  }
  auto textures = root.find("textures");
  auto materials = root.find("materials");
  if (textures == root.end() || materials == root.end()) return;
  auto want = [&](const Json& info) {
    size_t t = info.at("index").get<size_t>();
    auto source = (*textures)[t].find("source");
    if (source != (*textures)[t].end()) images_.wanted[source->get<size_t>()] = true;
  };
  for (const Json& m : *materials) {
    if (auto e = m.find("emissiveTexture"); e != m.end()) want(*e);
    auto pbr = m.find("pbrMetallicRoughness");
    if (pbr == m.end()) continue;
    if (auto b = pbr->find("baseColorTexture"); b != pbr->end()) want(*b);
  }
}

// ---------------------------------------------------------------------------------------------
// Pass 2

void Loader::parseWithTinygltf() {
  tinygltf::TinyGLTF gltf;
  gltf.SetImageLoader(&detail::decodeImage, &images_);
  std::string err, warn;
  bool ok = false;
  if (bytes_.size() > 0xffffffffull) fail("file is larger than 4 GiB");
  if (binary_) {
    ok = gltf.LoadBinaryFromMemory(&model_, &err, &warn, bytes_.data(), unsigned(bytes_.size()), baseDir_);
  } else {
    ok = gltf.LoadASCIIFromString(&model_, &err, &warn, jsonText_.data(), unsigned(jsonText_.size()), baseDir_);
  }
  if (!ok && !images_.error.empty()) fail(images_.error);
  if (!ok || !err.empty()) {
    std::string text = oneLine(err.empty() ? warn : err);
    fail("glTF parse error: " + (text.empty() ? std::string("unknown error") : text));
  }
}

// ---------------------------------------------------------------------------------------------
// Pass 3: accessors

std::string Loader::meshLabel(int meshIndex, int primIndex) const {
  std::string s = "mesh " + std::to_string(meshIndex);
  const std::string& name = model_.meshes[size_t(meshIndex)].name;
  if (!name.empty()) s += " ('" + name + "')";
  return s + " primitive " + std::to_string(primIndex);
}

int componentSize(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

// Reads one component as float; normalized integers map to [0,1] / [-1,1].
float readComponent(const uint8_t* p, int componentType, bool normalized) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: { float v; std::memcpy(&v, p, 4); return v; }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? p[0] / 255.0f : float(p[0]);
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      int8_t v; std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v; std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0f : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v; std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v; std::memcpy(&v, p, 4);
      return normalized ? float(double(v) / 4294967295.0) : float(v);
    }
    default: return 0.0f;
  }
}

uint32_t readIndexComponent(const uint8_t* p, int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return p[0];
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t v; std::memcpy(&v, p, 2); return v; }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t v; std::memcpy(&v, p, 4); return v; }
    default: return 0;
  }
}

// A validated strided view of accessor-like data inside a buffer.
struct ByteView {
  const uint8_t* data = nullptr;
  size_t stride = 0;
};

const char* typeName(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
    default: return "unknown";
  }
}

// Checks that 'count' elements of 'elementSize' bytes at 'offset' with 'stride' fit buffer view
// 'viewIndex', and that the view fits its buffer; returns a pointer to the first element.
ByteView viewBytes(const tinygltf::Model& model, int viewIndex, size_t offset, size_t count, size_t elementSize,
                   const std::string& what, const std::function<void(const std::string&)>& fail) {
  if (viewIndex < 0 || size_t(viewIndex) >= model.bufferViews.size()) {
    fail(what + " refers to buffer view " + std::to_string(viewIndex) + " which is out of range (the file has " +
         std::to_string(model.bufferViews.size()) + ")");
  }
  const tinygltf::BufferView& view = model.bufferViews[size_t(viewIndex)];
  if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size()) {
    fail("buffer view " + std::to_string(viewIndex) + " refers to buffer " + std::to_string(view.buffer) +
         " which is out of range");
  }
  const tinygltf::Buffer& buffer = model.buffers[size_t(view.buffer)];
  if (uint64_t(view.byteOffset) + uint64_t(view.byteLength) > buffer.data.size()) {
    fail("buffer view " + std::to_string(viewIndex) + " (bytes " + std::to_string(view.byteOffset) + ".." +
         std::to_string(uint64_t(view.byteOffset) + view.byteLength) + ") is out of range of buffer " +
         std::to_string(view.buffer) + " (" + std::to_string(buffer.data.size()) + " bytes)");
  }
  size_t stride = view.byteStride ? size_t(view.byteStride) : elementSize;
  if (stride < elementSize) {
    fail(what + ": buffer view " + std::to_string(viewIndex) + " byteStride " + std::to_string(stride) +
         " is smaller than the element size " + std::to_string(elementSize));
  }
  if (count > 0) {
    // Compute in long double-free 64-bit arithmetic, guarding overflow by a division check.
    uint64_t c = count - 1;
    if (c > 0 && stride > UINT64_MAX / c) fail(what + " is out of range of its buffer view (overflow)");
    uint64_t end = uint64_t(offset) + c * stride + elementSize;
    if (end < offset || end > view.byteLength) {
      fail(what + " is out of range: it needs bytes " + std::to_string(offset) + ".." + std::to_string(end) +
           " of buffer view " + std::to_string(viewIndex) + " which has " + std::to_string(view.byteLength) +
           " bytes");
    }
  }
  return {buffer.data.data() + view.byteOffset + offset, stride};
}

std::vector<float> Loader::readAccessor(int accessorIndex, int wantType, const std::string& what) {
  auto failFn = [this](const std::string& m) { fail(m); };
  if (accessorIndex < 0 || size_t(accessorIndex) >= model_.accessors.size()) {
    fail(what + " refers to accessor " + std::to_string(accessorIndex) + " which is out of range");
  }
  const tinygltf::Accessor& acc = model_.accessors[size_t(accessorIndex)];
  std::string label = what + " (accessor " + std::to_string(accessorIndex) + ")";
  if (acc.type != wantType) {
    fail(label + " has type " + typeName(acc.type) + ", expected " + typeName(wantType));
  }
  int csize = componentSize(acc.componentType);
  if (csize == 0) fail(label + " has invalid componentType " + std::to_string(acc.componentType));
  int nc = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
  size_t count = acc.count;
  if (count > (size_t(1) << 31)) fail(label + " count " + std::to_string(count) + " is too large");
  if (acc.bufferView < 0 && count > kMaxAccessorCountWithoutData)
    fail(label + " count " + std::to_string(count) + " has no buffer view; at most " +
         std::to_string(kMaxAccessorCountWithoutData) + " elements may be implied zeros");
  size_t elementSize = size_t(csize) * size_t(nc);
  // The buffer view is checked before the output is allocated: a count the data cannot back must
  // not allocate (fuzzing: an accessor claiming 2e9 elements of a 12-byte view).
  ByteView v{};
  if (acc.bufferView >= 0) v = viewBytes(model_, acc.bufferView, acc.byteOffset, count, elementSize, label, failFn);
  std::vector<float> out(count * size_t(nc), 0.0f);
  if (acc.bufferView >= 0) {
    for (size_t i = 0; i < count; ++i) {
      const uint8_t* e = v.data + i * v.stride;
      for (int c = 0; c < nc; ++c) out[i * nc + c] = readComponent(e + c * csize, acc.componentType, acc.normalized);
    }
  }
  if (acc.sparse.isSparse) {
    size_t n = size_t(std::max(acc.sparse.count, 0));
    int icsize = componentSize(acc.sparse.indices.componentType);
    if (icsize == 0 || acc.sparse.indices.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
        acc.sparse.indices.componentType == TINYGLTF_COMPONENT_TYPE_SHORT ||
        acc.sparse.indices.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT) {
      fail(label + " has sparse indices of invalid componentType");
    }
    ByteView iv = viewBytes(model_, acc.sparse.indices.bufferView, size_t(acc.sparse.indices.byteOffset), n,
                            size_t(icsize), label + " sparse indices", failFn);
    ByteView vv = viewBytes(model_, acc.sparse.values.bufferView, size_t(acc.sparse.values.byteOffset), n,
                            elementSize, label + " sparse values", failFn);
    iv.stride = size_t(icsize);
    vv.stride = elementSize;
    for (size_t k = 0; k < n; ++k) {
      uint32_t target = readIndexComponent(iv.data + k * iv.stride, acc.sparse.indices.componentType);
      if (target >= count) fail(label + " sparse index " + std::to_string(target) + " is out of range");
      for (int c = 0; c < nc; ++c) {
        out[target * nc + c] = readComponent(vv.data + k * vv.stride + c * csize, acc.componentType, acc.normalized);
      }
    }
  }
  return out;
}

std::vector<uint32_t> Loader::readIndices(int accessorIndex, const std::string& what) {
  auto failFn = [this](const std::string& m) { fail(m); };
  if (accessorIndex < 0 || size_t(accessorIndex) >= model_.accessors.size()) {
    fail(what + " refers to accessor " + std::to_string(accessorIndex) + " which is out of range");
  }
  const tinygltf::Accessor& acc = model_.accessors[size_t(accessorIndex)];
  std::string label = what + " (accessor " + std::to_string(accessorIndex) + ")";
  if (acc.type != TINYGLTF_TYPE_SCALAR) fail(label + " must be SCALAR");
  int ct = acc.componentType;
  if (ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
    fail(label + " has componentType " + std::to_string(ct) + "; indices must be unsigned byte, short or int");
  }
  if (acc.sparse.isSparse) {
    // Rare for indices; read through the float path would lose precision, so decode directly.
    std::vector<float> f = readAccessor(accessorIndex, TINYGLTF_TYPE_SCALAR, what);
    std::vector<uint32_t> out(f.size());
    for (size_t i = 0; i < f.size(); ++i) out[i] = uint32_t(f[i]);
    return out;
  }
  size_t count = acc.count;
  if (count > (size_t(1) << 31)) fail(label + " count " + std::to_string(count) + " is too large");
  if (acc.bufferView < 0) {
    if (count > kMaxAccessorCountWithoutData)
      fail(label + " count " + std::to_string(count) + " has no buffer view; at most " +
           std::to_string(kMaxAccessorCountWithoutData) + " elements may be implied zeros");
    return std::vector<uint32_t>(count, 0);
  }
  int csize = componentSize(ct);
  ByteView v = viewBytes(model_, acc.bufferView, acc.byteOffset, count, size_t(csize), label, failFn);
  std::vector<uint32_t> out(count, 0);  // after the range check: the view backs 'count' elements
  for (size_t i = 0; i < count; ++i) out[i] = readIndexComponent(v.data + i * v.stride, ct);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Pass 3: materials and textures

int Loader::textureFor(Scene& scene, int gltfTexture) {
  if (gltfTexture < 0 || size_t(gltfTexture) >= model_.textures.size()) return -1;
  int source = model_.textures[size_t(gltfTexture)].source;
  if (source < 0 || size_t(source) >= model_.images.size()) return -1;
  if (textureMap_.empty()) textureMap_.assign(model_.images.size(), -2);
  if (textureMap_[size_t(source)] != -2) return textureMap_[size_t(source)];
  const tinygltf::Image& img = model_.images[size_t(source)];
  std::string label = "image " + std::to_string(source) + (img.uri.empty() || img.uri.rfind("data:", 0) == 0
                                                               ? std::string()
                                                               : " ('" + img.uri + "')");
  if (img.image.empty() || img.width <= 0 || img.height <= 0) {
    fail(label + " could not be read (the file is unreadable or empty); textures must be PNG, JPEG, TGA, BMP, PSD, "
                 "GIF, HDR, PIC or PNM files");
  }
  int comp = img.component;
  int bytesPerChannel = img.bits == 16 ? 2 : img.bits == 8 ? 1 : 0;
  if (comp < 1 || comp > 4 || bytesPerChannel == 0) {
    fail(label + " has an unsupported pixel format (" + std::to_string(comp) + " channels, " +
         std::to_string(img.bits) + " bits)");
  }
  size_t pixels = size_t(img.width) * size_t(img.height);
  if (img.image.size() < pixels * size_t(comp) * size_t(bytesPerChannel)) fail(label + " pixel data is truncated");
  TextureImage tex;
  tex.name = img.name.empty() ? img.uri.substr(0, img.uri.rfind("data:", 0) == 0 ? 0 : img.uri.size()) : img.name;
  tex.width = img.width;
  tex.height = img.height;
  tex.rgba8.resize(pixels * 4);
  for (size_t i = 0; i < pixels; ++i) {
    uint8_t ch[4] = {0, 0, 0, 255};
    for (int c = 0; c < comp; ++c) {
      size_t at = (i * size_t(comp) + size_t(c)) * size_t(bytesPerChannel);
      // 16-bit: take the high byte (little-endian as decoded by stb).
      ch[c] = bytesPerChannel == 2 ? img.image[at + 1] : img.image[at];
    }
    uint8_t* dst = &tex.rgba8[i * 4];
    if (comp == 1) { dst[0] = dst[1] = dst[2] = ch[0]; dst[3] = 255; }
    else if (comp == 2) { dst[0] = dst[1] = dst[2] = ch[0]; dst[3] = ch[1]; }
    else { dst[0] = ch[0]; dst[1] = ch[1]; dst[2] = ch[2]; dst[3] = comp == 4 ? ch[3] : 255; }
  }
  scene.textures.push_back(std::move(tex));
  textureMap_[size_t(source)] = int(scene.textures.size() - 1);
  return textureMap_[size_t(source)];
}

uint32_t Loader::materialFor(Scene& scene, int gltfMaterial) {
  if (gltfMaterial < 0) {
    if (defaultMaterial_ < 0) {
      Material m;
      m.name = "default";
      scene.materials.push_back(m);
      trianglesByMaterial_.emplace_back();
      defaultMaterial_ = int(scene.materials.size() - 1);
    }
    return uint32_t(defaultMaterial_);
  }
  if (size_t(gltfMaterial) >= model_.materials.size()) {
    fail("material " + std::to_string(gltfMaterial) + " is out of range (the file has " +
         std::to_string(model_.materials.size()) + ")");
  }
  if (materialMap_.empty()) materialMap_.assign(model_.materials.size(), -1);
  if (materialMap_[size_t(gltfMaterial)] >= 0) return uint32_t(materialMap_[size_t(gltfMaterial)]);
  const tinygltf::Material& src = model_.materials[size_t(gltfMaterial)];
  Material m;
  m.name = src.name.empty() ? "material-" + std::to_string(gltfMaterial) : src.name;
  const auto& bc = src.pbrMetallicRoughness.baseColorFactor;
  if (bc.size() == 4) m.baseColor = glm::vec4(float(bc[0]), float(bc[1]), float(bc[2]), float(bc[3]));
  m.baseColorTexture = textureFor(scene, src.pbrMetallicRoughness.baseColorTexture.index);
  if (src.emissiveFactor.size() == 3) {
    m.emissive = glm::vec3(float(src.emissiveFactor[0]), float(src.emissiveFactor[1]), float(src.emissiveFactor[2]));
  }
  auto strength = src.extensions.find("KHR_materials_emissive_strength");
  if (strength != src.extensions.end() && strength->second.IsObject()) {
    const tinygltf::Value& s = strength->second.Get("emissiveStrength");
    if (s.IsNumber()) m.emissive *= float(s.GetNumberAsDouble());
  }
  m.emissiveTexture = textureFor(scene, src.emissiveTexture.index);
  m.alphaMode = src.alphaMode == "MASK" ? AlphaMode::Mask : src.alphaMode == "BLEND" ? AlphaMode::Blend : AlphaMode::Opaque;
  m.alphaCutoff = float(src.alphaCutoff);
  m.doubleSided = src.doubleSided;
  scene.materials.push_back(m);
  trianglesByMaterial_.emplace_back();
  materialMap_[size_t(gltfMaterial)] = int(scene.materials.size() - 1);
  return uint32_t(scene.materials.size() - 1);
}

// ---------------------------------------------------------------------------------------------
// Pass 3: geometry

glm::mat4 localMatrix(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    glm::mat4 m;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m[c][r] = float(node.matrix[size_t(c * 4 + r)]);
    return m;
  }
  glm::mat4 t(1.0f), r(1.0f), s(1.0f);
  if (node.translation.size() == 3) {
    t = glm::translate(glm::mat4(1.0f), glm::vec3(float(node.translation[0]), float(node.translation[1]),
                                                  float(node.translation[2])));
  }
  if (node.rotation.size() == 4) {
    glm::quat q(float(node.rotation[3]), float(node.rotation[0]), float(node.rotation[1]), float(node.rotation[2]));
    float len = glm::length(q);
    if (len > 0.0f) r = glm::mat4_cast(q / len);
  }
  if (node.scale.size() == 3) {
    s = glm::scale(glm::mat4(1.0f), glm::vec3(float(node.scale[0]), float(node.scale[1]), float(node.scale[2])));
  }
  return t * r * s;
}

void Loader::addPrimitive(Scene& scene, int meshIndex, int primIndex, const glm::mat4& world, int placement) {
  const tinygltf::Primitive& prim = model_.meshes[size_t(meshIndex)].primitives[size_t(primIndex)];
  std::string label = meshLabel(meshIndex, primIndex);
  int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
  if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
    ++skippedPrimitives_;  // points and lines carry no surface
    return;
  }
  auto posIt = prim.attributes.find("POSITION");
  if (posIt == prim.attributes.end()) {
    ++skippedPrimitives_;
    return;
  }
  std::vector<float> pos = readAccessor(posIt->second, TINYGLTF_TYPE_VEC3, label + " POSITION");
  size_t vertexCount = pos.size() / 3;
  for (size_t v = 0; v < vertexCount; ++v) {
    for (int c = 0; c < 3; ++c) {
      float x = pos[v * 3 + size_t(c)];
      if (std::isnan(x)) fail(label + ": vertex " + std::to_string(v) + " has a NaN position");
      if (std::isinf(x)) fail(label + ": vertex " + std::to_string(v) + " has an infinite (Inf) position");
    }
  }

  // Index list (or implicit 0..n-1), validated against the vertex count.
  std::vector<uint32_t> idx;
  if (prim.indices >= 0) {
    idx = readIndices(prim.indices, label + " indices");
    for (size_t i = 0; i < idx.size(); ++i) {
      if (idx[i] >= vertexCount) {
        fail(label + ": index " + std::to_string(idx[i]) + " (entry " + std::to_string(i) +
             ") is out of range of its " + std::to_string(vertexCount) + " vertices");
      }
    }
  } else {
    idx.resize(vertexCount);
    for (size_t i = 0; i < vertexCount; ++i) idx[i] = uint32_t(i);
  }
  // Convert to a triangle list.
  std::vector<uint32_t> tris;
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    tris.assign(idx.begin(), idx.begin() + long(idx.size() / 3 * 3));
  } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
    for (size_t i = 2; i < idx.size(); ++i) {
      if (i % 2 == 0) tris.insert(tris.end(), {idx[i - 2], idx[i - 1], idx[i]});
      else tris.insert(tris.end(), {idx[i - 1], idx[i - 2], idx[i]});
    }
  } else {
    for (size_t i = 2; i < idx.size(); ++i) tris.insert(tris.end(), {idx[i - 1], idx[i], idx[0]});
  }
  if (tris.empty()) return;

  std::vector<float> nrm, uv;
  auto nIt = prim.attributes.find("NORMAL");
  if (nIt != prim.attributes.end()) {
    nrm = readAccessor(nIt->second, TINYGLTF_TYPE_VEC3, label + " NORMAL");
    if (nrm.size() != pos.size()) fail(label + ": NORMAL count differs from POSITION count");
  }
  auto tIt = prim.attributes.find("TEXCOORD_0");
  if (tIt != prim.attributes.end()) {
    uv = readAccessor(tIt->second, TINYGLTF_TYPE_VEC2, label + " TEXCOORD_0");
    if (uv.size() / 2 != vertexCount) fail(label + ": TEXCOORD_0 count differs from POSITION count");
  }

  glm::mat3 linear(world);
  float det = glm::determinant(linear);
  bool flip = det < 0.0f;
  bool invertible = std::abs(det) > 1e-20f;
  glm::mat3 normalMatrix = invertible ? glm::transpose(glm::inverse(linear)) : glm::mat3(1.0f);

  const uint32_t base = uint32_t(scene.positions.size());
  // Bounded output: node instancing (and node graphs that are not trees) repeat a primitive's
  // data, so the flattened scene is capped rather than the file trusted (found by reasoning about
  // the fuzzer's limits: a 2^20-element accessor instanced by many nodes).
  size_t trianglesSoFar = 0;
  for (const auto& t : trianglesByMaterial_) trianglesSoFar += t.size() / 3;
  if (scene.positions.size() + vertexCount > kMaxSceneElements || trianglesSoFar + tris.size() / 3 > kMaxSceneElements)
    fail(label + ": the flattened scene would have more than " + std::to_string(kMaxSceneElements) +
         " vertices or triangles (nodes instance its meshes); at most that many are loaded");
  for (size_t v = 0; v < vertexCount; ++v) {
    glm::vec3 p(pos[v * 3], pos[v * 3 + 1], pos[v * 3 + 2]);
    glm::vec3 wp = glm::vec3(world * glm::vec4(p, 1.0f));
    if (!std::isfinite(wp.x) || !std::isfinite(wp.y) || !std::isfinite(wp.z)) {
      fail(label + ": vertex " + std::to_string(v) + " is not finite after the node transform (Inf/NaN)");
    }
    scene.positions.push_back(wp);
    glm::vec3 n(0.0f);
    if (!nrm.empty() && invertible) {
      n = normalMatrix * glm::vec3(nrm[v * 3], nrm[v * 3 + 1], nrm[v * 3 + 2]);
      float len = glm::length(n);
      n = (std::isfinite(len) && len > 1e-20f) ? n / len : glm::vec3(0.0f);
    }
    scene.normals.push_back(n);
    scene.uvs.push_back(uv.empty() ? glm::vec2(0.0f) : glm::vec2(uv[v * 2], uv[v * 2 + 1]));
  }
  if (flip) {
    for (size_t t = 0; t + 2 < tris.size(); t += 3) std::swap(tris[t + 1], tris[t + 2]);
  }
  // Area-weighted normals where the file has none (or the given ones were unusable).
  bool computeAll = nrm.empty() || !invertible;
  std::vector<glm::vec3> accum(vertexCount, glm::vec3(0.0f));
  {
    for (size_t t = 0; t + 2 < tris.size(); t += 3) {
      const glm::vec3& a = scene.positions[base + tris[t]];
      const glm::vec3& b = scene.positions[base + tris[t + 1]];
      const glm::vec3& c = scene.positions[base + tris[t + 2]];
      glm::vec3 cr = glm::cross(b - a, c - a);  // length = 2 * area: area weighting
      for (int k = 0; k < 3; ++k) accum[tris[t + size_t(k)]] += cr;
    }
  }
  for (size_t v = 0; v < vertexCount; ++v) {
    glm::vec3& n = scene.normals[base + v];
    if (computeAll || n == glm::vec3(0.0f)) {
      float len = glm::length(accum[v]);
      n = len > 1e-30f ? accum[v] / len : glm::vec3(0.0f, 1.0f, 0.0f);
    }
  }

  // A moving node's vertices are kept in its own space too, to be posed again at other times.
  if (animation_.placements[size_t(placement)].moves) {
    MovingVertices m;
    m.placement = placement;
    m.first = base;
    m.count = uint32_t(vertexCount);
    m.localPositions.resize(vertexCount);
    m.localNormals.resize(vertexCount);
    const glm::mat3 toLocalNormal = glm::transpose(linear);  // inverse of the normal matrix, up to scale
    for (size_t v = 0; v < vertexCount; ++v) {
      m.localPositions[v] = glm::vec3(pos[v * 3], pos[v * 3 + 1], pos[v * 3 + 2]);
      glm::vec3 n = invertible ? toLocalNormal * scene.normals[base + v] : scene.normals[base + v];
      const float len = glm::length(n);
      m.localNormals[v] = len > 1e-20f ? n / len : glm::vec3(0.0f, 1.0f, 0.0f);
    }
    animation_.moving.push_back(std::move(m));
  }

  uint32_t material = materialFor(scene, prim.material);
  std::vector<uint32_t>& out = trianglesByMaterial_[material];
  for (uint32_t i : tris) out.push_back(base + i);
}

void Loader::addNode(Scene& scene, int rootIndex, const glm::mat4& rootParent) {
  // Explicit stack: depth is bounded by the node count (cycles were rejected in pass 1).
  struct Item { int node; glm::mat4 parent; int parentPlacement; };
  std::vector<Item> stack{{rootIndex, rootParent, -1}};
  SceneAnimation& anim = animation_;
  size_t visits = 0;
  const size_t maxVisits = std::max<size_t>(1, model_.nodes.size()) * 64 + 1024;
  while (!stack.empty()) {
    Item item = stack.back();
    stack.pop_back();
    if (++visits > maxVisits) fail("node hierarchy is too large or not a tree (node visited too often)");
    if (item.node < 0 || size_t(item.node) >= model_.nodes.size()) {
      fail("node " + std::to_string(item.node) + " is out of range (the file has " +
           std::to_string(model_.nodes.size()) + " nodes)");
    }
    const tinygltf::Node& node = model_.nodes[size_t(item.node)];
    glm::mat4 world = item.parent * localMatrix(node);
    NodePlacement placement;
    placement.node = item.node;
    placement.parent = item.parentPlacement;
    placement.moves = (item.parentPlacement >= 0 && anim.placements[size_t(item.parentPlacement)].moves) ||
                      animatedNodes_[size_t(item.node)];
    anim.placements.push_back(placement);
    const int placementIndex = int(anim.placements.size() - 1);

    if (node.mesh >= 0) {
      if (size_t(node.mesh) >= model_.meshes.size()) fail("node " + std::to_string(item.node) + " mesh is out of range");
      const tinygltf::Mesh& mesh = model_.meshes[size_t(node.mesh)];
      for (size_t p = 0; p < mesh.primitives.size(); ++p) addPrimitive(scene, node.mesh, int(p), world, placementIndex);
    }
    glm::vec3 origin = glm::vec3(world * glm::vec4(0, 0, 0, 1));
    glm::vec3 minusZ = glm::mat3(world) * glm::vec3(0, 0, -1);
    glm::vec3 plusY = glm::mat3(world) * glm::vec3(0, 1, 0);
    if (node.camera >= 0 && size_t(node.camera) < model_.cameras.size()) {
      const tinygltf::Camera& src = model_.cameras[size_t(node.camera)];
      if (src.type == "perspective" && glm::length(minusZ) > 0.0f) {
        Camera cam;
        cam.name = src.name.empty() ? (node.name.empty() ? "camera-" + std::to_string(node.camera) : node.name) : src.name;
        cam.position = origin;
        cam.forward = glm::normalize(minusZ);
        glm::vec3 up = plusY - glm::dot(plusY, cam.forward) * cam.forward;
        cam.up = glm::length(up) > 1e-12f ? glm::normalize(up) : glm::vec3(0, 1, 0);
        if (src.perspective.yfov > 0.0) cam.yfov = float(src.perspective.yfov);
        if (src.perspective.znear > 0.0) cam.znear = float(src.perspective.znear);
        cam.zfar = src.perspective.zfar > 0.0 ? float(src.perspective.zfar) : 100.0f;
        scene.cameras.push_back(cam);
        anim.cameraPlacement.push_back(placementIndex);
      }
    }
    auto lp = node.extensions.find("KHR_lights_punctual");
    if (lp != node.extensions.end() && lp->second.IsObject()) {
      const tinygltf::Value& li = lp->second.Get("light");
      int lightIndex = li.IsInt() ? li.GetNumberAsInt() : -1;
      if (lightIndex >= 0 && size_t(lightIndex) < model_.lights.size()) {
        const tinygltf::Light& src = model_.lights[size_t(lightIndex)];
        Light l;
        l.name = src.name.empty() ? (node.name.empty() ? "light-" + std::to_string(lightIndex) : node.name) : src.name;
        l.type = src.type == "directional" ? LightType::Directional : src.type == "spot" ? LightType::Spot : LightType::Point;
        l.position = origin;
        l.direction = glm::length(minusZ) > 0.0f ? glm::normalize(minusZ) : glm::vec3(0, 0, -1);
        if (src.color.size() == 3) l.color = glm::vec3(float(src.color[0]), float(src.color[1]), float(src.color[2]));
        l.intensity = float(src.intensity);
        l.range = float(src.range);
        l.innerConeAngle = float(src.spot.innerConeAngle);
        l.outerConeAngle = float(src.spot.outerConeAngle);
        scene.lights.push_back(l);
        anim.lightPlacement.push_back(placementIndex);
      }
    }
    // Push children in reverse so they are visited in file order.
    for (size_t c = node.children.size(); c-- > 0;) stack.push_back({node.children[c], world, placementIndex});
  }
}

// ---------------------------------------------------------------------------------------------
// Pass 3: animations

void Loader::readAnimations(Scene& scene) {
  SceneAnimation& anim = animation_;
  for (const tinygltf::Node& node : model_.nodes) {
    NodeRest rest;
    if (node.matrix.size() == 16) {
      rest.hasMatrix = true;
      rest.matrix = localMatrix(node);
    }
    if (node.translation.size() == 3)
      rest.translation = glm::vec3(float(node.translation[0]), float(node.translation[1]), float(node.translation[2]));
    if (node.rotation.size() == 4) {
      glm::quat q(float(node.rotation[3]), float(node.rotation[0]), float(node.rotation[1]), float(node.rotation[2]));
      const float len = glm::length(q);
      if (len > 0.0f) rest.rotation = q / len;
    }
    if (node.scale.size() == 3) rest.scale = glm::vec3(float(node.scale[0]), float(node.scale[1]), float(node.scale[2]));
    anim.nodes.push_back(rest);
  }
  size_t weightChannels = 0;
  for (size_t a = 0; a < model_.animations.size(); ++a) {
    const tinygltf::Animation& src = model_.animations[a];
    anim.names.push_back(src.name.empty() ? "animation-" + std::to_string(a) : src.name);
    for (size_t c = 0; c < src.channels.size(); ++c) {
      const tinygltf::AnimationChannel& ch = src.channels[c];
      const std::string where = "animations[" + std::to_string(a) + "].channels[" + std::to_string(c) + "]";
      // Pass 1 checked the sampler index, the node and the path names.
      if (ch.target_path == "weights") {
        ++weightChannels;  // morph targets: voxlab has none
        continue;
      }
      if (ch.sampler < 0 || size_t(ch.sampler) >= src.samplers.size())
        fail(where + ".sampler " + std::to_string(ch.sampler) + " is out of range");
      if (ch.target_node < 0 || size_t(ch.target_node) >= model_.nodes.size())
        fail(where + " targets no node in range (node " + std::to_string(ch.target_node) + ")");
      AnimationChannel channel;
      channel.node = ch.target_node;
      channel.path = ch.target_path == "rotation" ? AnimationPath::Rotation
                     : ch.target_path == "scale"  ? AnimationPath::Scale
                                                  : AnimationPath::Translation;
      const tinygltf::AnimationSampler& ss = src.samplers[size_t(ch.sampler)];
      const std::string sw = "animations[" + std::to_string(a) + "].samplers[" + std::to_string(ch.sampler) + "]";
      AnimationSampler sampler;
      sampler.interpolation = ss.interpolation == "STEP"          ? Interpolation::Step
                              : ss.interpolation == "CUBICSPLINE" ? Interpolation::CubicSpline
                                                                  : Interpolation::Linear;
      std::vector<float> times = readAccessor(ss.input, TINYGLTF_TYPE_SCALAR, sw + " input");
      if (times.empty()) fail(sw + " input has no key times");
      for (size_t k = 0; k < times.size(); ++k) {
        if (!std::isfinite(times[k])) fail(sw + " input time " + std::to_string(k) + " is not finite");
        if (k > 0 && !(times[k] > times[k - 1]))
          fail(sw + " input times are not increasing (time " + std::to_string(k) + " = " + std::to_string(times[k]) +
               " after " + std::to_string(times[k - 1]) + ")");
      }
      const bool rotation = channel.path == AnimationPath::Rotation;
      const int outputType = rotation ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3;
      std::vector<float> values =
          readAccessor(ss.output, outputType, sw + " output (for " + animationPathName(channel.path) + ")");
      const int components = rotation ? 4 : 3;
      const size_t perKey = sampler.interpolation == Interpolation::CubicSpline ? 3 : 1;
      const size_t count = values.size() / size_t(components);
      if (count != times.size() * perKey)
        fail(sw + " output has " + std::to_string(count) + " values for " + std::to_string(times.size()) +
             " key times; " + interpolationName(sampler.interpolation) + " needs " + std::to_string(perKey) +
             " per key time (" + std::to_string(times.size() * perKey) + ")");
      for (size_t i = 0; i < count; ++i) {
        glm::vec4 v(0.0f);
        for (int k = 0; k < components; ++k) {
          v[k] = values[i * size_t(components) + size_t(k)];
          if (!std::isfinite(v[k])) fail(sw + " output value " + std::to_string(i) + " is not finite");
        }
        sampler.values.push_back(v);
      }
      sampler.times = std::move(times);
      anim.duration = std::max(anim.duration, sampler.times.back());
      channel.sampler = int(anim.samplers.size());
      anim.samplers.push_back(std::move(sampler));
      anim.channels.push_back(channel);
    }
  }
  animatedNodes_.assign(model_.nodes.size(), false);
  for (const AnimationChannel& c : anim.channels) animatedNodes_[size_t(c.node)] = true;
  if (weightChannels)
    log::warn(scene.name + ": " + std::to_string(weightChannels) +
              " animation channel(s) of morph target weights skipped (voxlab has no morph targets)");
}

// The bounds of an animated scene hold its moving vertices at every key time and at three
// points between consecutive keys (a cubic spline may overshoot its keys in between).
void Loader::extendBoundsOverAnimation(Scene& scene) {
  const SceneAnimation& anim = animation_;
  if (!anim.movesGeometry()) return;
  std::vector<float> times{0.0f};
  for (const AnimationSampler& s : anim.samplers)
    for (size_t k = 0; k < s.times.size(); ++k) {
      times.push_back(s.times[k]);
      if (k + 1 < s.times.size())
        for (int q = 1; q < 4; ++q) times.push_back(s.times[k] + (s.times[k + 1] - s.times[k]) * float(q) / 4.0f);
    }
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  // Bounded work: at most 1024 poses, and at most 2^24 vertex transforms in all.
  size_t movingVertices = 0;
  for (const MovingVertices& m : anim.moving) movingVertices += m.count;
  const size_t poses = std::clamp<size_t>((size_t(1) << 24) / std::max<size_t>(1, movingVertices), 2, 1024);
  const size_t stride = std::max<size_t>(1, (times.size() + poses - 1) / poses);
  for (size_t i = 0; i < times.size(); i += stride) {
    const float t = std::clamp(times[i], 0.0f, anim.duration);
    const std::vector<glm::mat4> world = anim.worldMatrices(t);
    for (const MovingVertices& m : anim.moving)
      for (const glm::vec3& p : m.localPositions) {
        const glm::vec3 w = glm::vec3(world[size_t(m.placement)] * glm::vec4(p, 1.0f));
        if (std::isfinite(w.x) && std::isfinite(w.y) && std::isfinite(w.z)) scene.bounds.extend(w);
      }
  }
}

void Loader::buildScene(Scene& scene) {
  std::vector<int> roots;
  int sceneIndex = model_.defaultScene >= 0 ? model_.defaultScene : (model_.scenes.empty() ? -1 : 0);
  if (sceneIndex >= 0 && size_t(sceneIndex) < model_.scenes.size()) {
    roots = model_.scenes[size_t(sceneIndex)].nodes;
    const tinygltf::Value& extras = model_.scenes[size_t(sceneIndex)].extras;
    if (extras.IsObject() && extras.Has("sky_radiance")) {
      const tinygltf::Value& sky = extras.Get("sky_radiance");
      const double value = sky.IsNumber() ? sky.GetNumberAsDouble() : -1.0;
      if (!(value >= 0.0 && value <= 1000.0))
        fail("scene extras sky_radiance must be a number in [0, 1000] W/(m^2 sr)");
      scene.skyRadiance = float(value);
    }
  } else {
    // No scenes: every node that is nobody's child is a root.
    std::vector<bool> isChild(model_.nodes.size(), false);
    for (const auto& n : model_.nodes)
      for (int c : n.children)
        if (c >= 0 && size_t(c) < isChild.size()) isChild[size_t(c)] = true;
    for (size_t i = 0; i < model_.nodes.size(); ++i)
      if (!isChild[i]) roots.push_back(int(i));
  }
  readAnimations(scene);
  for (int r : roots) addNode(scene, r, glm::mat4(1.0f));

  // Sort triangles into one contiguous draw range per material (materials in first-use order).
  for (size_t m = 0; m < trianglesByMaterial_.size(); ++m) {
    const std::vector<uint32_t>& t = trianglesByMaterial_[m];
    if (t.empty()) continue;
    DrawRange d;
    d.firstIndex = uint32_t(scene.indices.size());
    d.indexCount = uint32_t(t.size());
    d.material = uint32_t(m);
    scene.draws.push_back(d);
    scene.indices.insert(scene.indices.end(), t.begin(), t.end());
  }
  if (scene.indices.empty()) {
    std::string why = skippedPrimitives_ ? " (" + std::to_string(skippedPrimitives_) +
                                               " primitive(s) were points or lines, which are skipped)"
                                         : "";
    fail("contains no triangles" + why);
  }
  for (uint32_t i : scene.indices) scene.bounds.extend(scene.positions[i]);
  extendBoundsOverAnimation(scene);
  if (scene.materials.empty()) {
    Material m;
    m.name = "default";
    scene.materials.push_back(m);
  }
  if (scene.cameras.empty()) {
    scene.cameras.push_back(frameBounds(scene.bounds, Camera{}.yfov));
    scene.cameras.back().name = kFramingCameraName;
    animation_.cameraPlacement.push_back(-1);
    log::warn(scene.name + ": " + kFramingCameraName + "; added a camera on the +z side looking along -z at the bounds' centre, the whole scene in view (--look-from/--look-at or the viewer to change it)");
  }
  if (scene.lights.empty()) {
    scene.lights.push_back(defaultSun());
    animation_.lightPlacement.push_back(-1);
    log::warn(scene.name + ": " + kDefaultSunName + "; added a white sun from elevation 60, azimuth 30 degrees, 5 W/m^2 (set light.0.* to change it)");
  }
}

// Deepest nesting of arrays and objects in JSON text (strings skipped). tinygltf converts
// "extras" and extension values recursively, so deep nesting must be refused before it parses.
size_t jsonNestingDepth(const std::string& text) {
  size_t depth = 0, deepest = 0;
  bool inString = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (inString) {
      if (c == '\\') ++i;
      else if (c == '"') inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

constexpr size_t kMaxJsonNesting = 128;

Scene Loader::load() {
  readFile();
  if (size_t depth = jsonNestingDepth(jsonText_); depth > kMaxJsonNesting)
    fail("JSON nests " + std::to_string(depth) + " levels deep; at most " + std::to_string(kMaxJsonNesting) +
         " are accepted");
  Json root;
  try {
    root = Json::parse(jsonText_);
  } catch (const Json::parse_error& e) {
    // nlohmann's text quotes the raw bytes it last read, which may be anything: drop that part.
    std::string what = e.what();
    auto lastRead = what.find("; last read:");
    if (lastRead != std::string::npos) {
      auto expected = what.find("; expected", lastRead);
      what = what.substr(0, lastRead) + (expected == std::string::npos ? "" : what.substr(expected));
    }
    auto colon = what.find("parse error");
    fail("is not valid JSON (" + (colon == std::string::npos ? what : what.substr(colon)) + ")");
  }
  gltf::JsonChecker(path_, baseDir_).check(root);
  selectImages(root);
  parseWithTinygltf();
  Scene scene;
  scene.path = path_;
  scene.name = std::filesystem::path(path_).stem().string();
  buildScene(scene);
  for (const MovingVertices& m : animation_.moving) scene.movingVertices.push_back({m.first, m.count});
  poseScene(scene, animation_, 0.0f);
  return scene;
}

}  // namespace

Scene loadScene(const std::string& path) {
  SceneAnimation unused;
  return loadScene(path, unused);
}

Scene loadScene(const std::string& path, SceneAnimation& animation) {
  try {
    Loader loader(path);
    Scene scene = loader.load();
    animation = std::move(loader.animation());
    return scene;
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw Error(oneLine("scene '" + path + "'") + ": out of memory while loading (file too large or corrupt)");
  } catch (const std::exception& e) {
    throw Error(oneLine("scene '" + path + "': " + e.what(), 1000));
  }
}

}  // namespace voxlab
