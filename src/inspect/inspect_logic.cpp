#include "inspect/inspect_logic.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <sstream>

#include "core/error.h"
#include "capture/output_handler.h"
#include "inspect/script_verbs.h"

namespace voxlab {

// --- Display mapping -----------------------------------------------------------------------------

SliceSpec sliceToShow(const LevelData& level, const SliceSpec& chosen) {
  if (level.size.z <= 1) return SliceSpec{2, 0};
  SliceSpec s = chosen;
  if (s.index < 0) s.index = (s.axis == 0 ? level.size.x : s.axis == 1 ? level.size.y : level.size.z) / 2;
  return s;
}

glm::ivec2 sliceExtent(const LevelData& d, const SliceSpec& s) {
  switch (s.axis) {
    case 0: return {d.size.z, d.size.y};
    case 1: return {d.size.x, d.size.z};
    default: return {d.size.x, d.size.y};
  }
}

glm::ivec3 sliceTexel(const LevelData& d, const SliceSpec& s, int px, int py) {
  int axisSize = s.axis == 0 ? d.size.x : s.axis == 1 ? d.size.y : d.size.z;
  int index = std::clamp(s.index, 0, std::max(axisSize - 1, 0));
  switch (s.axis) {
    case 0: return {index, d.size.y - 1 - py, px};
    case 1: return {px, index, d.size.z - 1 - py};
    default: return {px, d.size.y - 1 - py, index};
  }
}

namespace {

// lo/hi of channel c over a whole level (finite values only), for the normalised semantics.
void levelRange(const LevelData& d, int c, float& lo, float& hi) {
  lo = 1e30f;
  hi = -1e30f;
  for (size_t t = 0; t < d.texelCount(); ++t) {
    float v = d.values[t * d.channels + c];
    if (std::isfinite(v)) { lo = std::min(lo, v); hi = std::max(hi, v); }
  }
}

// RGB of one texel as the slice view shows it: one channel in grey, or the semantic's mapping.
void mapTexel(const float* v, int channels, const TexelMapping& mapping, int ch, float x, float lo, float hi, uint8_t* o) {
  if (ch >= 0) {
    uint8_t g = mapping.normalise ? unitToByte(hi > lo ? (v[ch] - lo) / (hi - lo) : 0.0f) : unitToByte(v[ch] * x);
    o[0] = o[1] = o[2] = g;
    return;
  }
  mapping.map(v, channels, x, lo, hi, o);
}

}  // namespace

void normalisedRange(const LevelData& level, int channel, float& lo, float& hi) { levelRange(level, channel, lo, hi); }

DisplayImage rgbOf(const SliceImage& slice) {
  DisplayImage image;
  image.width = slice.width;
  image.height = slice.height;
  image.rgb.resize(size_t(slice.width) * slice.height * 3);
  for (size_t i = 0; i < size_t(slice.width) * slice.height; ++i)
    for (int c = 0; c < 3; ++c) image.rgb[i * 3 + c] = slice.rgba[i * 4 + c];
  return image;
}

SliceImage mapSlice(const LevelData& d, Semantic semantic, const SliceSpec& s, const DisplaySettings& ds) {
  SliceImage img;
  glm::ivec2 e = sliceExtent(d, s);
  img.width = e.x;
  img.height = e.y;
  img.rgba.assign(size_t(e.x) * e.y * 4, 255);
  if (d.values.empty() || d.channels == 0) return img;
  int ch = ds.channel >= d.channels ? d.channels - 1 : ds.channel;
  // Scalars are normalised over the whole level so that moving the slice keeps the scale.
  const TexelMapping& mapping = texelMapping(semantic);
  float lo = 0, hi = 0;
  if (mapping.normalise) levelRange(d, std::max(ch, 0), lo, hi);
  for (int py = 0; py < e.y; ++py)
    for (int px = 0; px < e.x; ++px) {
      glm::ivec3 t = sliceTexel(d, s, px, py);
      const float* v = &d.values[((size_t(t.z) * d.size.y + t.y) * d.size.x + t.x) * d.channels];
      mapTexel(v, d.channels, mapping, ch, ds.exposure, lo, hi, &img.rgba[(size_t(py) * e.x + px) * 4]);
    }
  return img;
}

// --- 3D views -------------------------------------------------------------------------------------

VolumeRGBA mapVolume(const LevelData& d, Semantic semantic, const DisplaySettings& ds) {
  VolumeRGBA vol;
  vol.size = d.size;
  vol.rgba.assign(d.texelCount() * 4, 0);
  if (d.values.empty() || d.channels == 0) return vol;
  int ch = ds.channel >= d.channels ? d.channels - 1 : ds.channel;
  const TexelMapping& mapping = texelMapping(semantic);
  float lo = 0, hi = 0;
  if (mapping.normalise) levelRange(d, std::max(ch, 0), lo, hi);
  bool alphaIsOpacity = ch < 0 && d.channels == 4 && mapping.alphaIsOpacity;
  for (size_t t = 0; t < d.texelCount(); ++t) {
    const float* v = &d.values[t * d.channels];
    uint8_t* o = &vol.rgba[t * 4];
    uint8_t a = 0;
    if (alphaIsOpacity) {
      a = unitToByte(v[3]);
    } else {
      bool any = false;
      for (int k = ch < 0 ? 0 : ch; k < (ch < 0 ? d.channels : ch + 1); ++k) any = any || (v[k] != 0.0f && std::isfinite(v[k]));
      a = any ? 255 : 0;
    }
    if (a == 0) continue;
    mapTexel(v, d.channels, mapping, ch, ds.exposure, lo, hi, o);
    o[3] = a;
    ++vol.nonEmpty;
  }
  return vol;
}

glm::vec3 OrbitCamera::eye() const {
  glm::vec3 dir(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
  return target + dir * (distance * radius);
}

glm::mat4 OrbitCamera::view() const {
  glm::vec3 e = eye(), f = glm::normalize(target - e);
  glm::vec3 r = glm::normalize(glm::cross(f, glm::vec3(0, 1, 0)));
  glm::vec3 u = glm::cross(r, f);
  glm::mat4 m(1.0f);
  m[0][0] = r.x, m[1][0] = r.y, m[2][0] = r.z;
  m[0][1] = u.x, m[1][1] = u.y, m[2][1] = u.z;
  m[0][2] = -f.x, m[1][2] = -f.y, m[2][2] = -f.z;
  m[3][0] = -glm::dot(r, e), m[3][1] = -glm::dot(u, e), m[3][2] = glm::dot(f, e);
  return m;
}

glm::mat4 OrbitCamera::projection(float aspect) const {
  float n = std::max(1e-3f, (distance - 1.5f) * radius * 0.5f), f = (distance + 1.5f) * radius * 2.0f;
  float t = 1.0f / std::tan(yfov * 0.5f);
  glm::mat4 m(0.0f);
  m[0][0] = t / aspect;
  m[1][1] = t;
  m[2][2] = -(f + n) / (f - n);
  m[2][3] = -1.0f;
  m[3][2] = -2.0f * f * n / (f - n);
  return m;
}

void OrbitCamera::rotate(float yawDeg, float pitchDeg) {
  yaw = std::remainder(yaw + yawDeg * 0.0174532925f, 6.2831853f);
  pitch = std::clamp(pitch + pitchDeg * 0.0174532925f, -1.4835f, 1.4835f);
}

void OrbitCamera::lookAlong(const glm::vec3& forward) {
  float l = glm::length(forward);
  if (!(l > 1e-6f)) return;
  glm::vec3 off = -forward / l;  // from the target to the eye
  yaw = std::atan2(off.x, off.z);
  pitch = std::clamp(std::asin(std::clamp(off.y, -1.0f, 1.0f)), -1.4835f, 1.4835f);
}

// --- Scene camera moves ------------------------------------------------------------------------------

namespace {
constexpr float kMaxPitch = 1.4835f;  // 85 degrees

// Forward from yaw (about +y, 0 = -z) and pitch; up without roll.
Camera withDirection(Camera c, float yaw, float pitch) {
  pitch = std::clamp(pitch, -kMaxPitch, kMaxPitch);
  c.forward = glm::vec3(-std::cos(pitch) * std::sin(yaw), std::sin(pitch), -std::cos(pitch) * std::cos(yaw));
  glm::vec3 right = glm::normalize(glm::cross(c.forward, glm::vec3(0, 1, 0)));
  c.up = glm::cross(right, c.forward);
  return c;
}
void yawPitchOf(const glm::vec3& f, float& yaw, float& pitch) {
  yaw = std::atan2(-f.x, -f.z);
  pitch = std::asin(std::clamp(f.y, -1.0f, 1.0f));
}
}  // namespace

Camera orbitCamera(const Camera& c, glm::vec3 target, float yawDeg, float pitchDeg) {
  // The camera turns rigidly about the target (position and view together), so a camera that was
  // flown off-centre keeps its framing, and turning back by the same angles returns it exactly.
  auto rotate = [](glm::vec3 v, glm::vec3 axis, float angle) {
    float c = std::cos(angle), s = std::sin(angle);
    return v * c + glm::cross(axis, v) * s + axis * glm::dot(axis, v) * (1.0f - c);
  };
  Camera o = c;
  const float yaw = glm::radians(yawDeg);
  o.position = target + rotate(c.position - target, glm::vec3(0, 1, 0), yaw);
  o.forward = glm::normalize(rotate(c.forward, glm::vec3(0, 1, 0), yaw));
  // Pitch: raising the eye tilts the view down; the view's pitch stays within +-85 degrees.
  float p0 = std::asin(std::clamp(o.forward.y, -1.0f, 1.0f));
  float turn = std::clamp(p0 - glm::radians(pitchDeg), -kMaxPitch, kMaxPitch) - p0;
  glm::vec3 right = glm::normalize(glm::cross(o.forward, glm::vec3(0, 1, 0)));
  o.position = target + rotate(o.position - target, right, turn);
  o.forward = glm::normalize(rotate(o.forward, right, turn));
  o.up = glm::cross(right, o.forward);
  o.name = "orbit";
  return o;
}

Camera lookCamera(const Camera& c, float yawDeg, float pitchDeg) {
  float yaw, pitch;
  yawPitchOf(c.forward, yaw, pitch);
  Camera o = withDirection(c, yaw + glm::radians(yawDeg), pitch + glm::radians(pitchDeg));
  o.name = "fly";
  return o;
}

Camera flyCamera(const Camera& c, float right, float up, float forward) {
  Camera o = c;
  glm::vec3 r = glm::normalize(glm::cross(c.forward, c.up));
  o.position += r * right + c.up * up + c.forward * forward;
  o.name = "fly";
  return o;
}

// --- Script image checks ----------------------------------------------------------------------------

ImageDifference imageDifference(const std::vector<uint8_t>& a, int aw, int ah, const std::vector<uint8_t>& b, int bw,
                                int bh) {
  ImageDifference d;
  const size_t na = size_t(std::max(aw, 0)) * size_t(std::max(ah, 0)), nb = size_t(std::max(bw, 0)) * size_t(std::max(bh, 0));
  const size_t ca = na ? a.size() / na : 0, cb = nb ? b.size() / nb : 0;
  if (aw != bw || ah != bh || ca != cb || ca == 0 || a.size() != na * ca || b.size() != nb * cb) {
    d.pixels = d.differing = std::max({na, nb, size_t(1)});
    return d;
  }
  d.pixels = na;
  for (size_t i = 0; i < na; ++i)
    if (!std::equal(&a[i * ca], &a[i * ca] + ca, &b[i * ca])) ++d.differing;
  return d;
}

ViewContent viewContent(const std::vector<uint8_t>& rgba, const uint8_t background[3], const uint8_t frame[3]) {
  ViewContent v;
  v.pixels = rgba.size() / 4;
  auto near = [&](size_t i, const uint8_t* c) {
    return std::abs(int(rgba[i]) - c[0]) <= 2 && std::abs(int(rgba[i + 1]) - c[1]) <= 2 &&
           std::abs(int(rgba[i + 2]) - c[2]) <= 2;
  };
  double sum = 0.0, sum2 = 0.0;
  for (size_t i = 0; i + 3 < rgba.size(); i += 4) {
    if (near(i, background) || near(i, frame)) continue;
    const double y = 0.2126 * rgba[i] + 0.7152 * rgba[i + 1] + 0.0722 * rgba[i + 2];
    sum += y;
    sum2 += y * y;
    ++v.content;
  }
  if (v.content > 1) {
    const double mean = sum / double(v.content);
    v.lumaStdDev = std::sqrt(std::max(0.0, sum2 / double(v.content) - mean * mean));
  }
  return v;
}

// --- Reproduction ----------------------------------------------------------------------------------

std::vector<std::pair<std::string, std::string>> viewerDemand(const Technique& technique,
                                                              const std::vector<std::pair<std::string, std::string>>& shown) {
  std::set<std::pair<int, std::string>> wanted;
  auto add = [&](const std::string& stage, const std::string& output) {
    auto [index, desc] = technique.findOutput(stage, output);  // throws naming the valid ones
    wanted.insert({index, desc->name});
  };
  add(technique.finalStage(), technique.finalOutput());
  for (const auto& [stage, output] : shown) add(stage, output);
  for (int i = 0; i < technique.stageCount(); ++i)
    if (!technique.decl(i).probes.empty())
      for (const auto& o : technique.decl(i).outputs)
        if (o.probeRecord) wanted.insert({i, o.name});
  std::vector<std::pair<std::string, std::string>> demand;
  for (const auto& [index, output] : wanted) demand.push_back({technique.stage(index).id(), output});
  return demand;
}

std::string reproduceCommand(const std::string& technique, const std::string& scene, const ParamSet& params,
                             const ParamSet& defaults, int width, int height, int camera,
                             const std::string& until, const std::string& out, const Camera* freeCamera) {
  auto quote = [](const std::string& s) {
    if (s.find_first_of(" \t'\"$\\") == std::string::npos) return s;
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
  };
  std::string cmd = "voxlab run --technique " + quote(technique) + " --scene " + quote(scene);
  for (const auto& [name, desc] : params.descs()) {
    double v = params.value(name);
    if (defaults.has(name) && ParamDesc::sameValue(defaults.value(name), v)) continue;
    cmd += " --set " + quote(name + "=" + desc.format(v));
  }
  cmd += " --size " + std::to_string(width) + "x" + std::to_string(height);
  if (camera != 0) cmd += " --camera " + std::to_string(camera);
  if (freeCamera) {
    auto vec = [](glm::vec3 v) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "%.7g,%.7g,%.7g", v.x, v.y, v.z);
      return std::string(buf);
    };
    cmd += " --look-from " + vec(freeCamera->position) + " --look-at " + vec(freeCamera->position + freeCamera->forward);
  }
  if (!until.empty()) cmd += " --until " + quote(until);
  cmd += " --out " + quote(out);
  return cmd;
}

// --- Presenter narrative ---------------------------------------------------------------------------

namespace {

// Inline Markdown reduced to its words: **bold**, *emphasis* and `code` markers dropped, links
// [text](url) as their text.
std::string plainInline(const std::string& s) {
  std::string r;
  for (size_t i = 0; i < s.size(); ++i) {
    char c = s[i];
    if (c == '*' || c == '`') continue;
    if (c == '[') {
      size_t close = s.find("](", i);
      size_t end = close == std::string::npos ? close : s.find(')', close);
      if (end != std::string::npos) {
        r += s.substr(i + 1, close - i - 1);
        i = end;
        continue;
      }
    }
    r += c;
  }
  return r;
}

}  // namespace

std::vector<NarrativeBlock> narrativeBlocks(const std::string& text) {
  std::vector<NarrativeBlock> blocks;
  std::istringstream in(text);
  std::string line;
  bool open = false, fence = false;
  while (std::getline(in, line)) {
    const size_t first = line.find_first_not_of(" \t");
    if (line.compare(first == std::string::npos ? 0 : first, 3, "```") == 0) {
      fence = !fence;
      open = false;
      continue;
    }
    if (fence) continue;
    if (first == std::string::npos) {
      open = false;
      continue;
    }
    std::string body = line.substr(first);
    if (body[0] == '#') {
      size_t k = body.find_first_not_of('#');
      blocks.push_back({NarrativeBlock::Kind::Heading, plainInline(body.substr(std::min(k + 1, body.size())))});
      open = false;
      continue;
    }
    size_t digits = body.find_first_not_of("0123456789");
    const bool bullet = body.rfind("- ", 0) == 0 || body.rfind("* ", 0) == 0;
    const bool numbered = digits != std::string::npos && digits > 0 && body.compare(digits, 2, ". ") == 0;
    if (bullet || numbered) {
      std::string mark = bullet ? "\xE2\x80\xA2 " : body.substr(0, digits + 2);  // U+2022 bullet
      blocks.push_back({NarrativeBlock::Kind::Item, mark + plainInline(body.substr(bullet ? 2 : digits + 2))});
      open = true;
      continue;
    }
    if (open) {
      blocks.back().text += " " + plainInline(body);
    } else {
      blocks.push_back({NarrativeBlock::Kind::Paragraph, plainInline(body)});
      open = true;
    }
  }
  return blocks;
}

// --- Scripts -----------------------------------------------------------------------------------------

namespace {

std::string substituteEnv(const std::string& s, const std::string& where) {
  std::string r;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '$' && i + 1 < s.size() && s[i + 1] == '{') {
      size_t end = s.find('}', i);
      if (end == std::string::npos) throw Error(where + ": unterminated ${...}");
      std::string name = s.substr(i + 2, end - i - 2);
      const char* v = std::getenv(name.c_str());
      if (!v) throw Error(where + ": environment variable " + name + " is not set");
      r += v;
      i = end;
    } else {
      r += s[i];
    }
  }
  return r;
}

}  // namespace

std::string scriptVerbsHelp() {
  std::string s;
  for (const ScriptVerb& v : scriptVerbs())
    if (v.usage) s += std::string("  ") + v.usage + "\n";
  return s;
}

std::vector<ScriptAction> parseScript(const std::string& text, const std::string& path) {
  std::vector<ScriptAction> actions;
  std::istringstream in(text);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    std::string where = path + ":" + std::to_string(n);
    size_t hash = line.find('#');
    if (hash != std::string::npos) line = line.substr(0, hash);
    std::istringstream words(substituteEnv(line, where));
    ScriptAction a;
    a.line = n;
    if (!(words >> a.verb)) continue;
    for (std::string w; words >> w;) a.args.push_back(w);
    const ScriptVerb* spec = findScriptVerb(a.verb);
    if (!spec || !spec->usage) {
      std::vector<std::string> names;
      for (const ScriptVerb& v : scriptVerbs())
        if (v.usage) names.push_back(v.name);
      throw Error(where + ": unknown action '" + a.verb + "'; valid: " + joinNames(names));
    }
    if (int(a.args.size()) < spec->minArgs || int(a.args.size()) > spec->maxArgs)
      throw Error(where + ": wrong arguments; usage: " + spec->usage);
    actions.push_back(std::move(a));
  }
  return actions;
}

}  // namespace voxlab
