// The probe chain read back: a probe-chain record (Semantic::ProbeChain) as sections of labelled
// values with units, in the order its stage declared the fields, and the check that its parts add
// up to its total. No window needed: the Probe tab's chain view (visualisers/probe_chain.cpp) and
// the script verb expect-probe-chain draw and check what these return; unit-tested in
// tests/unit/test_probe_chain.cpp.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "capture/capture.h"

namespace voxlab {

// A number with 'digits' significant digits: 0.1235, 1235, 1.235e+05, 0.
std::string formatSignificant(double value, int digits = 4);
// A decoded record value as the viewer prints it: numbers with 'digits' significant digits,
// arrays as "(a, b, c)", anything else as JSON.
std::string formatRecordValue(const nlohmann::json& value, int digits = 4);

struct ProbeChainEntry {
  std::string label;  // "position"
  std::string unit;   // "m"; "" for a pure number
  FieldRole role = FieldRole::Other;
  std::vector<double> values;  // 1 to 4 components
};

struct ProbeChainSection {
  std::string name;  // "surface", "direct", "indirect", "composite"
  std::vector<ProbeChainEntry> entries;
};

struct ProbeChain {
  std::vector<ProbeChainSection> sections;  // in declaration order
  const ProbeChainEntry* find(FieldRole role) const;  // the first entry of that role (nullptr: none)
  std::vector<const ProbeChainEntry*> all(FieldRole role) const;
};

// Field "section: label [unit]" -> section, label, unit (a name without ": " is its own section;
// without a trailing "[...]" it has no unit).
void splitChainFieldName(const std::string& name, std::string& section, std::string& label, std::string& unit);

// Record 0 of a probe-chain output (empty without records).
ProbeChain decodeProbeChain(const CapturedOutput& out);

// Whether the Addend entries sum to the Sum entry, per component.
struct ProbeChainSum {
  std::vector<double> addends;  // the sum of the Addend entries
  std::vector<double> total;    // the Sum entry
  double worstRelative = 0.0;   // max over components of |addends - total| / max(|total|, 1e-6)
  std::string error;            // "" when both exist and have the same number of components
};
ProbeChainSum sumProbeChain(const ProbeChain& chain);

}  // namespace voxlab
