// Pass 1 of loading a glTF file (scene/gltf_loader.cpp): the structural check of its JSON.
#include "scene/gltf_json_check.h"

#include <cctype>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <vector>

#include "core/error.h"

namespace voxlab::gltf {
namespace {

using Json = nlohmann::json;

const std::vector<std::string> kSupportedExtensions = {"KHR_lights_punctual",
                                                       "KHR_materials_emissive_strength"};

const char* jsonTypeName(const Json& j) {
  switch (j.type()) {
    case Json::value_t::null: return "null";
    case Json::value_t::object: return "an object";
    case Json::value_t::array: return "an array";
    case Json::value_t::string: return "a string";
    case Json::value_t::boolean: return "a boolean";
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned: return "an integer";
    case Json::value_t::number_float: return "a number";
    default: return "an unknown value";
  }
}

enum class Kind { Int, Num, Str, Bool, Obj, ObjArr, StrArr, IntArr, NumArr, Ref, RefArr, TexInfo };

struct FieldSpec {
  const char* key;
  Kind kind;
  const char* target = nullptr;  // Ref / RefArr / TexInfo: the top-level array referred to
  int length = 0;                // NumArr: required length (0 = any)
};

bool isNonNegativeInt(const Json& j) {
  return j.is_number_unsigned() || (j.is_number_integer() && j.get<int64_t>() >= 0);
}

std::string decodeUri(const std::string& uri) {
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit((unsigned char)uri[i + 1]) &&
        std::isxdigit((unsigned char)uri[i + 2])) {
      out += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

}  // namespace

// Collapses any multi-line / control-character text into one trimmed line of bounded length.
std::string oneLine(const std::string& text, size_t maxLength) {
  // Line breaks become "; ", other control characters spaces; runs of spaces collapse.
  std::string out;
  std::string line;
  std::vector<std::string> lines;
  for (unsigned char c : text) {
    if (c == '\n' || c == '\r') {
      lines.push_back(line);
      line.clear();
    } else if (c < 0x20 || c == 0x7f) {
      line += ' ';
    } else {
      line += char(c);
    }
  }
  lines.push_back(line);
  for (std::string& l : lines) {
    std::string t;
    for (char c : l) {
      if (c == ' ' && (t.empty() || t.back() == ' ')) continue;
      t += c;
    }
    while (!t.empty() && t.back() == ' ') t.pop_back();
    if (t.empty()) continue;
    if (!out.empty()) out += "; ";
    out += t;
  }
  if (out.size() > maxLength) out = out.substr(0, maxLength - 3) + "...";
  return out;
}

Error sceneError(const std::string& path, const std::string& what) {
  return Error(oneLine("scene '" + path + "': " + what, 1000));
}

void JsonChecker::check(const Json& root) {
  checkJson(root);
  checkCycles(root);
  checkExternalFiles(root);
}

// alphaMode must be one of the three glTF names, alphaCutoff a number >= 0 (types are checked by
// the field specs).
void JsonChecker::checkMaterialAlpha(const Json& material, const std::string& where) {
  if (auto mode = material.find("alphaMode"); mode != material.end() && mode->is_string()) {
    std::string m = mode->get<std::string>();
    if (m != "OPAQUE" && m != "MASK" && m != "BLEND") {
      fail(where + ".alphaMode '" + oneLine(m, 40) + "' is not one of OPAQUE, MASK, BLEND");
    }
  }
  if (auto cutoff = material.find("alphaCutoff"); cutoff != material.end() && cutoff->is_number()) {
    double c = cutoff->get<double>();
    if (!(c >= 0.0)) fail(where + ".alphaCutoff " + cutoff->dump() + " must be a number >= 0");
  }
}

void JsonChecker::checkJson(const Json& root) {
  if (!root.is_object()) fail(std::string("JSON root must be an object, got ") + jsonTypeName(root));

  // asset.version: glTF 1.0 files are recognisably different and must not be half-loaded.
  auto asset = root.find("asset");
  if (asset == root.end()) {
    fail("has no 'asset' object (not a glTF 2.0 file; glTF 1.0 is not supported)");
  }
  if (!asset->is_object()) fail(std::string("'asset' must be an object, got ") + jsonTypeName(*asset));
  auto version = asset->find("version");
  if (version == asset->end()) fail("asset.version is missing (only glTF 2.x is supported)");
  if (!version->is_string()) {
    fail(std::string("asset.version must be a string such as \"2.0\", got ") + jsonTypeName(*version) + " " +
         oneLine(version->dump(), 40));
  }
  std::string versionText = version->get<std::string>();
  if (versionText.rfind("2.", 0) != 0) {
    fail("glTF version " + versionText + " is not supported (only glTF 2.x; glTF 1.0 files must be converted to 2.0)");
  }

  const std::map<std::string, std::vector<FieldSpec>> specs = {
      {"accessors",
       {{"bufferView", Kind::Ref, "bufferViews"}, {"byteOffset", Kind::Int}, {"componentType", Kind::Int},
        {"normalized", Kind::Bool}, {"count", Kind::Int}, {"type", Kind::Str}, {"sparse", Kind::Obj},
        {"min", Kind::NumArr}, {"max", Kind::NumArr}, {"name", Kind::Str}}},
      {"animations", {}},
      {"buffers", {{"uri", Kind::Str}, {"byteLength", Kind::Int}, {"name", Kind::Str}}},
      {"bufferViews",
       {{"buffer", Kind::Ref, "buffers"}, {"byteOffset", Kind::Int}, {"byteLength", Kind::Int},
        {"byteStride", Kind::Int}, {"target", Kind::Int}, {"name", Kind::Str}}},
      {"cameras", {{"type", Kind::Str}, {"perspective", Kind::Obj}, {"orthographic", Kind::Obj}, {"name", Kind::Str}}},
      {"images", {{"uri", Kind::Str}, {"mimeType", Kind::Str}, {"bufferView", Kind::Ref, "bufferViews"}, {"name", Kind::Str}}},
      {"materials",
       {{"name", Kind::Str}, {"pbrMetallicRoughness", Kind::Obj}, {"emissiveFactor", Kind::NumArr, nullptr, 3},
        {"emissiveTexture", Kind::TexInfo, "textures"}, {"normalTexture", Kind::TexInfo, "textures"},
        {"occlusionTexture", Kind::TexInfo, "textures"}, {"doubleSided", Kind::Bool},
        {"alphaMode", Kind::Str}, {"alphaCutoff", Kind::Num}, {"extensions", Kind::Obj}}},
      {"meshes", {{"primitives", Kind::ObjArr}, {"name", Kind::Str}, {"weights", Kind::NumArr}}},
      {"nodes",
       {{"children", Kind::RefArr, "nodes"}, {"mesh", Kind::Ref, "meshes"}, {"camera", Kind::Ref, "cameras"},
        {"skin", Kind::Ref, "skins"}, {"matrix", Kind::NumArr, nullptr, 16},
        {"translation", Kind::NumArr, nullptr, 3}, {"rotation", Kind::NumArr, nullptr, 4},
        {"scale", Kind::NumArr, nullptr, 3}, {"name", Kind::Str}, {"extensions", Kind::Obj}}},
      {"samplers", {}},
      {"scenes", {{"nodes", Kind::RefArr, "nodes"}, {"name", Kind::Str}}},
      {"skins", {}},
      {"textures", {{"source", Kind::Ref, "images"}, {"sampler", Kind::Ref, "samplers"}}},
  };

  auto arraySize = [&](const char* name) -> size_t {
    auto it = root.find(name);
    return (it != root.end() && it->is_array()) ? it->size() : 0;
  };

  // Checks one field of an object against its spec; 'where' is e.g. "nodes[3]".
  std::function<void(const Json&, const std::string&, const FieldSpec&)> checkField =
      [&](const Json& obj, const std::string& where, const FieldSpec& f) {
        auto it = obj.find(f.key);
        if (it == obj.end()) return;
        const Json& v = *it;
        std::string name = where + "." + f.key;
        auto expect = [&](bool ok, const char* what) {
          if (!ok) fail(name + " must be " + what + ", got " + jsonTypeName(v) + " " + oneLine(v.dump(), 40));
        };
        auto checkRef = [&](const Json& r, const std::string& rname) {
          if (!isNonNegativeInt(r)) {
            fail(rname + " must be a non-negative integer index, got " + jsonTypeName(r) + " " + oneLine(r.dump(), 40));
          }
          size_t n = arraySize(f.target);
          if (r.get<uint64_t>() >= n) {
            fail(rname + " = " + r.dump() + " is out of range ('" + f.target + "' has " + std::to_string(n) + " entries)");
          }
        };
        switch (f.kind) {
          case Kind::Int: expect(isNonNegativeInt(v), "a non-negative integer"); break;
          case Kind::Num: expect(v.is_number(), "a number"); break;
          case Kind::Str: expect(v.is_string(), "a string"); break;
          case Kind::Bool: expect(v.is_boolean(), "a boolean"); break;
          case Kind::Obj: expect(v.is_object(), "an object"); break;
          case Kind::ObjArr:
            expect(v.is_array(), "an array of objects");
            for (size_t i = 0; i < v.size(); ++i) {
              if (!v[i].is_object()) {
                fail(name + "[" + std::to_string(i) + "] must be an object, got " + jsonTypeName(v[i]));
              }
            }
            break;
          case Kind::StrArr:
            expect(v.is_array(), "an array of strings");
            for (const Json& e : v) expect(e.is_string(), "an array of strings");
            break;
          case Kind::IntArr:
            expect(v.is_array(), "an array of integers");
            for (const Json& e : v) expect(isNonNegativeInt(e), "an array of non-negative integers");
            break;
          case Kind::NumArr:
            expect(v.is_array(), "an array of numbers");
            for (const Json& e : v) expect(e.is_number(), "an array of numbers");
            if (f.length && int(v.size()) != f.length) {
              fail(name + " must have " + std::to_string(f.length) + " numbers, got " + std::to_string(v.size()));
            }
            break;
          case Kind::Ref: checkRef(v, name); break;
          case Kind::RefArr:
            expect(v.is_array(), "an array of indices");
            for (size_t i = 0; i < v.size(); ++i) checkRef(v[i], name + "[" + std::to_string(i) + "]");
            break;
          case Kind::TexInfo: {
            expect(v.is_object(), "an object");
            auto idx = v.find("index");
            if (idx == v.end()) fail(name + ".index is missing");
            checkRef(*idx, name + ".index");
            auto tc = v.find("texCoord");
            if (tc != v.end() && !isNonNegativeInt(*tc)) fail(name + ".texCoord must be a non-negative integer");
            break;
          }
        }
      };

  for (const auto& [arrayName, fields] : specs) {
    auto it = root.find(arrayName);
    if (it == root.end()) continue;
    if (!it->is_array()) {
      fail("'" + arrayName + "' must be an array, got " + jsonTypeName(*it) + " " + oneLine(it->dump(), 40));
    }
    for (size_t i = 0; i < it->size(); ++i) {
      const Json& obj = (*it)[i];
      std::string where = arrayName + "[" + std::to_string(i) + "]";
      if (!obj.is_object()) fail(where + " must be an object, got " + jsonTypeName(obj));
      for (const FieldSpec& f : fields) checkField(obj, where, f);
    }
  }
  for (const char* name : {"extensionsUsed", "extensionsRequired"}) {
    auto it = root.find(name);
    if (it != root.end()) checkField(root, "(root)", FieldSpec{name, Kind::StrArr});
  }
  if (auto it = root.find("scene"); it != root.end()) {
    checkField(root, "(root)", FieldSpec{"scene", Kind::Ref, "scenes"});
  }

  // Required fields and nested structures we read.
  if (auto acc = root.find("accessors"); acc != root.end()) {
    for (size_t i = 0; i < acc->size(); ++i) {
      const Json& a = (*acc)[i];
      std::string where = "accessors[" + std::to_string(i) + "]";
      for (const char* req : {"componentType", "count", "type"}) {
        if (!a.contains(req)) fail(where + " has no '" + req + "'");
      }
    }
  }
  if (auto bv = root.find("bufferViews"); bv != root.end()) {
    for (size_t i = 0; i < bv->size(); ++i) {
      for (const char* req : {"buffer", "byteLength"}) {
        if (!(*bv)[i].contains(req)) fail("bufferViews[" + std::to_string(i) + "] has no '" + req + "'");
      }
    }
  }
  if (auto meshes = root.find("meshes"); meshes != root.end()) {
    for (size_t m = 0; m < meshes->size(); ++m) {
      const Json& mesh = (*meshes)[m];
      auto prims = mesh.find("primitives");
      if (prims == mesh.end()) fail("meshes[" + std::to_string(m) + "] has no 'primitives'");
      for (size_t p = 0; p < prims->size(); ++p) {
        const Json& prim = (*prims)[p];
        std::string where = "meshes[" + std::to_string(m) + "].primitives[" + std::to_string(p) + "]";
        auto attrs = prim.find("attributes");
        if (attrs == prim.end() || !attrs->is_object()) fail(where + ".attributes must be an object");
        for (auto a = attrs->begin(); a != attrs->end(); ++a) {
          checkField(*attrs, where + ".attributes", FieldSpec{a.key().c_str(), Kind::Ref, "accessors"});
        }
        checkField(prim, where, FieldSpec{"indices", Kind::Ref, "accessors"});
        checkField(prim, where, FieldSpec{"material", Kind::Ref, "materials"});
        checkField(prim, where, FieldSpec{"mode", Kind::Int});
      }
    }
  }
  if (auto mats = root.find("materials"); mats != root.end()) {
    for (size_t m = 0; m < mats->size(); ++m) {
      auto pbr = (*mats)[m].find("pbrMetallicRoughness");
      if (pbr == (*mats)[m].end()) {
        checkMaterialAlpha((*mats)[m], "materials[" + std::to_string(m) + "]");
        continue;
      }
      std::string where = "materials[" + std::to_string(m) + "].pbrMetallicRoughness";
      checkMaterialAlpha((*mats)[m], "materials[" + std::to_string(m) + "]");
      checkField(*pbr, where, FieldSpec{"baseColorFactor", Kind::NumArr, nullptr, 4});
      checkField(*pbr, where, FieldSpec{"baseColorTexture", Kind::TexInfo, "textures"});
      checkField(*pbr, where, FieldSpec{"metallicFactor", Kind::Num});
      checkField(*pbr, where, FieldSpec{"roughnessFactor", Kind::Num});
    }
  }

  // Required extensions: refuse what we cannot honour, naming it and what we support.
  if (auto req = root.find("extensionsRequired"); req != root.end()) {
    std::vector<std::string> unsupported;
    for (const Json& e : *req) {
      std::string name = e.get<std::string>();
      if (std::find(kSupportedExtensions.begin(), kSupportedExtensions.end(), name) == kSupportedExtensions.end()) {
        unsupported.push_back(name);
      }
    }
    if (!unsupported.empty()) {
      fail("requires unsupported extension" + std::string(unsupported.size() > 1 ? "s " : " ") +
           joinNames(unsupported) + " (supported: " + joinNames(kSupportedExtensions) + ")");
    }
  }

  // Animations: the samplers and channels the loader reads (accessor types, counts and key
  // times are checked when the loader reads them).
  if (auto anims = root.find("animations"); anims != root.end()) {
    for (size_t a = 0; a < anims->size(); ++a) {
      const Json& anim = (*anims)[a];
      const std::string where = "animations[" + std::to_string(a) + "]";
      for (const char* req : {"channels", "samplers"})
        if (!anim.contains(req)) fail(where + " has no '" + req + "'");
      checkField(anim, where, FieldSpec{"channels", Kind::ObjArr});
      checkField(anim, where, FieldSpec{"samplers", Kind::ObjArr});
      checkField(anim, where, FieldSpec{"name", Kind::Str});
      const Json& samplers = anim["samplers"];
      for (size_t s = 0; s < samplers.size(); ++s) {
        const std::string sw = where + ".samplers[" + std::to_string(s) + "]";
        for (const char* req : {"input", "output"}) {
          if (!samplers[s].contains(req)) fail(sw + " has no '" + req + "'");
          checkField(samplers[s], sw, FieldSpec{req, Kind::Ref, "accessors"});
        }
        checkField(samplers[s], sw, FieldSpec{"interpolation", Kind::Str});
        if (auto in = samplers[s].find("interpolation"); in != samplers[s].end()) {
          const std::string mode = in->get<std::string>();
          if (mode != "LINEAR" && mode != "STEP" && mode != "CUBICSPLINE")
            fail(sw + ".interpolation '" + oneLine(mode, 40) + "' is unknown; valid: LINEAR, STEP, CUBICSPLINE");
        }
      }
      const Json& channels = anim["channels"];
      for (size_t c = 0; c < channels.size(); ++c) {
        const std::string cw = where + ".channels[" + std::to_string(c) + "]";
        const Json& channel = channels[c];
        auto sampler = channel.find("sampler");
        if (sampler == channel.end()) fail(cw + " has no 'sampler'");
        if (!isNonNegativeInt(*sampler))
          fail(cw + ".sampler must be a non-negative integer index, got " + oneLine(sampler->dump(), 40));
        if (sampler->get<uint64_t>() >= samplers.size())
          fail(cw + ".sampler = " + sampler->dump() + " is out of range (the animation has " +
               std::to_string(samplers.size()) + " samplers)");
        auto target = channel.find("target");
        if (target == channel.end() || !target->is_object()) fail(cw + ".target must be an object");
        checkField(*target, cw + ".target", FieldSpec{"node", Kind::Ref, "nodes"});
        auto path = target->find("path");
        if (path == target->end() || !path->is_string()) fail(cw + ".target.path must be a string");
        const std::string p = path->get<std::string>();
        if (p != "translation" && p != "rotation" && p != "scale" && p != "weights")
          fail(cw + ".target.path '" + oneLine(p, 40) + "' is unknown; valid: translation, rotation, scale, weights");
      }
    }
  }

  // KHR_lights_punctual: light definitions and node references.
  size_t lightCount = 0;
  if (auto ext = root.find("extensions"); ext != root.end()) {
    if (!ext->is_object()) fail(std::string("'extensions' must be an object, got ") + jsonTypeName(*ext));
    if (auto lp = ext->find("KHR_lights_punctual"); lp != ext->end()) {
      if (!lp->is_object()) fail("extensions.KHR_lights_punctual must be an object");
      if (auto lights = lp->find("lights"); lights != lp->end()) {
        if (!lights->is_array()) fail("extensions.KHR_lights_punctual.lights must be an array");
        lightCount = lights->size();
        for (size_t i = 0; i < lights->size(); ++i) {
          const Json& l = (*lights)[i];
          std::string where = "KHR_lights_punctual.lights[" + std::to_string(i) + "]";
          if (!l.is_object()) fail(where + " must be an object");
          auto type = l.find("type");
          if (type == l.end() || !type->is_string()) fail(where + ".type must be a string");
          std::string t = type->get<std::string>();
          if (t != "directional" && t != "point" && t != "spot") {
            fail(where + ".type '" + t + "' is not one of directional, point, spot");
          }
          checkField(l, where, FieldSpec{"color", Kind::NumArr, nullptr, 3});
          checkField(l, where, FieldSpec{"intensity", Kind::Num});
          checkField(l, where, FieldSpec{"range", Kind::Num});
          checkField(l, where, FieldSpec{"spot", Kind::Obj});
          if (auto spot = l.find("spot"); spot != l.end()) {
            checkField(*spot, where + ".spot", FieldSpec{"innerConeAngle", Kind::Num});
            checkField(*spot, where + ".spot", FieldSpec{"outerConeAngle", Kind::Num});
          }
        }
      }
    }
  }
  if (auto nodes = root.find("nodes"); nodes != root.end()) {
    for (size_t i = 0; i < nodes->size(); ++i) {
      auto ext = (*nodes)[i].find("extensions");
      if (ext == (*nodes)[i].end()) continue;
      auto lp = ext->find("KHR_lights_punctual");
      if (lp == ext->end()) continue;
      std::string where = "nodes[" + std::to_string(i) + "].extensions.KHR_lights_punctual";
      if (!lp->is_object()) fail(where + " must be an object");
      auto light = lp->find("light");
      if (light == lp->end() || !isNonNegativeInt(*light)) fail(where + ".light must be a non-negative integer");
      if (light->get<uint64_t>() >= lightCount) {
        fail(where + ".light = " + light->dump() + " is out of range (the file defines " +
             std::to_string(lightCount) + " lights)");
      }
    }
  }
}

// glTF requires the node hierarchy to be a forest; a cycle would make traversal infinite.
void JsonChecker::checkCycles(const Json& root) {
  auto nodesIt = root.find("nodes");
  if (nodesIt == root.end()) return;
  const Json& nodes = *nodesIt;
  const size_t n = nodes.size();
  auto nodeName = [&](size_t i) {
    std::string s = std::to_string(i);
    auto nm = nodes[i].find("name");
    if (nm != nodes[i].end() && nm->is_string()) s += " ('" + nm->get<std::string>() + "')";
    return s;
  };
  std::vector<std::vector<size_t>> children(n);
  for (size_t i = 0; i < n; ++i) {
    auto c = nodes[i].find("children");
    if (c == nodes[i].end()) continue;
    for (const Json& e : *c) children[i].push_back(e.get<size_t>());
  }
  // Iterative three-colour depth-first search.
  std::vector<uint8_t> colour(n, 0);  // 0 unvisited, 1 on stack, 2 done
  for (size_t start = 0; start < n; ++start) {
    if (colour[start]) continue;
    std::vector<std::pair<size_t, size_t>> stack{{start, 0}};
    colour[start] = 1;
    while (!stack.empty()) {
      auto& [node, next] = stack.back();
      if (next < children[node].size()) {
        size_t child = children[node][next++];
        if (colour[child] == 1) {
          // Reconstruct the cycle child -> ... -> node -> child.
          std::vector<size_t> cycle{child};
          for (size_t k = stack.size(); k-- > 0 && stack[k].first != child;) cycle.insert(cycle.begin() + 1, stack[k].first);
          std::string text;
          for (size_t k = 0; k < cycle.size(); ++k) {
            if (cycle.size() > 8 && k == 3) {
              text += "... (" + std::to_string(cycle.size() - 6) + " more) -> ";
              k = cycle.size() - 3;
            }
            text += "node " + nodeName(cycle[k]) + " -> ";
          }
          text += "node " + nodeName(child);
          fail("node hierarchy has a cycle: " + text);
        }
        if (colour[child] == 0) {
          colour[child] = 1;
          stack.push_back({child, 0});
        }
      } else {
        colour[node] = 2;
        stack.pop_back();
      }
    }
  }
}

void JsonChecker::checkExternalFiles(const Json& root) {
  for (const char* kind : {"buffers", "images"}) {
    auto arr = root.find(kind);
    if (arr == root.end()) continue;
    for (size_t i = 0; i < arr->size(); ++i) {
      auto uri = (*arr)[i].find("uri");
      if (uri == (*arr)[i].end()) continue;
      std::string u = uri->get<std::string>();
      if (u.rfind("data:", 0) == 0) continue;
      std::filesystem::path file = std::filesystem::path(baseDir_) / decodeUri(u);
      std::error_code ec;
      if (!std::filesystem::is_regular_file(file, ec)) {
        std::string what = std::string(kind) == "buffers" ? "buffer " : "image ";
        fail(what + std::to_string(i) + " refers to external file '" + u + "' which does not exist (looked for " +
             file.string() + ")");
      }
    }
  }
}
}  // namespace voxlab::gltf
