// The script verbs of the viewer (voxlab view --script), registered next to the feature they drive:
// each panel file registers its verbs with VOXLAB_REGISTER_SCRIPT_VERBS, as the Details tabs
// register with VOXLAB_REGISTER_DETAILS_TAB. A verb is its name, its argument count, its usage
// line and its handler; parseScript checks the name and the count, Viewer::execute looks the verb
// up and calls the handler with a ScriptCall, whose typed arguments fail with the verb's usage.
#pragma once
#include <initializer_list>
#include <string>
#include <vector>

#include "inspect/inspect_logic.h"

namespace voxlab {

class Viewer;
class ScriptCall;
struct CapturedOutput;

struct ScriptVerb {
  const char* name;
  int minArgs, maxArgs;
  const char* usage;  // "NAME ARGS (what it does)"; nullptr: a step the viewer inserts itself (soak's)
  void (*run)(Viewer& viewer, const ScriptCall& call);
};

// Every verb, in the order of their groups (then as registered): the help and the "valid:" list.
const std::vector<ScriptVerb>& scriptVerbs();
// The verb named 'name', or nullptr.
const ScriptVerb* findScriptVerb(const std::string& name);
// Registers a group of verbs; 'order' places the group in the help (lower first).
bool registerScriptVerbs(int order, std::initializer_list<ScriptVerb> verbs);
#define VOXLAB_REGISTER_SCRIPT_VERBS(name, order, ...) \
  static const bool voxlabScriptVerbs_##name = ::voxlab::registerScriptVerbs(order, {__VA_ARGS__})

// One script action as its handler sees it. fail() reports a failed check; the typed arguments
// report a malformed word with the verb's usage. The viewer adds "FILE:LINE: VERB: " to both.
class ScriptCall {
 public:
  ScriptCall(const ScriptAction& action, const ScriptVerb& verb) : action_(action), verb_(verb) {}
  const ScriptAction& action() const { return action_; }
  const std::string& verb() const { return action_.verb; }
  size_t count() const { return action_.args.size(); }
  const std::string& arg(size_t i) const;
  int intArg(size_t i) const;
  float floatArg(size_t i) const;
  bool onOff(size_t i) const;               // "on" or "off"
  std::string text(size_t from = 0) const;  // the words from 'from' on, joined by spaces
  [[noreturn]] void fail(const std::string& message) const;
  [[noreturn]] void badArgument(const std::string& message) const;  // message + "; usage: ..."

 private:
  const ScriptAction& action_;
  const ScriptVerb& verb_;
};

// The selected output, captured now (script_runner.cpp); fails the call with the capture's error.
const CapturedOutput& requireShownCapture(Viewer& viewer, const ScriptCall& call);

}  // namespace voxlab
