#include "graph/param.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "core/error.h"

namespace voxlab {

ParamDesc ParamDesc::integer(std::string name, int def, int lo, int hi, std::string help, std::string unit) {
  ParamDesc d;
  d.name = std::move(name); d.type = ParamType::Int; d.defaultValue = def; d.minValue = lo;
  d.maxValue = hi; d.help = std::move(help); d.unit = std::move(unit);
  return d;
}

ParamDesc ParamDesc::real(std::string name, double def, double lo, double hi, std::string help, std::string unit) {
  ParamDesc d;
  d.name = std::move(name); d.type = ParamType::Float; d.defaultValue = def; d.minValue = lo;
  d.maxValue = hi; d.help = std::move(help); d.unit = std::move(unit);
  return d;
}

ParamDesc ParamDesc::fromScene(std::string name, double lo, double hi, std::string help, std::string unit) {
  ParamDesc d = real(std::move(name), std::nan(""), lo, hi, std::move(help), std::move(unit));
  d.sceneDefault = true;
  return d;
}

bool ParamDesc::isSceneValue(double v) { return std::isnan(v); }

ParamDesc ParamDesc::boolean(std::string name, bool def, std::string help) {
  ParamDesc d;
  d.name = std::move(name); d.type = ParamType::Bool; d.defaultValue = def ? 1 : 0; d.minValue = 0;
  d.maxValue = 1; d.help = std::move(help);
  return d;
}

ParamDesc ParamDesc::choice(std::string name, std::vector<std::string> choices, int def, std::string help) {
  ParamDesc d;
  d.name = std::move(name); d.type = ParamType::Choice; d.choices = std::move(choices);
  d.defaultValue = def; d.minValue = 0; d.maxValue = double(d.choices.size()) - 1; d.help = std::move(help);
  return d;
}

const char* ParamDesc::typeName() const {
  switch (type) {
    case ParamType::Int: return "int";
    case ParamType::Float: return "float";
    case ParamType::Bool: return "bool";
    case ParamType::Choice: return "choice";
  }
  return "?";
}

std::string ParamDesc::format(double v) const {
  switch (type) {
    case ParamType::Int: return std::to_string(int(std::lround(v)));
    case ParamType::Bool: return v != 0 ? "true" : "false";
    case ParamType::Choice: {
      int i = int(std::lround(v));
      return i >= 0 && i < int(choices.size()) ? choices[i] : "?";
    }
    case ParamType::Float: {
      if (sceneDefault && isSceneValue(v)) return "scene";
      std::ostringstream s;
      s.precision(6);
      s << v;
      return s.str();
    }
  }
  return "";
}

std::string ParamDesc::rangeText() const {
  switch (type) {
    case ParamType::Bool: return "true or false";
    case ParamType::Choice: return "one of " + joinNames(choices);
    default: {
      std::string r = format(minValue) + ".." + format(maxValue);
      if (powerOfTwo) r += " (power of two)";
      if (sceneDefault) r += ", or scene (the loaded scene's value, the default)";
      return r;
    }
  }
}

void ParamDesc::validate(double v) const {
  if (sceneDefault && isSceneValue(v)) return;
  bool ok = std::isfinite(v) && v >= minValue && v <= maxValue;
  if (ok && (type == ParamType::Int || type == ParamType::Choice || type == ParamType::Bool))
    ok = v == std::floor(v);
  if (ok && powerOfTwo) {
    long i = long(v);
    ok = i > 0 && (i & (i - 1)) == 0;
  }
  if (!ok) throw Error("parameter " + name + "=" + format(v) + " is out of range; valid: " + rangeText());
}

double ParamDesc::parse(const std::string& text) const {
  auto bad = [&] {
    return Error("parameter " + name + "='" + text + "' is not valid; valid: " + rangeText());
  };
  double v = 0;
  if (sceneDefault && text == "scene") return std::nan("");
  switch (type) {
    case ParamType::Bool:
      if (text == "true" || text == "1" || text == "on") v = 1;
      else if (text == "false" || text == "0" || text == "off") v = 0;
      else throw bad();
      break;
    case ParamType::Choice: {
      v = -1;
      for (size_t i = 0; i < choices.size(); ++i)
        if (choices[i] == text) v = double(i);
      if (v < 0) throw bad();
      break;
    }
    default: {
      char* end = nullptr;
      v = std::strtod(text.c_str(), &end);
      if (text.empty() || *end != '\0') throw bad();
      if (type == ParamType::Int && v != std::floor(v)) throw bad();
      if (!std::isfinite(v) || v < minValue || v > maxValue) throw bad();
    }
  }
  try {
    validate(v);
  } catch (const Error&) {
    throw bad();
  }
  return v;
}

void ParamSet::declare(const ParamDesc& d) {
  auto it = descs_.find(d.name);
  if (it != descs_.end()) {
    const ParamDesc& e = it->second;
    if (e.type != d.type || !ParamDesc::sameValue(e.defaultValue, d.defaultValue) || e.minValue != d.minValue ||
        e.maxValue != d.maxValue || e.choices != d.choices)
      throw Error("parameter " + d.name + " is declared twice with different types, defaults or ranges");
    return;
  }
  descs_[d.name] = d;
  values_[d.name] = d.defaultValue;
}

const ParamDesc& ParamSet::desc(const std::string& name) const {
  auto it = descs_.find(name);
  if (it == descs_.end()) {
    std::vector<std::string> names;
    for (const auto& [n, d] : descs_) names.push_back(n);
    throw Error("unknown parameter '" + name + "'; valid parameters: " + joinNames(names));
  }
  return it->second;
}

double ParamSet::value(const std::string& name) const {
  desc(name);
  return values_.at(name);
}

const std::string& ParamSet::getChoice(const std::string& name) const {
  const ParamDesc& d = desc(name);
  return d.choices.at(size_t(values_.at(name)));
}

void ParamSet::set(const std::string& name, double v) {
  desc(name).validate(v);
  values_[name] = v;
}

std::vector<std::string> ParamSet::vectorComponents(const std::string& name) const {
  if (name.empty() || has(name)) return {};
  std::vector<std::string> parts;
  for (const char* axis : {".x", ".y", ".z"}) {
    if (!has(name + axis)) return {};
    parts.push_back(name + axis);
  }
  return parts;
}

std::vector<std::pair<std::string, double>> ParamSet::parseText(const std::string& name, const std::string& text) const {
  const std::vector<std::string> parts = vectorComponents(name);
  if (parts.empty()) return {{name, desc(name).parse(text)}};
  // "X,Y,Z": exactly three fields, each valid for its component; nothing is set otherwise.
  std::vector<std::string> fields;
  size_t from = 0;
  for (;;) {
    size_t comma = text.find(',', from);
    fields.push_back(text.substr(from, comma == std::string::npos ? std::string::npos : comma - from));
    if (comma == std::string::npos) break;
    from = comma + 1;
  }
  auto form = [&] {
    const ParamDesc& x = desc(parts[0]);
    return "three comma-separated values X,Y,Z (e.g. " + name + "=1.5,0,-2) for " + name + ".x/.y/.z, each " +
           x.rangeText() + (x.unit.empty() ? "" : " " + x.unit);
  };
  if (fields.size() != 3)
    throw Error("parameter " + name + "='" + text + "' has " + std::to_string(fields.size()) + " value" +
                (fields.size() == 1 ? "" : "s") + "; valid: " + form());
  std::vector<std::pair<std::string, double>> out;
  for (size_t i = 0; i < 3; ++i) {
    try {
      out.push_back({parts[i], desc(parts[i]).parse(fields[i])});
    } catch (const Error&) {
      throw Error("parameter " + name + "='" + text + "': '" + fields[i] + "' is not a valid " + parts[i] +
                  "; valid: " + form());
    }
  }
  return out;
}

void ParamSet::setText(const std::string& name, const std::string& text) {
  for (const auto& [n, v] : parseText(name, text)) values_[n] = v;
}

void ParamSet::setAssignment(const std::string& a) {
  auto eq = a.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error("--set '" + a + "' is not NAME=VALUE (e.g. voxel.resolution=64)");
  setText(a.substr(0, eq), a.substr(eq + 1));
}

void ParamSet::resetToDefaults() {
  for (const auto& [n, d] : descs_) values_[n] = d.defaultValue;
}

std::map<std::string, std::string> ParamSet::formatted() const {
  std::map<std::string, std::string> out;
  for (const auto& [n, d] : descs_) out[n] = d.format(values_.at(n));
  return out;
}

}  // namespace voxlab
