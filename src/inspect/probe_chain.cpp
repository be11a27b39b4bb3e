// The probe chain read back (probe_chain.h).
#include "inspect/probe_chain.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace voxlab {

std::string formatSignificant(double value, int digits) {
  if (value == 0.0) return "0";  // also -0
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*g", std::clamp(digits, 1, 17), value);
  return buf;
}

std::string formatRecordValue(const nlohmann::json& value, int digits) {
  if (value.is_number_integer()) return value.dump();
  if (value.is_number()) return formatSignificant(value.get<double>(), digits);
  if (value.is_array()) {
    std::string s = "(";
    for (size_t i = 0; i < value.size(); ++i) s += (i ? ", " : "") + formatRecordValue(value[i], digits);
    return s + ")";
  }
  if (value.is_string()) return value.get<std::string>();
  return value.dump();
}

const ProbeChainEntry* ProbeChain::find(FieldRole role) const {
  for (const auto& s : sections)
    for (const auto& e : s.entries)
      if (e.role == role) return &e;
  return nullptr;
}

std::vector<const ProbeChainEntry*> ProbeChain::all(FieldRole role) const {
  std::vector<const ProbeChainEntry*> found;
  for (const auto& s : sections)
    for (const auto& e : s.entries)
      if (e.role == role) found.push_back(&e);
  return found;
}

void splitChainFieldName(const std::string& name, std::string& section, std::string& label, std::string& unit) {
  const size_t colon = name.find(": ");
  section = colon == std::string::npos ? name : name.substr(0, colon);
  label = colon == std::string::npos ? name : name.substr(colon + 2);
  unit.clear();
  const size_t open = label.rfind(" [");
  if (!label.empty() && label.back() == ']' && open != std::string::npos) {
    unit = label.substr(open + 2, label.size() - open - 3);
    label = label.substr(0, open);
  }
}

ProbeChain decodeProbeChain(const CapturedOutput& out) {
  ProbeChain chain;
  if (out.recordCount == 0) return chain;
  const nlohmann::json record = recordJson(out, 0);
  for (const BufferField& f : out.desc.layout.fields) {
    ProbeChainEntry e;
    std::string section;
    splitChainFieldName(f.name, section, e.label, e.unit);
    e.role = f.role;
    auto v = record.find(f.name);
    if (v == record.end()) continue;
    if (v->is_array()) {
      for (const auto& c : *v) e.values.push_back(c.is_number() ? c.get<double>() : 0.0);
    } else if (v->is_number()) {
      e.values.push_back(v->get<double>());
    }
    if (chain.sections.empty() || chain.sections.back().name != section) chain.sections.push_back({section, {}});
    chain.sections.back().entries.push_back(std::move(e));
  }
  return chain;
}

ProbeChainSum sumProbeChain(const ProbeChain& chain) {
  ProbeChainSum r;
  const ProbeChainEntry* total = chain.find(FieldRole::Sum);
  const auto addends = chain.all(FieldRole::Addend);
  if (!total) {
    r.error = "the chain declares no Sum field";
    return r;
  }
  if (addends.empty()) {
    r.error = "the chain declares no Addend field";
    return r;
  }
  r.total = total->values;
  r.addends.assign(r.total.size(), 0.0);
  for (const ProbeChainEntry* a : addends) {
    if (a->values.size() != r.total.size()) {
      r.error = "addend '" + a->label + "' has " + std::to_string(a->values.size()) + " components, the sum " +
                std::to_string(r.total.size());
      return r;
    }
    for (size_t c = 0; c < r.total.size(); ++c) r.addends[c] += a->values[c];
  }
  for (size_t c = 0; c < r.total.size(); ++c)
    r.worstRelative = std::max(r.worstRelative, std::fabs(r.addends[c] - r.total[c]) / std::max(std::fabs(r.total[c]), 1e-6));
  return r;
}

}  // namespace voxlab
