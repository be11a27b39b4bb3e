#include "capture/capture.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <future>
#include <memory>

#include "capture/image_files.h"
#include "capture/output_handler.h"
#include "core/error.h"
#include "gpu/resources.h"

namespace voxlab {

using nlohmann::json;

// --- Readback ------------------------------------------------------------------------------------

// The float the driver gives for each byte value of an 8-bit unorm texture, asked of the driver
// once (a texture holding the bytes 0..255, read back as floats), so that a level read back as
// bytes and mapped through it has exactly the values of a level read back as floats.
static const std::array<float, 256>& unormByteValues() {
  static const std::array<float, 256> values = [] {
    std::array<uint8_t, 256> bytes;
    for (int k = 0; k < 256; ++k) bytes[k] = uint8_t(k);
    GLuint id = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &id);
    glTextureStorage2D(id, 1, GL_RGBA8, 64, 1);
    glTextureSubImage2D(id, 0, 0, 0, 64, 1, GL_RGBA, GL_UNSIGNED_BYTE, bytes.data());
    std::array<float, 256> v;
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glGetTextureImage(id, 0, GL_RGBA, GL_FLOAT, GLsizei(sizeof v), v.data());
    glDeleteTextures(1, &id);
    return v;
  }();
  return values;
}

static LevelData readTextureLevel(const Texture& tex, int level) {
  FormatInfo fi = formatInfo(tex.desc().format);
  const GLenum internal = tex.desc().format;
  // 8-bit unorm levels (the SVO's brick pools: 22 M values) read back as bytes and mapped through
  // the driver's own byte -> float values: llvmpipe's conversion to floats took 34 ns a texel.
  if (internal == GL_R8 || internal == GL_RG8 || internal == GL_RGBA8) {
    const std::array<float, 256>& byteValue = unormByteValues();
    LevelData d;
    d.size = tex.levelSize(level);
    d.channels = fi.channels;
    const size_t n = d.texelCount() * d.channels;
    std::vector<uint8_t> bytes(n);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    glGetTextureImage(tex.id(), level, fi.readFormat, GL_UNSIGNED_BYTE, GLsizei(n), bytes.data());
    d.values.resize(n);
    for (size_t i = 0; i < n; ++i) d.values[i] = byteValue[bytes[i]];
    return d;
  }
  LevelData d;
  d.size = tex.levelSize(level);
  d.channels = fi.channels;
  size_t n = d.texelCount() * d.channels;
  d.values.resize(n);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  if (fi.isInteger) {
    std::vector<uint32_t> tmp(n);
    glGetTextureImage(tex.id(), level, fi.readFormat, GL_UNSIGNED_INT, GLsizei(n * 4), tmp.data());
    for (size_t i = 0; i < n; ++i) d.values[i] = float(tmp[i]);
    d.integers = std::move(tmp);
  } else {
    glGetTextureImage(tex.id(), level, fi.readFormat, GL_FLOAT, GLsizei(n * 4), d.values.data());
  }
  return d;
}

CapturedOutput captureOutput(Blackboard& board, const OutputDesc& desc) {
  CapturedOutput out;
  out.desc = desc;
  if (desc.kind == OutputKind::Buffer) {
    Buffer& buf = board.buffer(desc.resourceName());
    const BufferLayout& L = desc.layout;
    if (L.stride == 0) throw Error("output " + desc.name + " is a buffer without a record layout");
    uint32_t capacity = uint32_t(buf.size() / L.stride);
    uint32_t count = capacity;
    if (!L.countResource.empty()) {
      auto bytes = board.buffer(L.countResource).download(4, L.countOffset);
      std::memcpy(&count, bytes.data(), 4);
      count = std::min(count, capacity);
    }
    out.format = "records";
    out.recordCount = count;
    out.records = buf.download(size_t(count) * L.stride);
    return out;
  }
  Texture& tex = board.texture(desc.resourceName());
  out.format = formatName(tex.desc().format);
  for (int l = 0; l < tex.levels(); ++l) {
    out.levels.push_back(readTextureLevel(tex, l));
  }
  // Volumes: their placement or the voxel space; images only when a stage placed them (columns of a
  // volume, as the bitmask columns: Blackboard::placementOf gives a 2D texture no default).
  out.world = board.placementOf(desc.resourceName());
  return out;
}

// --- Statistics ----------------------------------------------------------------------------------

// Whether a texel's emptiness is its alpha alone (an RGBA volume whose alpha is opacity). Looked
// up once per level: the mapping is found by the semantic's name.
static bool emptinessIsAlpha(const CapturedOutput& out, const LevelData& d) {
  return out.desc.kind == OutputKind::Volume3D && d.channels == 4 && texelMapping(out.desc.semantic).alphaIsOpacity;
}

static bool texelNonEmpty(const float* v, int channels, bool alphaOnly) {
  if (alphaOnly) return v[3] != 0.0f;
  for (int c = 0; c < channels; ++c)
    if (v[c] != 0.0f) return true;
  return false;
}

bool texelNonEmpty(const CapturedOutput& out, const LevelData& d, size_t t) {
  return texelNonEmpty(&d.values[t * d.channels], d.channels, emptinessIsAlpha(out, d));
}

static double fieldScalar(const uint8_t* rec, const BufferField& f, int component) {
  uint32_t u;
  std::memcpy(&u, rec + f.offset + (f.type == FieldType::Vec2 || f.type == FieldType::Vec3 || f.type == FieldType::Vec4 ? 4 * component : 0), 4);
  switch (f.type) {
    case FieldType::U32: return double(u);
    case FieldType::I32: return double(int32_t(u));
    case FieldType::F32: case FieldType::Vec2: case FieldType::Vec3: case FieldType::Vec4: {
      float x;
      std::memcpy(&x, &u, 4);
      return x;
    }
    case FieldType::UnormRGBA8: return double((u >> (8 * component)) & 0xffu) / 255.0;
    case FieldType::SnormRGBA8: return std::max(-1.0, double(int8_t((u >> (8 * component)) & 0xffu)) / 127.0);
    case FieldType::Packed10_10_10: return double((u >> (10 * component)) & 0x3ffu);
  }
  return 0;
}

static int fieldComponents(FieldType t) {
  switch (t) {
    case FieldType::Vec2: return 2;
    case FieldType::Vec3: case FieldType::Packed10_10_10: return 3;
    case FieldType::Vec4: case FieldType::UnormRGBA8: case FieldType::SnormRGBA8: return 4;
    default: return 1;
  }
}

json outputStatistics(const CapturedOutput& out) { return outputHandler(out.desc).statistics(out); }

static json worldBoxJson(const CapturedOutput& out) {
  json s = json::object();
  if (out.world) s["world_box"] = {{"lo", {out.world->lo.x, out.world->lo.y, out.world->lo.z}},
                                   {"hi", {out.world->hi.x, out.world->hi.y, out.world->hi.z}}};
  return s;
}

json recordStatistics(const CapturedOutput& out) {
  json s = worldBoxJson(out);
  {
    s["count"] = out.recordCount;
    const auto& L = out.desc.layout;
    for (const auto& f : L.fields) {
      int nc = fieldComponents(f.type);
      std::vector<double> lo(nc, 1e300), hi(nc, -1e300), sum(nc, 0.0);
      for (uint32_t r = 0; r < out.recordCount; ++r)
        for (int c = 0; c < nc; ++c) {
          double v = fieldScalar(&out.records[size_t(r) * L.stride], f, c);
          lo[c] = std::min(lo[c], v); hi[c] = std::max(hi[c], v); sum[c] += v;
        }
      if (out.recordCount == 0) continue;
      json fj;
      for (int c = 0; c < nc; ++c) {
        fj["min"].push_back(lo[c]);
        fj["max"].push_back(hi[c]);
        fj["mean"].push_back(sum[c] / out.recordCount);
      }
      s["fields"][f.name] = fj;
    }
  }
  return s;
}

json levelStatistics(const CapturedOutput& out) {
  json s = worldBoxJson(out);
  for (size_t l = 0; l < out.levels.size(); ++l) {
    const LevelData& d = out.levels[l];
    std::vector<double> lo(d.channels, 1e300), hi(d.channels, -1e300), sum(d.channels, 0.0);
    size_t nonEmpty = 0, nonFinite = 0;
    const bool alphaOnly = emptinessIsAlpha(out, d);
    const int nc = d.channels;
    const float* v = d.values.data();
    for (size_t t = 0, n = d.texelCount(); t < n; ++t, v += nc) {
      for (int c = 0; c < nc; ++c) {
        if (!std::isfinite(v[c])) { ++nonFinite; continue; }
        lo[c] = std::min(lo[c], double(v[c])); hi[c] = std::max(hi[c], double(v[c])); sum[c] += v[c];
      }
      if (texelNonEmpty(v, nc, alphaOnly)) ++nonEmpty;
    }
    json lj;
    lj["level"] = l;
    lj["size"] = {d.size.x, d.size.y, d.size.z};
    lj["min"] = lo;
    lj["max"] = hi;
    std::vector<double> mean(d.channels);
    for (int c = 0; c < d.channels; ++c) mean[c] = sum[c] / std::max<size_t>(d.texelCount(), 1);
    lj["mean"] = mean;
    lj["non_empty"] = nonEmpty;
    lj["non_finite"] = nonFinite;
    s["levels"].push_back(lj);
  }
  return s;
}

// --- Display mapping -----------------------------------------------------------------------------

static uint8_t toByte(float v) { return unitToByte(v); }

DisplayImage besideImage(const DisplayImage& left, const DisplayImage& right, int gap) {
  DisplayImage out;
  out.width = left.width + gap + right.width;
  out.height = std::max(left.height, right.height);
  out.rgb.assign(size_t(out.width) * out.height * 3, 0);
  auto paste = [&](const DisplayImage& from, int x0) {
    for (int y = 0; y < from.height; ++y)
      std::copy_n(&from.rgb[size_t(y) * from.width * 3], size_t(from.width) * 3, &out.rgb[(size_t(y) * out.width + x0) * 3]);
  };
  paste(left, 0);
  paste(right, left.width + gap);
  return out;
}

DisplayImage displayImage(const CapturedOutput& out, int level) {
  const LevelData& d = out.levels.at(level);
  const TexelMapping& mapping = texelMapping(out.desc.semantic);
  float lo = 1e30f, hi = -1e30f;
  for (size_t t = 0; t < d.texelCount(); ++t) {
    float v = d.values[t * d.channels];
    if (std::isfinite(v)) { lo = std::min(lo, v); hi = std::max(hi, v); }
  }
  int slices = d.size.z, shown = std::min(slices, 64);
  int cols = int(std::ceil(std::sqrt(double(shown)))), rows = (shown + cols - 1) / cols;
  int gap = slices > 1 ? 1 : 0;
  DisplayImage img;
  img.width = cols * d.size.x + (cols - 1) * gap;
  img.height = rows * d.size.y + (rows - 1) * gap;
  img.rgb.assign(size_t(img.width) * img.height * 3, slices > 1 ? 40 : 0);
  // A texel equal to the one mapped before it takes that one's colour: volumes are mostly runs of
  // empty texels, and the mapping (a pure function of the values) costs a pow per channel.
  const size_t texelBytes = sizeof(float) * size_t(d.channels);
  const float* previous = nullptr;
  uint8_t previousRgb[3] = {0, 0, 0};
  for (int s = 0; s < shown; ++s) {
    int z = shown == slices ? s : int((long(s) * slices) / shown);
    int ox = (s % cols) * (d.size.x + gap), oy = (s / cols) * (d.size.y + gap);
    for (int y = 0; y < d.size.y; ++y)
      for (int x = 0; x < d.size.x; ++x) {
        size_t t = (size_t(z) * d.size.y + y) * d.size.x + x;
        int py = oy + (d.size.y - 1 - y);  // GL rows are bottom-up; images are top-down
        const float* texel = &d.values[t * d.channels];
        uint8_t* rgb = &img.rgb[(size_t(py) * img.width + ox + x) * 3];
        if (previous && std::memcmp(texel, previous, texelBytes) == 0) {
          std::memcpy(rgb, previousRgb, 3);
          continue;
        }
        mapping.map(texel, d.channels, 1.0f, lo, hi, rgb);
        previous = texel;
        std::memcpy(previousRgb, rgb, 3);
      }
  }
  return img;
}

DisplayImage pointView(const CapturedOutput& out, int size, std::vector<int32_t>* pick) {
  DisplayImage img;
  img.width = img.height = size;
  img.rgb.assign(size_t(size) * size * 3, 24);
  if (pick) pick->assign(size_t(size) * size, -1);
  const auto& L = out.desc.layout;
  const BufferField* pos = nullptr;
  const BufferField* col = nullptr;
  for (const auto& f : L.fields) {
    if (f.role == FieldRole::Position && !pos) pos = &f;
    if (f.role == FieldRole::Color && !col) col = &f;
  }
  if (!pos || out.recordCount == 0) return img;
  std::vector<glm::vec3> p(out.recordCount);
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (uint32_t r = 0; r < out.recordCount; ++r) {
    const uint8_t* rec = &out.records[size_t(r) * L.stride];
    p[r] = {fieldScalar(rec, *pos, 0), fieldScalar(rec, *pos, 1), fieldScalar(rec, *pos, 2)};
    lo = glm::min(lo, p[r]);
    hi = glm::max(hi, p[r]);
  }
  // A fixed three-quarter orthographic view: yaw 35 degrees, pitch 25 degrees, z-buffered splats.
  glm::vec3 c = 0.5f * (lo + hi);
  float radius = 0.5f * glm::length(hi - lo) + 1.0f;
  float cy = std::cos(0.61f), sy = std::sin(0.61f), cp = std::cos(0.436f), sp = std::sin(0.436f);
  std::vector<float> depth(size_t(size) * size, 1e30f);
  // Splats grow as records get fewer, so that forty cone samples read on a projector as well as
  // a million fragments: about a third of the spacing of that many points spread over the view.
  const int spacing = int(double(size) / (3.0 * std::sqrt(double(out.recordCount))));
  int splat = std::clamp(spacing, std::max(1, size / 256), std::max(1, size / 48));
  for (uint32_t r = 0; r < out.recordCount; ++r) {
    glm::vec3 q = p[r] - c;
    float x1 = cy * q.x + sy * q.z, z1 = -sy * q.x + cy * q.z;
    float y2 = cp * q.y - sp * z1, z2 = sp * q.y + cp * z1;
    int px = int((x1 / radius * 0.48f + 0.5f) * size), py = int((0.5f - y2 / radius * 0.48f) * size);
    uint8_t rgb[3] = {230, 230, 230};
    if (col) {
      const uint8_t* rec = &out.records[size_t(r) * L.stride];
      for (int k = 0; k < 3; ++k) rgb[k] = toByte(srgbEncode(float(fieldScalar(rec, *col, k))));
    }
    for (int dy = 0; dy < splat; ++dy)
      for (int dx = 0; dx < splat; ++dx) {
        int xx = px + dx - splat / 2, yy = py + dy - splat / 2;
        if (xx < 0 || yy < 0 || xx >= size || yy >= size) continue;
        size_t i = size_t(yy) * size + xx;
        if (z2 >= depth[i]) continue;
        depth[i] = z2;
        std::memcpy(&img.rgb[i * 3], rgb, 3);
        if (pick) (*pick)[i] = int32_t(r);
      }
  }
  return img;
}

// --- Files ---------------------------------------------------------------------------------------

std::vector<RecordPoint> recordPoints(const CapturedOutput& out) {
  std::vector<RecordPoint> pts;
  const auto& L = out.desc.layout;
  const BufferField* pos = nullptr;
  const BufferField* col = nullptr;
  const BufferField* nrm = nullptr;
  for (const auto& f : L.fields) {
    if (f.role == FieldRole::Position && !pos) pos = &f;
    if (f.role == FieldRole::Color && !col) col = &f;
    if (f.role == FieldRole::Normal && !nrm) nrm = &f;
  }
  if (!pos || L.stride == 0) return pts;
  for (uint32_t r = 0; r < out.recordCount && size_t(r + 1) * L.stride <= out.records.size(); ++r) {
    const uint8_t* rec = &out.records[size_t(r) * L.stride];
    RecordPoint p;
    for (int k = 0; k < 3; ++k) p.position[k] = float(fieldScalar(rec, *pos, k)) * L.positionScale;
    if (col)
      for (int k = 0; k < 3; ++k) p.color[k] = float(fieldScalar(rec, *col, k));
    if (nrm)
      for (int k = 0; k < 3; ++k) p.normal[k] = float(fieldScalar(rec, *nrm, k));
    pts.push_back(p);
  }
  return pts;
}

void writePng(const DisplayImage& image, const std::string& path) {
  writePngFile(path, image.width, image.height, 3, image.rgb.data());
}

// Flips each z slice's rows: GL order (row 0 at the bottom) <-> file order (row 0 at the top,
// slices stacked downwards). The mapping is its own inverse.
static std::vector<float> flipSliceRows(const std::vector<float>& in, glm::ivec3 size, int channels) {
  std::vector<float> out(in.size());
  size_t rowFloats = size_t(size.x) * channels;
  for (int z = 0; z < size.z; ++z)
    for (int y = 0; y < size.y; ++y) {
      size_t a = (size_t(z) * size.y + y) * rowFloats;
      size_t b = (size_t(z) * size.y + (size.y - 1 - y)) * rowFloats;
      std::memcpy(&out[b], &in[a], rowFloats * 4);
    }
  return out;
}

// Texture formats of at most 11 significant bits per channel, whose every value a half float keeps:
// 16-bit floats exactly, 8-bit unorm values k/255 within 2^-12 of their value, so round(255 x)
// gives the byte back (readImageFile does, by the file's voxlab:format).
static bool halfKeepsEveryValue(const std::string& format) {
  static const char* const kFormats[] = {"r8", "rg8", "rgba8", "r16f", "rg16f", "rgba16f"};
  return std::find(std::begin(kFormats), std::end(kFormats), format) != std::end(kFormats);
}

void writeLevelExr(const LevelData& d, const std::string& path, const std::string& semantic,
                   const std::string& textureFormat) {
  std::vector<ImageFileAttribute> attributes = {{"voxlab:depth", std::to_string(d.size.z), true},
                                                {"voxlab:semantic", semantic, false}};
  if (!textureFormat.empty()) attributes.push_back({"voxlab:format", textureFormat, false});
  // Half floats where that loses nothing of the texture: half the bytes to deflate (a 128^3 RGBA
  // volume level is 32 MiB as floats), which was most of a run's writing time.
  const bool half = halfKeepsEveryValue(textureFormat);
  const int width = d.size.x, height = d.size.y * d.size.z;
  // Large volume levels (the SVO's brick pools, 128^3 RGBA grids) without deflate: it was most of
  // their writing time, and they are the longest jobs of a whole run's file writing (svo on the
  // Cornell box: 0.3 to 0.4 s of CPU saved, the run folder 50 -> 70 MB). Images keep the smaller files.
  const size_t kLargeVolumeValues = size_t(4) << 20;
  const ExrCompression compression =
      d.size.z > 1 && d.values.size() >= kLargeVolumeValues ? ExrCompression::Rle : ExrCompression::Zip;
  if (!half) {
    std::vector<float> rows = flipSliceRows(d.values, d.size, d.channels);
    writeExrFile(path, width, height, d.channels, attributes, ExrPixels::Float, rows.data(), compression);
    return;
  }
  // Flipped and converted in one pass: a 128^3 RGBA level is 32 MiB as floats, 16 as halves.
  std::unique_ptr<uint16_t[]> halves(new uint16_t[d.values.size()]);  // every value is written below
  const size_t rowValues = size_t(d.size.x) * d.channels;
  for (int z = 0; z < d.size.z; ++z)
    for (int y = 0; y < d.size.y; ++y) {
      const float* from = &d.values[(size_t(z) * d.size.y + y) * rowValues];
      uint16_t* to = &halves[(size_t(z) * d.size.y + (d.size.y - 1 - y)) * rowValues];
      toHalfBits(from, to, rowValues);
    }
  writeExrFile(path, width, height, d.channels, attributes, ExrPixels::Half, halves.get(), compression);
}

LevelData readLevelExr(const std::string& path) {
  ImageFileData img = readImageFile(path);
  int depth = std::max(1, std::stoi(img.attribute("voxlab:depth", "1")));
  LevelData d;
  d.channels = img.channels;
  d.size = {img.width, img.height / depth, depth};
  if (size_t(d.size.x) * d.size.y * d.size.z * d.channels != img.pixels.size())
    throw Error("'" + path + "' is not a stack of " + std::to_string(depth) + " equal slices");
  d.values = flipSliceRows(img.pixels, d.size, d.channels);
  return d;
}

json recordJson(const CapturedOutput& out, uint32_t r) {
  json rec;
  const auto& L = out.desc.layout;
  if (r >= out.recordCount || size_t(r + 1) * L.stride > out.records.size()) return rec;
  for (const auto& f : L.fields) {
    int nc = fieldComponents(f.type);
    if (nc == 1) {
      rec[f.name] = fieldScalar(&out.records[size_t(r) * L.stride], f, 0);
    } else {
      for (int c = 0; c < nc; ++c) rec[f.name].push_back(fieldScalar(&out.records[size_t(r) * L.stride], f, c));
    }
  }
  return rec;
}

json recordsJson(const CapturedOutput& out, size_t limit) {
  json arr = json::array();
  for (uint32_t r = 0; r < std::min<size_t>(out.recordCount, limit); ++r) arr.push_back(recordJson(out, r));
  return arr;
}

json manifestEntry(const CapturedOutput& out, const json& statistics) {
  json entry;
  entry["kind"] = kindName(out.desc.kind);
  entry["semantic"] = semanticName(out.desc.semantic);
  entry["format"] = out.format;
  entry["statistics"] = statistics;
  return entry;
}

void writeRecordFiles(const CapturedOutput& out, const std::string& dir, const std::string& prefix, const json& statistics,
                      json& files) {
  auto add = [&](const std::string& name) {
    files.push_back(name);
    return dir + "/" + name;
  };
  json summary;
  summary["count"] = out.recordCount;
  summary["stride"] = out.desc.layout.stride;
  summary["statistics"] = statistics;
  summary["first_records"] = recordsJson(out, 64);
  std::ofstream(add(prefix + ".json")) << summary.dump(2) << "\n";
  std::ofstream bin(add(prefix + ".bin"), std::ios::binary);
  bin.write(reinterpret_cast<const char*>(out.records.data()), std::streamsize(out.records.size()));
}

void writeLevelFiles(const CapturedOutput& out, const std::string& dir, const std::string& prefix, json& files) {
  std::vector<std::string> bases;
  for (size_t l = 0; l < out.levels.size(); ++l) {
    bases.push_back(prefix + (out.levels.size() > 1 ? "@" + std::to_string(l) : ""));
    files.push_back(bases.back() + ".png");
    files.push_back(bases.back() + ".exr");
  }
  // The EXR files (values) on a thread of their own while this one draws the PNG views: the two
  // are independent, and a run that writes one output (--final-only) would otherwise encode them
  // one after the other on one core.
  std::future<void> values = std::async(std::launch::async, [&]() {
    for (size_t l = 0; l < out.levels.size(); ++l)
      writeLevelExr(out.levels[l], dir + "/" + bases[l] + ".exr", semanticName(out.desc.semantic), out.format);
  });
  try {
    for (size_t l = 0; l < out.levels.size(); ++l) writePng(displayImage(out, int(l)), dir + "/" + bases[l] + ".png");
  } catch (...) {
    values.wait();
    throw;
  }
  values.get();
}

json writeOutputFiles(const CapturedOutput& out, const std::string& dir, const std::string& prefix) {
  return outputHandler(out.desc).writeFiles(out, dir, prefix);
}

}  // namespace voxlab
