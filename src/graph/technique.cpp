#include "graph/technique.h"

#include <algorithm>
#include <map>
#include <set>

#include "core/error.h"
#include "graph/scene_inputs.h"
#include "graph/reference_mode.h"
#include "graph/resource_budget.h"

namespace voxlab {

Technique::Technique(std::string id, std::string title, std::string summary)
    : id_(std::move(id)), title_(std::move(title)), summary_(std::move(summary)) {}

void Technique::addStage(std::unique_ptr<Stage> stage) {
  StageDecl decl;
  StageBuilder builder(decl);
  stage->declare(builder);
  decls_.push_back(std::move(decl));
  stages_.push_back(std::move(stage));
}

void Technique::setFinalOutput(const std::string& stage, const std::string& output) {
  finalStage_ = stage;
  finalOutput_ = output;
}

int Technique::stageIndex(const std::string& id) const {
  for (int i = 0; i < stageCount(); ++i)
    if (id == stages_[i]->id()) return i;
  throw Error("technique " + id_ + " has no stage '" + id + "'; valid stages: " + joinNames(stageIds()));
}

std::vector<std::string> Technique::stageIds() const {
  std::vector<std::string> ids;
  for (const auto& s : stages_) ids.push_back(s->id());
  return ids;
}

ParamSet Technique::defaultParams() const {
  ParamSet p;
  for (const auto& d : decls_)
    for (const auto& param : d.params) p.declare(param);
  p.declare(memoryBudgetParam());  // every technique: the resource budget (graph/resource_budget.h)
  return p;
}

int Technique::writerOf(const std::string& resource, int before) const {
  for (int i = std::min(before, stageCount()) - 1; i >= 0; --i) {
    const auto& d = decls_[i];
    if (std::find(d.writes.begin(), d.writes.end(), resource) != d.writes.end()) return i;
    for (const auto& o : d.outputs)
      if (o.resourceName() == resource) return i;
  }
  return -1;
}

bool Technique::dependsOnView(int stage) const {
  for (const auto& res : decls_.at(stage).reads) {
    if (res == kViewResource) return true;
    int w = writerOf(res, stage);
    if (w >= 0 && dependsOnView(w)) return true;
  }
  return false;
}

void Technique::validate() const {
  std::set<std::string> ids;
  for (int i = 0; i < stageCount(); ++i) {
    std::string id = stages_[i]->id();
    if (!ids.insert(id).second) throw Error(id_ + ": stage id '" + id + "' is used twice");
    std::set<std::string> outs;
    for (const auto& o : decls_[i].outputs)
      if (!outs.insert(o.name).second) throw Error(id_ + "/" + id + ": output '" + o.name + "' declared twice");
    for (const auto& r : decls_[i].reads)
      if (!isSceneInput(r) && writerOf(r, i) < 0)
        throw Error(id_ + "/" + id + " reads '" + r + "' but no earlier stage writes it");
    // A probe names parameters of its own stage; a light-space probe names its image.
    for (const auto& p : decls_[i].probes) {
      for (const auto& n : p.paramNames()) {
        bool declared = false;
        for (const auto& q : decls_[i].params) declared = declared || q.name == n;
        if (!declared)
          throw Error(id_ + "/" + id + ": " + probeSpaceName(p.space) + " probe names parameter '" + n +
                      "', which the stage does not declare");
      }
      if (p.x.empty() || p.y.empty() || (p.space == ProbeSpace::Volume && p.z.empty()))
        throw Error(id_ + "/" + id + ": a " + probeSpaceName(p.space) + " probe needs parameters for x, y" +
                    (p.space == ProbeSpace::Volume ? " and z" : ""));
      if (p.space == ProbeSpace::Light && p.resource.empty())
        throw Error(id_ + "/" + id + ": a light probe names the light-space image it points into");
    }
  }
  // Each resource has exactly one writer, so an earlier stage's output is never overwritten by a
  // later stage and stays inspectable after the whole technique has run.
  std::map<std::string, std::string> writers;
  for (int i = 0; i < stageCount(); ++i) {
    std::vector<std::string> written = decls_[i].writes;
    for (const auto& o : decls_[i].outputs) written.push_back(o.resourceName());
    std::set<std::string> mine(written.begin(), written.end());
    for (const auto& r : mine) {
      auto [it, fresh] = writers.emplace(r, stages_[i]->id());
      if (!fresh)
        throw Error(id_ + ": resource '" + r + "' is written by both " + it->second + " and " + stages_[i]->id());
    }
  }
  const ParamSet defaults = defaultParams();  // throws on conflicting declarations
  // A reference mode's {name}s are parameters of the technique (any stage's).
  for (int i = 0; i < stageCount(); ++i)
    for (const auto& o : decls_[i].outputs) {
      try {
        referenceModeUnder(o, defaults);
      } catch (const Error& e) {
        throw Error(id_ + "/" + stages_[i]->id() + ": " + e.what());
      }
    }
  findOutput(finalStage_, finalOutput_);
}

std::pair<int, const OutputDesc*> Technique::findOutput(const std::string& stage, const std::string& output) const {
  int i = stageIndex(stage);
  std::vector<std::string> names;
  for (const auto& o : decls_[i].outputs) {
    if (o.name == output) return {i, &o};
    names.push_back(o.name);
  }
  throw Error(id_ + "/" + stage + " has no output '" + output + "'; valid outputs: " + joinNames(names));
}

// --- Registry ------------------------------------------------------------------------------------

static std::vector<TechniqueEntry>& registry() {
  static std::vector<TechniqueEntry> entries;
  return entries;
}

void registerTechnique(const TechniqueEntry& entry) {
  auto& r = registry();
  r.push_back(entry);
  std::sort(r.begin(), r.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
}

const std::vector<TechniqueEntry>& techniqueRegistry() { return registry(); }

std::vector<std::string> techniqueIds() {
  std::vector<std::string> ids;
  for (const auto& e : registry()) ids.push_back(e.id);
  return ids;
}

std::unique_ptr<Technique> createTechnique(const std::string& id) {
  for (const auto& e : registry())
    if (e.id == id) {
      auto t = e.create();
      t->validate();
      return t;
    }
  throw Error("unknown technique '" + id + "'; valid techniques: " + joinNames(techniqueIds()));
}

}  // namespace voxlab
