#include "reference/path_tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <climits>
#include <cstdlib>
#include <thread>

#include "core/error.h"
#include "scene/light_model.h"

namespace voxlab::reference {

namespace {

constexpr float kPi = 3.14159265358979323846f;
constexpr int kRussianRouletteAfter = 3;  // reflections before Russian roulette may end a path
constexpr int kMaxReflections = 1024;     // hard cap (bias < 0.95^1021)
constexpr uint64_t kBlock = 1024;         // samples per block in the point estimators

// ---- Counter-based random numbers -----------------------------------------------------------
// A 64-bit avalanche finaliser (xor-shift-multiply, the SplitMix64 output function). Every random
// number is a pure function of (seed, key, sample, reflection, dimension).
inline uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

class SampleStream {
 public:
  SampleStream(uint64_t seed, uint64_t key, uint64_t sample)
      : path_(mix64(mix64(mix64(seed + 0x9e3779b97f4a7c15ULL) ^ key) + sample)) {}
  void setReflection(uint32_t r) { reflection_ = r; dim_ = 0; }
  float next() {
    uint64_t h = mix64(path_ ^ mix64((uint64_t(reflection_) << 32 | dim_++) + 0x632be59bd9b4e019ULL));
    return float(h >> 40) * (1.0f / 16777216.0f);  // 24 bits: [0, 1)
  }

 private:
  uint64_t path_;
  uint32_t reflection_ = 0;
  uint32_t dim_ = 0;
};

// ---- Small vector helpers -------------------------------------------------------------------
inline float maxAbs(const glm::vec3& p) {
  return std::max(std::abs(p.x), std::max(std::abs(p.y), std::abs(p.z)));
}
// Start point of a ray leaving a surface at p on the side of unit normal n.
inline glm::vec3 offsetRay(const glm::vec3& p, const glm::vec3& n) {
  return p + n * (2e-5f * (1.0f + maxAbs(p)));
}
inline void basis(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
  // Orthonormal frame (Frisvad-style branch on the sign of z, written out directly).
  float s = n.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (s + n.z);
  float c = n.x * n.y * a;
  t = glm::vec3(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
  b = glm::vec3(c, s + n.y * n.y * a, -n.y);
}
inline glm::vec3 cosineSample(const glm::vec3& n, float u1, float u2) {
  float r = std::sqrt(u1);
  float phi = 2.0f * kPi * u2;
  glm::vec3 t, b;
  basis(n, t, b);
  float z = std::sqrt(std::max(0.0f, 1.0f - u1));
  return glm::normalize(t * (r * std::cos(phi)) + b * (r * std::sin(phi)) + n * z);
}
inline float maxComponent(const glm::vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

float srgbToLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

struct LinearTexture {
  int width = 0, height = 0;
  std::vector<glm::vec3> texels;  // linear RGB, row 0 at the top (v = 0)
  std::vector<float> alpha;       // alpha / 255, same layout
  // Bilinear alpha with REPEAT wrap (alphaMode MASK).
  float sampleAlpha(glm::vec2 uv) const {
    if (width <= 0 || height <= 0) return 1.0f;
    float x = uv.x * width - 0.5f, y = uv.y * height - 0.5f;
    float fx = std::floor(x), fy = std::floor(y);
    float ax = x - fx, ay = y - fy;
    auto wrap = [](long i, int n) { long m = i % n; return int(m < 0 ? m + n : m); };
    int x0 = wrap(long(fx), width), x1 = wrap(long(fx) + 1, width);
    int y0 = wrap(long(fy), height), y1 = wrap(long(fy) + 1, height);
    auto at = [&](int xx, int yy) { return alpha[size_t(yy) * width + xx]; };
    return (at(x0, y0) * (1 - ax) + at(x1, y0) * ax) * (1 - ay) + (at(x0, y1) * (1 - ax) + at(x1, y1) * ax) * ay;
  }
  glm::vec3 sample(glm::vec2 uv) const {
    if (width <= 0 || height <= 0) return glm::vec3(1.0f);
    float x = uv.x * width - 0.5f, y = uv.y * height - 0.5f;
    float fx = std::floor(x), fy = std::floor(y);
    float ax = x - fx, ay = y - fy;
    auto wrap = [](long i, int n) { long m = i % n; return int(m < 0 ? m + n : m); };
    int x0 = wrap(long(fx), width), x1 = wrap(long(fx) + 1, width);
    int y0 = wrap(long(fy), height), y1 = wrap(long(fy) + 1, height);
    auto at = [&](int xx, int yy) { return texels[size_t(yy) * width + xx]; };
    return (at(x0, y0) * (1 - ax) + at(x1, y0) * ax) * (1 - ay) +
           (at(x0, y1) * (1 - ax) + at(x1, y1) * ax) * ay;
  }
};

struct TriangleData {
  glm::vec3 p0, e1, e2;
  glm::vec3 front{0, 1, 0};  // unit geometric normal of the emitting side
  float area = 0.0f;
  uint32_t material = 0;
  float lightPdfArea = 0.0f;  // probability density per unit area of NEE choosing a point here
};

struct Hit {
  uint32_t tri = 0;
  float t = 0.0f;
  glm::vec3 p{0.0f};
  glm::vec3 ng{0.0f};  // unit geometric normal, front side
  glm::vec3 ns{0.0f};  // unit interpolated normal, flipped to ng's side
  glm::vec2 uv{0.0f};
};

// A reflecting path vertex: normals already on the side the light leaves toward.
struct Vertex {
  glm::vec3 p, ng, ns, albedo;
};

struct Range {
  int rMin, rMax;
};
Range reflectionRange(Mode mode) {
  switch (mode.kind) {
    case Mode::Direct: return {0, 1};
    case Mode::OneBounce: return {0, 2};
    case Mode::Indirect: return {2, INT_MAX};
    case Mode::IndirectBounces: return {2, 1 + mode.bounces};
    case Mode::TwoBounce: return {0, 3};
    default: return {0, INT_MAX};
  }
}

}  // namespace

// ---- Modes ------------------------------------------------------------------------------------
std::string modeName(Mode mode) {
  switch (mode.kind) {
    case Mode::Full: return "full";
    case Mode::Direct: return "direct";
    case Mode::OneBounce: return "one-bounce";
    case Mode::TwoBounce: return "two-bounce";
    case Mode::Indirect: return "indirect";
    case Mode::IndirectBounces: return "indirect-" + std::to_string(mode.bounces);
    case Mode::AO: return "ao";
  }
  return "?";
}
std::vector<std::string> modeNames() {
  std::vector<std::string> names = {"full", "direct", "one-bounce", "two-bounce", "indirect"};
  for (int k = 1; k <= Mode::kMaxIndirectBounces; ++k) names.push_back(modeName(Mode::indirect(k)));
  names.push_back("ao");
  return names;
}
std::string modeForms() {
  return "full, direct, one-bounce, two-bounce, indirect, indirect-K (K = 1.." +
         std::to_string(Mode::kMaxIndirectBounces) + ": K indirect bounces), ao";
}
Mode parseMode(const std::string& name) {
  for (Mode m : {Mode::Full, Mode::Direct, Mode::OneBounce, Mode::TwoBounce, Mode::Indirect, Mode::AO})
    if (modeName(m) == name) return m;
  // indirect-K: K written in decimal without sign or leading zero, 1..kMaxIndirectBounces.
  for (int k = 1; k <= Mode::kMaxIndirectBounces; ++k)
    if (modeName(Mode::indirect(k)) == name) return Mode::indirect(k);
  throw Error("unknown mode '" + name + "'; valid modes: " + modeForms());
}

int defaultThreadCount() {
  if (const char* env = std::getenv("VOXLAB_THREADS"); env && *env) {
    char* end = nullptr;
    long v = std::strtol(env, &end, 10);
    if (*end == '\0' && v >= 1 && v <= 4096) return int(v);
    throw Error("VOXLAB_THREADS '" + std::string(env) + "' is not an integer in 1..4096");
  }
  unsigned n = std::thread::hardware_concurrency();
  return n ? int(n) : 1;
}

// ---- Implementation -------------------------------------------------------------------------
struct ReferenceTracer::Impl {
  const Scene& scene;
  RTCDevice device = nullptr;
  RTCScene rtc = nullptr;
  std::vector<TriangleData> tris;
  std::vector<LinearTexture> textures;
  std::vector<uint32_t> emitters;    // triangle indices
  std::vector<double> emitterCdf;    // inclusive, normalised to 1
  bool hasNormals = false, hasUvs = false;
  glm::vec3 sky{0.0f};               // constant environment radiance (setSkyRadiance)

  explicit Impl(const Scene& s) : scene(s) {
    size_t nv = s.positions.size(), nt = s.triangleCount();
    hasNormals = s.normals.size() == nv;
    hasUvs = s.uvs.size() == nv;
    if (s.materials.empty()) throw Error("scene '" + s.name + "' has no materials");
    for (uint32_t i : s.indices)
      if (i >= nv) throw Error("scene '" + s.name + "' has a vertex index out of range");
    for (const auto& t : s.textures) {
      LinearTexture lt;
      lt.width = t.width;
      lt.height = t.height;
      if (t.rgba8.size() >= size_t(t.width) * t.height * 4) {
        float lut[256];
        for (int i = 0; i < 256; ++i) lut[i] = srgbToLinear(i / 255.0f);
        lt.texels.resize(size_t(t.width) * t.height);
        lt.alpha.resize(lt.texels.size());
        for (size_t i = 0; i < lt.texels.size(); ++i) {
          lt.texels[i] = {lut[t.rgba8[i * 4]], lut[t.rgba8[i * 4 + 1]], lut[t.rgba8[i * 4 + 2]]};
          lt.alpha[i] = float(t.rgba8[i * 4 + 3]) / 255.0f;
        }
      } else {
        lt.width = lt.height = 0;
      }
      textures.push_back(std::move(lt));
    }

    tris.resize(nt);
    for (const auto& d : s.draws)
      for (uint32_t k = d.firstIndex / 3; k < (d.firstIndex + d.indexCount) / 3 && k < nt; ++k)
        tris[k].material = d.material < s.materials.size() ? d.material : 0;
    double totalPower = 0.0;
    std::vector<double> power;
    for (size_t k = 0; k < nt; ++k) {
      auto& t = tris[k];
      uint32_t i0 = s.indices[3 * k], i1 = s.indices[3 * k + 1], i2 = s.indices[3 * k + 2];
      t.p0 = s.positions[i0];
      t.e1 = s.positions[i1] - t.p0;
      t.e2 = s.positions[i2] - t.p0;
      glm::vec3 c = glm::cross(t.e1, t.e2);
      float len = glm::length(c);
      t.area = 0.5f * len;
      if (len > 0.0f) {
        t.front = c / len;
        if (hasNormals && glm::dot(t.front, s.normals[i0] + s.normals[i1] + s.normals[i2]) < 0.0f)
          t.front = -t.front;
      }
      const Material& m = s.materials[t.material];
      double w = double(m.emissive.x + m.emissive.y + m.emissive.z) / 3.0 * t.area;
      if (w > 0.0) {
        emitters.push_back(uint32_t(k));
        power.push_back(w);
        totalPower += w;
      }
    }
    double acc = 0.0;
    for (size_t i = 0; i < emitters.size(); ++i) {
      acc += power[i];
      emitterCdf.push_back(acc / totalPower);
      auto& t = tris[emitters[i]];
      t.lightPdfArea = float(power[i] / totalPower / t.area);
    }
    if (!emitterCdf.empty()) emitterCdf.back() = 1.0;

    device = rtcNewDevice(nullptr);
    if (!device) throw Error("cannot create an Embree device");
    rtc = rtcNewScene(device);
    rtcSetSceneBuildQuality(rtc, RTC_BUILD_QUALITY_HIGH);
    rtcSetSceneFlags(rtc, RTC_SCENE_FLAG_ROBUST);
    if (nt > 0) {
      RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
      auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
      auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nt));
      for (size_t i = 0; i < nv; ++i) {
        vb[3 * i] = s.positions[i].x;
        vb[3 * i + 1] = s.positions[i].y;
        vb[3 * i + 2] = s.positions[i].z;
      }
      std::copy(s.indices.begin(), s.indices.begin() + 3 * nt, ib);
      bool anyMasked = false;
      for (const Material& m : s.materials) anyMasked |= m.alphaMode == AlphaMode::Mask;
      if (anyMasked) {
        // alphaMode MASK: every ray (camera, bounce, shadow) passes through cut-away texels.
        rtcSetGeometryUserData(g, this);
        rtcSetGeometryIntersectFilterFunction(g, &Impl::alphaFilter);
        rtcSetGeometryOccludedFilterFunction(g, &Impl::alphaFilter);
      }
      rtcCommitGeometry(g);
      rtcAttachGeometry(rtc, g);
      rtcReleaseGeometry(g);
    }
    rtcCommitScene(rtc);
    if (rtcGetDeviceError(device) != RTC_ERROR_NONE)
      throw Error("Embree could not build the scene '" + s.name + "'");
  }
  // True where a MASK triangle has no surface: baseColor.a x texture alpha < alphaCutoff at the
  // hit's texture coordinates (b1, b2: Embree's barycentrics u, v).
  bool cutAway(uint32_t tri, float b1, float b2) const {
    const Material& m = scene.materials[tris[tri].material];
    if (m.alphaMode != AlphaMode::Mask) return false;
    float a = m.baseColor.w;
    if (m.baseColorTexture >= 0 && size_t(m.baseColorTexture) < textures.size())
      a *= textures[m.baseColorTexture].sampleAlpha(uvAt(tri, b1, b2));
    return a < m.alphaCutoff;
  }
  static void alphaFilter(const RTCFilterFunctionNArguments* args) {
    const Impl* self = static_cast<const Impl*>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
      if (args->valid[i] != -1) continue;
      unsigned prim = RTCHitN_primID(args->hit, args->N, i);
      if (self->cutAway(prim, RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i))) args->valid[i] = 0;
    }
  }

  ~Impl() {
    if (rtc) rtcReleaseScene(rtc);
    if (device) rtcReleaseDevice(device);
  }

  bool intersect(const glm::vec3& o, const glm::vec3& d, float tnear, float tfar, Hit& hit,
                 uint64_t& rays) const {
    ++rays;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh{};
    rh.ray.org_x = o.x; rh.ray.org_y = o.y; rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x; rh.ray.dir_y = d.y; rh.ray.dir_z = d.z;
    rh.ray.tnear = tnear;
    rh.ray.tfar = tfar;
    rh.ray.mask = 0xffffffffu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(rtc, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    const TriangleData& t = tris[rh.hit.primID];
    float u = rh.hit.u, v = rh.hit.v, w = 1.0f - u - v;
    hit.tri = rh.hit.primID;
    hit.t = rh.ray.tfar;
    hit.p = t.p0 + t.e1 * u + t.e2 * v;
    hit.ng = t.front;
    size_t k = hit.tri;
    uint32_t i0 = scene.indices[3 * k], i1 = scene.indices[3 * k + 1], i2 = scene.indices[3 * k + 2];
    if (hasNormals) {
      glm::vec3 n = scene.normals[i0] * w + scene.normals[i1] * u + scene.normals[i2] * v;
      float len = glm::length(n);
      hit.ns = len > 0.0f ? n / len : t.front;
      if (glm::dot(hit.ns, hit.ng) < 0.0f) hit.ns = -hit.ns;
    } else {
      hit.ns = hit.ng;
    }
    hit.uv = hasUvs ? scene.uvs[i0] * w + scene.uvs[i1] * u + scene.uvs[i2] * v : glm::vec2(0.0f);
    return true;
  }

  bool occluded(const glm::vec3& o, const glm::vec3& d, float tfar, uint64_t& rays) const {
    ++rays;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay r{};
    r.org_x = o.x; r.org_y = o.y; r.org_z = o.z;
    r.dir_x = d.x; r.dir_y = d.y; r.dir_z = d.z;
    r.tnear = 0.0f;
    r.tfar = tfar;
    r.mask = 0xffffffffu;
    rtcOccluded1(rtc, &ctx, &r);
    return r.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
  }

  glm::vec3 albedoAt(uint32_t tri, glm::vec2 uv) const {
    const Material& m = scene.materials[tris[tri].material];
    glm::vec3 a(m.baseColor);
    if (m.baseColorTexture >= 0 && size_t(m.baseColorTexture) < textures.size())
      a *= textures[m.baseColorTexture].sample(uv);
    return a;
  }
  glm::vec3 emissionAt(uint32_t tri, glm::vec2 uv) const {
    const Material& m = scene.materials[tris[tri].material];
    glm::vec3 e = m.emissive;
    if (e != glm::vec3(0.0f) && m.emissiveTexture >= 0 && size_t(m.emissiveTexture) < textures.size())
      e *= textures[m.emissiveTexture].sample(uv);
    return e;
  }
  glm::vec2 uvAt(uint32_t tri, float b1, float b2) const {
    if (!hasUvs) return glm::vec2(0.0f);
    const uint32_t* i = &scene.indices[3 * size_t(tri)];
    return scene.uvs[i[0]] * (1.0f - b1 - b2) + scene.uvs[i[1]] * b1 + scene.uvs[i[2]] * b2;
  }

  // Light arriving straight from emitters at vertex v, reflected toward the viewer: punctual
  // lights (exact light model, one shadow ray each) plus one MIS-weighted area-light sample.
  glm::vec3 directLight(const Vertex& v, SampleStream& rng, uint64_t& rays) const {
    glm::vec3 sum(0.0f);
    glm::vec3 brdf = v.albedo * (1.0f / kPi);
    glm::vec3 o = offsetRay(v.p, v.ng);
    for (const Light& light : scene.lights) {
      LightSample s = sampleLight(light, v.p);
      float cosS = glm::dot(v.ns, s.toLight);
      if (cosS <= 0.0f || glm::dot(v.ng, s.toLight) <= 0.0f) continue;
      glm::vec3 e = s.irradianceAtNormalIncidence * cosS;
      if (maxComponent(e) <= 0.0f) continue;
      float tfar = std::isinf(s.distance) ? INFINITY : s.distance * (1.0f - 1e-5f);
      if (occluded(o, s.toLight, tfar, rays)) continue;
      sum += brdf * e;
    }
    if (!emitters.empty()) {
      float uPick = rng.next(), u1 = rng.next(), u2 = rng.next();
      size_t idx = size_t(std::lower_bound(emitterCdf.begin(), emitterCdf.end(), double(uPick)) -
                          emitterCdf.begin());
      idx = std::min(idx, emitters.size() - 1);
      uint32_t tri = emitters[idx];
      const TriangleData& t = tris[tri];
      float su = std::sqrt(u1);
      float b1 = su * (1.0f - u2), b2 = su * u2;  // uniform on the triangle
      glm::vec3 q = t.p0 + t.e1 * b1 + t.e2 * b2;
      glm::vec3 d = q - v.p;
      float dist2 = glm::dot(d, d);
      if (dist2 > 0.0f) {
        float dist = std::sqrt(dist2);
        glm::vec3 wi = d / dist;
        float cosL = -glm::dot(t.front, wi);
        float cosS = glm::dot(v.ns, wi);
        if (cosL > 0.0f && cosS > 0.0f && glm::dot(v.ng, wi) > 0.0f) {
          glm::vec3 le = emissionAt(tri, uvAt(tri, b1, b2));
          if (maxComponent(le) > 0.0f) {
            float pdfL = t.lightPdfArea * dist2 / cosL;
            float pdfB = cosS / kPi;
            float w = pdfL * pdfL / (pdfL * pdfL + pdfB * pdfB);
            // Shadow ray between the two offset points (q lifted off the emitter on its emitting
            // side): a relative shortening alone falsely occludes short rays near shared edges.
            glm::vec3 oq = offsetRay(q, t.front) - o;
            float len = glm::length(oq);
            if (len > 0.0f && !occluded(o, oq / len, len, rays))
              sum += brdf * le * (cosS / pdfL * w);
          }
        }
      }
    }
    return sum;
  }

  // Radiance leaving vertex v (its first reflection is reflection number 'r0'), restricted to
  // reflection counts in [range.rMin, range.rMax].
  glm::vec3 shade(Vertex v, int r0, Range range, SampleStream& rng, uint64_t& rays) const {
    glm::vec3 L(0.0f), beta(1.0f);
    bool areaLights = !emitters.empty();
    for (int r = r0; r <= kMaxReflections; ++r) {
      rng.setReflection(uint32_t(r));
      bool counts = r >= range.rMin && r <= range.rMax;
      if (counts) L += beta * directLight(v, rng, rays);
      // The sky a bounce ray from here might see counts as r + 1 <= rMax: covered by r < rMax.
      bool needBsdfRay = r < range.rMax || (counts && areaLights);
      if (!needBsdfRay) break;
      if (r > kRussianRouletteAfter) {
        float q = std::min(0.95f, maxComponent(v.albedo));
        if (rng.next() >= q) break;
        beta /= q;
      }
      float u1 = rng.next(), u2 = rng.next();
      glm::vec3 wi = cosineSample(v.ns, u1, u2);
      float cosS = glm::dot(v.ns, wi);
      if (glm::dot(v.ng, wi) <= 0.0f || cosS <= 0.0f) break;
      beta *= v.albedo;  // f cos / pdf = (albedo/pi) cos / (cos/pi)
      if (maxComponent(beta) <= 0.0f) break;
      Hit h;
      if (!intersect(offsetRay(v.p, v.ng), wi, 0.0f, INFINITY, h, rays)) {
        // Escaped after r reflections: the sky, counted as light reflected r + 1 times (see
        // setSkyRadiance), so what it lights directly is indirect-1, as the techniques gather it.
        if (r + 1 >= range.rMin && r + 1 <= range.rMax) L += beta * sky;
        break;
      }
      float cosL = -glm::dot(h.ng, wi);
      if (counts && areaLights && cosL > 0.0f && tris[h.tri].lightPdfArea > 0.0f) {
        glm::vec3 le = emissionAt(h.tri, h.uv);
        float pdfB = cosS / kPi;
        float pdfL = tris[h.tri].lightPdfArea * h.t * h.t / cosL;
        float w = pdfB * pdfB / (pdfB * pdfB + pdfL * pdfL);
        L += beta * le * w;
      }
      if (r + 1 > range.rMax) break;
      // Continue from the hit, normals turned toward the side the ray came from.
      float side = cosL > 0.0f ? 1.0f : -1.0f;
      v = Vertex{h.p, h.ng * side, h.ns * side, albedoAt(h.tri, h.uv)};
    }
    return L;
  }

  // One sample of radiance along a ray (or of the visible fraction in ao mode).
  glm::vec3 radiance(const glm::vec3& o, const glm::vec3& d, float tnear, Mode mode, float aoRadius,
                     SampleStream& rng, uint64_t& rays) const {
    Hit h;
    if (!intersect(o, d, tnear, INFINITY, h, rays)) {
      if (mode == Mode::AO) return glm::vec3(1.0f);
      return reflectionRange(mode).rMin == 0 ? sky : glm::vec3(0.0f);  // the sky seen directly (r = 0)
    }
    float cosL = -glm::dot(h.ng, d);
    float side = cosL > 0.0f ? 1.0f : -1.0f;
    if (mode == Mode::AO) return glm::vec3(aoSample(h.p, h.ng * side, h.ns * side, aoRadius, rng, rays));
    Range range = reflectionRange(mode);
    glm::vec3 L(0.0f);
    if (range.rMin == 0 && cosL > 0.0f) L += emissionAt(h.tri, h.uv);
    Vertex v{h.p, h.ng * side, h.ns * side, albedoAt(h.tri, h.uv)};
    return L + shade(v, 1, range, rng, rays);
  }

  float aoSample(const glm::vec3& p, const glm::vec3& ng, const glm::vec3& ns, float radius,
                 SampleStream& rng, uint64_t& rays) const {
    rng.setReflection(1);
    float u1 = rng.next(), u2 = rng.next();
    glm::vec3 wi = cosineSample(ns, u1, u2);
    if (glm::dot(wi, ng) <= 0.0f) return 0.0f;  // below the geometric surface: the surface blocks
    return occluded(offsetRay(p, ng), wi, radius, rays) ? 0.0f : 1.0f;
  }

  // Mean and standard error of 'samples' evaluations of fn(sampleIndex, rays) -> vec3, summed in
  // fixed blocks so the result does not depend on the number of threads.
  template <class Fn>
  Estimate estimate(int samples, int threads, Fn fn) const {
    if (samples < 1) throw Error("the number of samples must be at least 1");
    uint64_t n = uint64_t(samples);
    uint64_t blocks = (n + kBlock - 1) / kBlock;
    std::vector<glm::dvec3> sum(blocks), sq(blocks);
    std::atomic<uint64_t> next{0};
    auto work = [&] {
      uint64_t rays = 0;
      for (uint64_t b; (b = next.fetch_add(1)) < blocks;) {
        glm::dvec3 s(0.0), s2(0.0);
        for (uint64_t i = b * kBlock; i < std::min(n, (b + 1) * kBlock); ++i) {
          glm::dvec3 x(fn(i, rays));
          s += x;
          s2 += x * x;
        }
        sum[b] = s;
        sq[b] = s2;
      }
    };
    int nt = std::max(1, std::min<int>(threads <= 0 ? defaultThreadCount() : threads, int(blocks)));
    std::vector<std::thread> pool;
    for (int i = 1; i < nt; ++i) pool.emplace_back(work);
    work();
    for (auto& t : pool) t.join();
    glm::dvec3 s(0.0), s2(0.0);
    for (uint64_t b = 0; b < blocks; ++b) {
      s += sum[b];
      s2 += sq[b];
    }
    Estimate e;
    e.samples = n;
    e.mean = s / double(n);
    if (n > 1) {
      glm::dvec3 var = glm::max(glm::dvec3(0.0), (s2 - s * s / double(n)) / double(n - 1));
      e.stdErr = glm::sqrt(var / double(n));
    }
    return e;
  }
};

ReferenceTracer::ReferenceTracer(const Scene& scene) : scene_(scene), impl_(new Impl(scene)) {}
ReferenceTracer::~ReferenceTracer() = default;

void ReferenceTracer::setSkyRadiance(const glm::vec3& radiance) {
  if (!(radiance.x >= 0.0f && radiance.y >= 0.0f && radiance.z >= 0.0f) || !std::isfinite(radiance.x + radiance.y + radiance.z))
    throw Error("the sky radiance must be finite and not negative");
  impl_->sky = radiance;
}
glm::vec3 ReferenceTracer::skyRadiance() const { return impl_->sky; }
float ReferenceTracer::firstHit(const glm::vec3& o, const glm::vec3& d) const {
  Hit h;
  uint64_t rays = 0;
  return impl_->intersect(o, d, 0.0f, INFINITY, h, rays) ? h.t : INFINITY;
}

bool ReferenceTracer::occluded(const glm::vec3& o, const glm::vec3& d, float tfar) const {
  uint64_t rays = 0;
  return impl_->occluded(o, d, tfar, rays);
}

Estimate ReferenceTracer::estimateRadiance(const glm::vec3& origin, const glm::vec3& dir, Mode mode,
                                           int samples, uint64_t key, float aoRadius,
                                           int threads) const {
  glm::vec3 d = glm::normalize(dir);
  return impl_->estimate(samples, threads, [&](uint64_t i, uint64_t& rays) {
    SampleStream rng(0, key, i);
    return impl_->radiance(origin, d, 0.0f, mode, aoRadius, rng, rays);
  });
}

Estimate ReferenceTracer::estimateIrradiance(const glm::vec3& p, const glm::vec3& n, Mode mode,
                                             int samples, uint64_t key, int threads) const {
  if (mode == Mode::AO) throw Error("estimateIrradiance does not take mode ao; use estimateAO");
  glm::vec3 nn = glm::normalize(n);
  Range range = reflectionRange(mode);
  return impl_->estimate(samples, threads, [&](uint64_t i, uint64_t& rays) {
    SampleStream rng(0, key, i);
    Vertex v{p, nn, nn, glm::vec3(1.0f)};  // albedo 1: outgoing radiance = E / pi
    return impl_->shade(v, 1, range, rng, rays) * kPi;
  });
}

Estimate ReferenceTracer::estimateAO(const glm::vec3& p, const glm::vec3& n, int samples,
                                     float radius, uint64_t key, int threads) const {
  glm::vec3 nn = glm::normalize(n);
  return impl_->estimate(samples, threads, [&](uint64_t i, uint64_t& rays) {
    SampleStream rng(0, key, i);
    return glm::vec3(impl_->aoSample(p, nn, nn, radius, rng, rays));
  });
}

Image ReferenceTracer::render(const ReferenceSettings& st, RenderStats* stats) const {
  if (st.spp < 1 || st.spp > 1000000)
    throw Error("spp " + std::to_string(st.spp) + " is outside 1..1000000");
  if (st.width < 1 || st.height < 1 || st.width > 8192 || st.height > 8192)
    throw Error("image size " + std::to_string(st.width) + "x" + std::to_string(st.height) +
                " is outside 1..8192 in either direction");
  if (st.cameraIndex < 0 || size_t(st.cameraIndex) >= scene_.cameras.size())
    throw Error("camera index " + std::to_string(st.cameraIndex) + " is outside 0.." +
                std::to_string(int(scene_.cameras.size()) - 1));
  if (!(st.aoRadius > 0.0f)) throw Error("the ao radius must be positive");
  const Camera& cam = scene_.cameras[size_t(st.cameraIndex)];
  glm::vec3 fwd = glm::normalize(cam.forward);
  glm::vec3 right = glm::normalize(glm::cross(fwd, cam.up));
  glm::vec3 up = glm::cross(right, fwd);
  float tanHalf = std::tan(0.5f * cam.yfov);
  float aspect = float(st.width) / float(st.height);

  Image img(st.width, st.height);
  if (st.computeStdErr) img.stdErr.assign(img.rgb.size(), 0.0f);
  int threads = st.threads > 0 ? st.threads : defaultThreadCount();
  threads = std::max(1, std::min(threads, st.height));
  std::atomic<int> nextRow{0}, rowsDone{0};
  std::atomic<uint64_t> totalRays{0};
  std::exception_ptr failure;
  std::atomic<bool> failed{false};

  auto work = [&] {
    uint64_t rays = 0;
    try {
      for (int y; (y = nextRow.fetch_add(1)) < st.height && !failed.load();) {
        for (int x = 0; x < st.width; ++x) {
          uint64_t key = uint64_t(y) * uint64_t(st.width) + uint64_t(x);
          glm::dvec3 s(0.0), s2(0.0);
          for (int i = 0; i < st.spp; ++i) {
            SampleStream rng(st.seed, key, uint64_t(i));
            rng.setReflection(0);
            float jx = 0.5f, jy = 0.5f;
            if (st.pixelJitter) { jx = rng.next(); jy = rng.next(); }
            float nx = (float(x) + jx) / float(st.width) * 2.0f - 1.0f;
            float ny = 1.0f - (float(y) + jy) / float(st.height) * 2.0f;
            glm::vec3 dir = glm::normalize(fwd + right * (nx * tanHalf * aspect) + up * (ny * tanHalf));
            float tnear = cam.znear / std::max(glm::dot(dir, fwd), 1e-6f);
            glm::dvec3 v(impl_->radiance(cam.position, dir, tnear, st.mode, st.aoRadius, rng, rays));
            s += v;
            s2 += v * v;
          }
          double n = double(st.spp);
          glm::dvec3 mean = s / n;
          float* px = img.at(x, y);
          for (int c = 0; c < 3; ++c) px[c] = float(mean[c]);
          if (st.computeStdErr && st.spp > 1) {
            glm::dvec3 var = glm::max(glm::dvec3(0.0), (s2 - s * s / n) / (n - 1.0));
            size_t o = (size_t(y) * size_t(st.width) + size_t(x)) * 3;
            for (int c = 0; c < 3; ++c) img.stdErr[o + c] = float(std::sqrt(var[c] / n));
          }
        }
        rowsDone.fetch_add(1);
      }
    } catch (...) {
      if (!failed.exchange(true)) failure = std::current_exception();
    }
    totalRays.fetch_add(rays);
  };

  auto t0 = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  for (int i = 0; i < threads; ++i) pool.emplace_back(work);
  if (st.progress) {
    while (rowsDone.load() < st.height && !failed.load()) {
      st.progress(double(rowsDone.load()) / st.height);
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  for (auto& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
  if (st.progress) st.progress(1.0);
  auto t1 = std::chrono::steady_clock::now();
  if (stats) {
    stats->rays = totalRays.load();
    stats->seconds = std::chrono::duration<double>(t1 - t0).count();
    stats->threads = threads;
  }
  return img;
}

}  // namespace voxlab::reference
