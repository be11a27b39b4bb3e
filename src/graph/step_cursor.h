// StepCursor: runs a technique's stages 0..k on a scene with a parameter set, and re-runs only
// what a change invalidates. The viewer's Next/Previous/Run-to-here, `voxlab run --until`, the
// snapshot suite and the benchmark all drive this one class.
//
// Invalidation follows the declarations: changing a parameter makes every stage that declares it
// stale; changing the view makes every stage that reads kViewResource stale; a stage is stale as
// soon as the stage that wrote one of its reads is stale. A new scene makes everything "not run".
#pragma once
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "graph/resource_budget.h"
#include "graph/technique.h"
#include "scene/gpu_scene.h"
#include "scene/scene.h"

namespace voxlab {

class ShaderLibrary;

// Partial: an iterative stage that ran some of its iterations (stepped one at a time); its
// resources hold the state after the last one, and later stages wait until it is Done.
enum class StageState { NotRun, Done, Stale, Partial };
const char* stageStateName(StageState s);

struct StageRecord {
  StageState state = StageState::NotRun;
  double cpuMs = 0.0;  // wall time of execute() including a glFinish
  double gpuMs = 0.0;  // GL_TIME_ELAPSED of the stage's commands
  int iterationsRun = 0;    // of the current (or last) run
  int iterationsTotal = 1;  // the stage's iterations() for that run
  StageStats stats;
  // The outputs the run wanted of it (StageContext::wantedOutputs); nullopt = all of them.
  std::optional<std::set<std::string>> wanted;
};

// What a run needs of each stage under the current demand: whether it runs at all, and which of
// its outputs are wanted (demanded, or read by a later stage that runs).
struct StagePlan {
  bool needed = true;
  std::optional<std::set<std::string>> wanted;  // nullopt = every output
};

class StepCursor {
 public:
  StepCursor(std::unique_ptr<Technique> technique, ShaderLibrary& shaders);
  ~StepCursor();

  Technique& technique() { return *technique_; }
  const Technique& technique() const { return *technique_; }
  void setScene(std::shared_ptr<const Scene> scene);  // uploads it; every stage becomes NotRun
  const Scene& scene() const { return *scene_; }
  const GpuScene& gpuScene() const { return *gpuScene_; }
  bool hasScene() const { return scene_ != nullptr; }

  const ParamSet& params() const { return params_; }
  void setParam(const std::string& name, double value);
  void setParamText(const std::string& name, const std::string& text);
  void setParams(const ParamSet& values);  // copies every value; invalidates what changed

  // Output size and camera. The camera defaults to the scene's first camera.
  void setViewSize(int width, int height);
  void setCamera(const Camera& camera);
  void useSceneCamera(int index);  // throws Error naming the valid range
  const ViewState& view() const { return view_; }
  const Camera& camera() const { return camera_; }

  int stageCount() const { return technique_->stageCount(); }
  const StageRecord& record(int stage) const { return records_.at(stage); }
  // Runs every stage 0..last that is not Done (a Partial stage continues from its next
  // iteration). Stages after 'last' keep their state (a Done stage after a re-run one becomes
  // Stale). For progress between iterations, step with runIteration (the viewer does).
  void runThrough(int last);
  void runAll() { runThrough(stageCount() - 1); }
  // Runs the next iteration of an iterative stage (the first one when it is not Partial), after
  // running any earlier stage the demand needs that is not Done. Returns the iteration that ran
  // (0-based). everyOutput: the stepped stage computes every output (a stage stepped on purpose:
  // lesson steps, the tests); otherwise what the demand wants of it (the viewer's stage-by-stage
  // progress).
  int runIteration(int stage, bool everyOutput = true);
  int iterations(int stage) const { return technique_->stage(stage).iterations(params_); }

  // Outputs on demand. By default a run computes every output. With a demand (stage id, output
  // name pairs), runThrough runs only the stages the demanded outputs depend on, following the
  // declared reads back from them, and tells each which of its outputs are wanted; a stage that ran
  // for fewer outputs than a later demand wants runs again. The viewer demands what it shows, the
  // CLI what it writes (--final-only: the final output), fidelity what it compares.
  void demandEverything();
  void demandOutputs(const std::vector<std::pair<std::string, std::string>>& outputs);  // throws on unknown ones
  bool demandsEverything() const { return !demand_.has_value(); }
  // The plan under the current demand; 'alsoStage' >= 0 demands every output of that stage too.
  std::vector<StagePlan> plan(int alsoStage = -1) const;
  // Whether 'output' of 'stage' holds data of the last run: the stage ran (Done or Partial) and
  // the output was wanted then or is not computed on demand.
  bool outputComputed(int stage, const std::string& output) const;
  // The same, or the stage is Stale and its last run computed the output: the data is there but
  // out of date (what the viewer shows as "stale").
  bool outputHeld(int stage, const std::string& output) const;
  // The first stage of 0..last the current demand needs that is not Done for what it wants (not
  // run, Stale, Partial, or Done for fewer outputs than the demand now wants); -1 when none. A
  // runThrough(last) runs exactly these, in order; the viewer runs them one per frame.
  int nextToRun(int last) const;

  Blackboard& board() { return board_; }
  ShaderLibrary& shaders() { return shaders_; }
  void invalidateAll();  // e.g. after a shader reload; stages forget held results (Stage::forgetHeldResults)
  void invalidate(int stage);  // that stage and every stage reading what it wrote become Stale
  // The resources the current parameters and view need, from the stages' declarations, and the
  // refusal line when they do not fit the GL limits and gpu.memory-budget ("" = they fit). Every
  // run checks it first and throws Error with that line before allocating anything.
  ResourceEstimate resourceEstimate() const;
  std::string resourceBudgetExcess() const;

 private:
  void markStale(int stage);
  void markReadersStale(int stage);  // every later stage reading what 'stage' wrote, then propagate()
  // Runs iterations of 'stage' until 'untilIteration' (exclusive, clamped to its count),
  // continuing a Partial stage; marks it Done after the last one.
  void runStage(int stage, int untilIteration, const std::optional<std::set<std::string>>& wanted);
  // Runs every stage 0..last the plan needs that is not Done for what it wants.
  void runNeeded(int last, const std::vector<StagePlan>& plan);
  // Done under a demand that wanted fewer on-demand outputs than 'wanted': it must run again.
  bool ranForLess(int stage, const std::optional<std::set<std::string>>& wanted) const;
  void propagate();
  void updateViewMatrices();

  std::unique_ptr<Technique> technique_;
  ShaderLibrary& shaders_;
  std::shared_ptr<const Scene> scene_;
  std::unique_ptr<GpuScene> gpuScene_;
  ParamSet params_;
  Camera camera_;
  ViewState view_;
  Blackboard board_;
  std::vector<StageRecord> records_;
  std::optional<std::set<std::pair<int, std::string>>> demand_;  // (stage index, output); nullopt = all
  mutable std::optional<ResourceLimits> limits_;  // queried from GL on first use
};

}  // namespace voxlab
