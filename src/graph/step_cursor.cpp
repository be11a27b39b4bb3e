#include "graph/step_cursor.h"

#include <algorithm>
#include <chrono>
#include <limits>

#include "core/error.h"
#include "gpu/gl_debug.h"
#include "gpu/shader_library.h"
#include "graph/scene_inputs.h"

namespace voxlab {

const char* stageStateName(StageState s) {
  switch (s) {
    case StageState::NotRun: return "not run";
    case StageState::Done: return "done";
    case StageState::Stale: return "stale";
    case StageState::Partial: return "partial";
  }
  return "?";
}

StepCursor::StepCursor(std::unique_ptr<Technique> technique, ShaderLibrary& shaders)
    : technique_(std::move(technique)), shaders_(shaders), params_(technique_->defaultParams()),
      records_(technique_->stageCount()) {}

StepCursor::~StepCursor() = default;

void StepCursor::setScene(std::shared_ptr<const Scene> scene) {
  gpuScene_.reset();
  board_.clear();
  scene_ = std::move(scene);
  gpuScene_ = std::make_unique<GpuScene>(*scene_);
  for (auto& r : records_) r = StageRecord{};
  camera_ = scene_->cameras.at(0);
  updateViewMatrices();
}

void StepCursor::markStale(int i) {
  auto& r = records_.at(i);
  if (r.state == StageState::Done || r.state == StageState::Partial) r.state = StageState::Stale;
}

void StepCursor::propagate() {
  for (int j = 0; j < stageCount(); ++j) {
    if (records_[j].state == StageState::Done) {
      for (const auto& res : technique_->decl(j).reads) {
        if (isSceneInput(res)) continue;
        int w = technique_->writerOf(res, j);
        if (w >= 0 && records_[w].state != StageState::Done) {
          markStale(j);
          break;
        }
      }
    }
  }
}

void StepCursor::setParam(const std::string& name, double value) {
  if (ParamDesc::sameValue(params_.value(name), value)) return;
  params_.set(name, value);
  for (int i = 0; i < stageCount(); ++i)
    for (const auto& p : technique_->decl(i).params)
      if (p.name == name) markStale(i);
  propagate();
}

void StepCursor::setParamText(const std::string& name, const std::string& text) {
  for (const auto& [n, v] : params_.parseText(name, text)) setParam(n, v);  // a vector parameter sets three
}

void StepCursor::setParams(const ParamSet& values) {
  for (const auto& [name, desc] : values.descs())
    if (params_.has(name)) setParam(name, values.value(name));
}

void StepCursor::invalidateAll() {
  for (int i = 0; i < stageCount(); ++i) {
    technique_->stage(i).forgetHeldResults();
    markStale(i);
  }
}

void StepCursor::invalidate(int stage) {
  markStale(stage);
  markReadersStale(stage);
}

void StepCursor::markReadersStale(int stage) {
  for (int j = stage + 1; j < stageCount(); ++j)
    for (const auto& res : technique_->decl(j).reads)
      if (!isSceneInput(res) && technique_->writerOf(res, j) == stage) markStale(j);
  propagate();
}

void StepCursor::updateViewMatrices() {
  view_.position = camera_.position;
  view_.view = camera_.view();
  view_.projection = camera_.projection(float(view_.width) / float(view_.height));
  for (int i = 0; i < stageCount(); ++i) {
    const auto& reads = technique_->decl(i).reads;
    if (std::find(reads.begin(), reads.end(), kViewResource) != reads.end()) markStale(i);
  }
  propagate();
}

void StepCursor::setViewSize(int width, int height) {
  if (width == view_.width && height == view_.height) return;
  view_.width = width;
  view_.height = height;
  updateViewMatrices();
}

void StepCursor::setCamera(const Camera& camera) {
  camera_ = camera;
  updateViewMatrices();
}

void StepCursor::useSceneCamera(int index) {
  if (!scene_) throw Error("no scene loaded");
  int n = int(scene_->cameras.size());
  if (index < 0 || index >= n)
    throw Error("camera " + std::to_string(index) + " does not exist; valid: 0.." + std::to_string(n - 1));
  setCamera(scene_->cameras[index]);
}

ResourceEstimate StepCursor::resourceEstimate() const { return estimateResources(*technique_, params_, view_); }

std::string StepCursor::resourceBudgetExcess() const {
  if (!limits_) limits_ = ResourceLimits::query();
  return checkResourceBudget(*technique_, params_, view_, *limits_);
}

void StepCursor::demandEverything() { demand_.reset(); }

void StepCursor::demandOutputs(const std::vector<std::pair<std::string, std::string>>& outputs) {
  std::set<std::pair<int, std::string>> demand;
  for (const auto& [stage, output] : outputs) {
    auto [index, desc] = technique_->findOutput(stage, output);  // throws naming the valid ones
    demand.insert({index, desc->name});
  }
  demand_ = std::move(demand);
}

std::vector<StagePlan> StepCursor::plan(int alsoStage) const {
  const int n = stageCount();
  std::vector<StagePlan> plan(n);
  if (!demand_) return plan;  // every stage, every output
  // Backwards from the last stage: a stage is needed when one of its outputs is demanded or a
  // later needed stage reads something it wrote; the outputs it must compute are the demanded ones
  // and those such a stage reads.
  for (int i = n - 1; i >= 0; --i) {
    StagePlan& p = plan[i];
    p.wanted.emplace();
    p.needed = false;
    const StageDecl& d = technique_->decl(i);
    for (const auto& o : d.outputs)
      if (i == alsoStage || demand_->count({i, o.name})) p.wanted->insert(o.name);
    for (int j = i + 1; j < n; ++j) {
      if (!plan[j].needed) continue;
      const StageDecl& reader = technique_->decl(j);
      for (const auto& res : reader.reads) {
        if (res == kViewResource || technique_->writerOf(res, j) != i) continue;
        if (auto c = reader.readConditions.find(res); c != reader.readConditions.end() &&
            !conditionHolds(c->second, params_, std::string(technique_->stage(j).id()) + " reading " + res))
          continue;
        p.needed = true;  // a plain write, or an output read as a resource
        for (const auto& o : d.outputs)
          if (o.resourceName() == res) p.wanted->insert(o.name);
      }
    }
    if (!p.wanted->empty()) p.needed = true;
  }
  return plan;
}

static const OutputDesc* findDeclaredOutput(const StageDecl& decl, const std::string& name) {
  for (const auto& o : decl.outputs)
    if (o.name == name) return &o;
  return nullptr;
}

bool StepCursor::ranForLess(int stage, const std::optional<std::set<std::string>>& wanted) const {
  const auto& ran = records_.at(stage).wanted;
  if (!ran) return false;  // it computed everything
  const StageDecl& d = technique_->decl(stage);
  for (const auto& o : d.outputs) {
    const bool wantedNow = !wanted || wanted->count(o.name);
    if (wantedNow && o.onDemand && !ran->count(o.name)) return true;
  }
  return false;
}

bool StepCursor::outputComputed(int stage, const std::string& output) const {
  const StageState s = records_.at(stage).state;
  return (s == StageState::Done || s == StageState::Partial) && outputHeld(stage, output);
}

bool StepCursor::outputHeld(int stage, const std::string& output) const {
  const StageRecord& r = records_.at(stage);
  if (r.state == StageState::NotRun) return false;
  if (!r.wanted || r.wanted->count(output)) return true;
  const OutputDesc* o = findDeclaredOutput(technique_->decl(stage), output);
  return o && !o->onDemand;
}

int StepCursor::nextToRun(int last) const {
  const std::vector<StagePlan> p = plan();
  for (int i = 0; i <= std::min(last, stageCount() - 1); ++i) {
    if (!p[i].needed) continue;
    if (records_[i].state != StageState::Done || ranForLess(i, p[i].wanted)) return i;
  }
  return -1;
}

void StepCursor::runNeeded(int last, const std::vector<StagePlan>& p) {
  for (int i = 0; i <= last; ++i) {
    if (!p[i].needed) continue;
    if (records_[i].state == StageState::Done && ranForLess(i, p[i].wanted)) markStale(i);
    if (records_[i].state != StageState::Done) runStage(i, std::numeric_limits<int>::max(), p[i].wanted);
  }
}

void StepCursor::runThrough(int last) {
  if (!scene_) throw Error("no scene loaded");
  if (std::string excess = resourceBudgetExcess(); !excess.empty()) throw Error(excess);
  runNeeded(std::min(last, stageCount() - 1), plan());
}

int StepCursor::runIteration(int stage, bool everyOutput) {
  if (!scene_) throw Error("no scene loaded");
  if (std::string excess = resourceBudgetExcess(); !excess.empty()) throw Error(excess);
  // The stepped stage is wanted whole (or for what the demand wants of it), with everything it reads.
  const std::vector<StagePlan> p = plan(everyOutput ? stage : -1);
  if (stage > 0) runNeeded(stage - 1, p);
  if (records_.at(stage).state == StageState::Done && ranForLess(stage, p[stage].wanted)) markStale(stage);
  int next = records_.at(stage).state == StageState::Partial ? records_[stage].iterationsRun : 0;
  runStage(stage, next + 1, p[stage].wanted);
  return next;
}

void StepCursor::runStage(int i, int untilIteration, const std::optional<std::set<std::string>>& wanted) {
  StageRecord& r = records_.at(i);
  Stage& stage = technique_->stage(i);
  const int total = stage.iterations(params_);
  int first = 0;
  if (r.state == StageState::Partial) {
    first = r.iterationsRun;
  } else {
    r.stats.clear();
    r.cpuMs = r.gpuMs = 0.0;
    r.iterationsRun = 0;
  }
  r.iterationsTotal = total;
  untilIteration = std::min(untilIteration, total);
  board_.setMemoryBudget(size_t(params_.getInt(memoryBudgetParam().name)) << 20);
  // A Partial stage continues with what it started with.
  if (r.state != StageState::Partial) r.wanted = wanted;
  StageContext ctx{*scene_, *gpuScene_, params_, board_, shaders_, view_, r.stats, 0,
                   r.wanted ? &*r.wanted : nullptr};
  GLDebugScope scope("stage " + technique_->id() + "/" + stage.id());
  GpuTimer timer(technique_->id() + "/" + stage.id() + ".timer");
  auto t0 = std::chrono::steady_clock::now();
  timer.begin();
  for (int it = first; it < untilIteration; ++it) {
    ctx.iteration = it;
    stage.execute(ctx);
  }
  timer.end();
  glFinish();
  auto t1 = std::chrono::steady_clock::now();
  // A stepped stage's times add up over its iterations.
  r.cpuMs += std::chrono::duration<double, std::milli>(t1 - t0).count();
  r.gpuMs += timer.milliseconds();
  r.iterationsRun = untilIteration;
  r.state = untilIteration >= total ? StageState::Done : StageState::Partial;
  markReadersStale(i);  // stages after this one now depend on changed data
}

}  // namespace voxlab
