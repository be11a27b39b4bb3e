// The script verb registry and the argument access of ScriptCall (script_verbs.h).
#include "inspect/script_verbs.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <utility>

#include "core/error.h"

namespace voxlab {

namespace {

struct VerbRegistry {
  std::vector<std::pair<int, ScriptVerb>> ordered;  // (group order, verb)
  std::vector<ScriptVerb> verbs;
};

VerbRegistry& registry() {
  static VerbRegistry r;
  return r;
}

}  // namespace

const std::vector<ScriptVerb>& scriptVerbs() { return registry().verbs; }

const ScriptVerb* findScriptVerb(const std::string& name) {
  for (const ScriptVerb& v : scriptVerbs())
    if (name == v.name) return &v;
  return nullptr;
}

bool registerScriptVerbs(int order, std::initializer_list<ScriptVerb> verbs) {
  VerbRegistry& r = registry();
  for (const ScriptVerb& v : verbs) {
    // Two features claiming one verb is a programming error that no script could work around.
    const bool taken = std::any_of(r.ordered.begin(), r.ordered.end(),
                                   [&](const auto& entry) { return std::string(entry.second.name) == v.name; });
    if (taken) {
      std::fprintf(stderr, "script verb '%s' is registered twice\n", v.name);
      std::abort();
    }
    r.ordered.emplace_back(order, v);
  }
  std::stable_sort(r.ordered.begin(), r.ordered.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  r.verbs.clear();
  for (const auto& [groupOrder, v] : r.ordered) r.verbs.push_back(v);
  return true;
}

const std::string& ScriptCall::arg(size_t i) const {
  if (i >= action_.args.size()) badArgument("argument " + std::to_string(i + 1) + " is missing");
  return action_.args[i];
}

int ScriptCall::intArg(size_t i) const {
  const std::string& word = arg(i);
  try {
    size_t used = 0;
    const int value = std::stoi(word, &used);
    if (used == word.size()) return value;
  } catch (const std::exception&) {
  }
  badArgument("'" + word + "' is not an integer");
}

float ScriptCall::floatArg(size_t i) const {
  const std::string& word = arg(i);
  try {
    size_t used = 0;
    const float value = std::stof(word, &used);
    if (used == word.size()) return value;
  } catch (const std::exception&) {
  }
  badArgument("'" + word + "' is not a number");
}

bool ScriptCall::onOff(size_t i) const {
  const std::string& word = arg(i);
  if (word != "on" && word != "off") badArgument("expected on or off, not '" + word + "'");
  return word == "on";
}

std::string ScriptCall::text(size_t from) const {
  std::string joined;
  for (size_t i = from; i < action_.args.size(); ++i) joined += (joined.empty() ? "" : " ") + action_.args[i];
  return joined;
}

void ScriptCall::fail(const std::string& message) const { throw Error(message); }

void ScriptCall::badArgument(const std::string& message) const {
  throw Error(message + "; usage: " + (verb_.usage ? verb_.usage : verb_.name));
}

}  // namespace voxlab
