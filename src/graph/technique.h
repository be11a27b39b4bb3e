// Technique: an ordered list of stages plus the name of its final output; the registry lists
// every technique; a technique registers itself with VOXLAB_REGISTER_TECHNIQUE in its own file.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "graph/stage.h"

namespace voxlab {

class Technique {
 public:
  Technique(std::string id, std::string title, std::string summary);
  const std::string& id() const { return id_; }
  const std::string& title() const { return title_; }
  const std::string& summary() const { return summary_; }

  template <typename S, typename... A>
  S& add(A&&... args) {
    auto s = std::make_unique<S>(std::forward<A>(args)...);
    S& ref = *s;
    addStage(std::move(s));
    return ref;
  }
  void addStage(std::unique_ptr<Stage> stage);
  void setFinalOutput(const std::string& stage, const std::string& output);

  int stageCount() const { return int(stages_.size()); }
  Stage& stage(int i) { return *stages_.at(i); }
  const Stage& stage(int i) const { return *stages_.at(i); }
  const StageDecl& decl(int i) const { return decls_.at(i); }
  int stageIndex(const std::string& id) const;  // throws Error listing the stage ids
  std::vector<std::string> stageIds() const;
  const std::string& finalStage() const { return finalStage_; }
  const std::string& finalOutput() const { return finalOutput_; }

  // Every parameter any stage declares, with defaults.
  ParamSet defaultParams() const;
  // Checks the declarations: unique stage ids and output names, every read has an earlier
  // writer, the final output exists. Throws Error describing the first problem.
  void validate() const;
  // Index of the stage that writes 'resource' last before stage 'before' (-1 = none).
  int writerOf(const std::string& resource, int before) const;
  // Whether a stage's results depend on the camera: it reads kViewResource, or reads what an
  // earlier stage that depends on it wrote. The viewer probes and overlays only such images.
  bool dependsOnView(int stage) const;
  // (stage index, output) for "stage/output"; throws Error listing valid names.
  std::pair<int, const OutputDesc*> findOutput(const std::string& stage, const std::string& output) const;

 private:
  std::string id_, title_, summary_;
  std::vector<std::unique_ptr<Stage>> stages_;
  std::vector<StageDecl> decls_;
  std::string finalStage_, finalOutput_;
};

struct TechniqueEntry {
  std::string id;
  std::string title;
  std::function<std::unique_ptr<Technique>()> create;
};

void registerTechnique(const TechniqueEntry& entry);
const std::vector<TechniqueEntry>& techniqueRegistry();  // sorted by id
std::unique_ptr<Technique> createTechnique(const std::string& id);  // throws Error listing ids
std::vector<std::string> techniqueIds();

struct TechniqueRegistrar {
  TechniqueRegistrar(const char* id, const char* title, std::unique_ptr<Technique> (*create)()) {
    registerTechnique({id, title, create});
  }
};

}  // namespace voxlab

// In a technique's main file: VOXLAB_REGISTER_TECHNIQUE("vct-grid", "Voxel cone tracing ...", makeFn);
#define VOXLAB_REGISTER_TECHNIQUE(id, title, factory) \
  static ::voxlab::TechniqueRegistrar voxlabTechniqueRegistrar_##factory(id, title, &factory)
