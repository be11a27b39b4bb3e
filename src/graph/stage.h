// Stage: one inspectable step of a technique. A stage declares what it reads, what it writes
// (its outputs) and which parameters it takes; the viewer, the CLI, the snapshot suite, the
// benchmark and the lessons all work from that declaration alone.
#pragma once
#include <functional>
#include <initializer_list>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "graph/blackboard.h"
#include "graph/output.h"
#include "graph/param.h"

namespace voxlab {

struct Scene;
class GpuScene;
class ShaderLibrary;

// Resource names that are not on the blackboard but still carry dependencies.
inline constexpr const char* kViewResource = "@view";  // camera and output size

// Probes: parameters that point at one element for a stage to record (its probe-record outputs,
// OutputDesc::probeRecord). The viewer sets them when the user clicks an image of that space, for
// every stage that declares a probe there, and re-runs what went stale; no stage is named.
enum class ProbeSpace {
  Screen,  // a pixel of the camera images: x, y are fractions of the width / height (y from the top)
  Volume,  // a cell of a volume at a level: x, y, z cell indices (Int parameters) at 'level'
  Light,   // a texel of a light-space image (RSM, shadow map): x, y fractions, as Screen
};
const char* probeSpaceName(ProbeSpace space);  // "screen", "volume", "light"

struct ProbeDesc {
  ProbeSpace space = ProbeSpace::Screen;
  std::string x, y, z;  // names of parameters the stage declares (z: Volume only)
  std::string level;    // Volume: the parameter holding the cell's level ("" = level 0 cells)
  // Volume: the volume resource whose cells are meant ("" = any volume); Light: the light-space
  // image resource (required), e.g. "shadow-map".
  std::string resource;

  static ProbeDesc screen(std::string x, std::string y) { return {ProbeSpace::Screen, std::move(x), std::move(y), "", "", ""}; }
  static ProbeDesc volume(std::string x, std::string y, std::string z, std::string level = "", std::string resource = "") {
    return {ProbeSpace::Volume, std::move(x), std::move(y), std::move(z), std::move(level), std::move(resource)};
  }
  static ProbeDesc light(std::string x, std::string y, std::string image) {
    return {ProbeSpace::Light, std::move(x), std::move(y), "", "", std::move(image)};
  }
  std::vector<std::string> paramNames() const;  // the non-empty ones
};

struct ViewState;

// What a stage will allocate on the blackboard for given parameters and view, declared so that
// the whole technique can be sized (graph/resource_budget.h) before any GL allocation. A texture
// gives the exact TextureDesc its execute() passes to ensureTexture; a buffer its byte size. A
// pool's size is where it starts: it may grow to what the scene needs (e.g. voxel fragments).
struct ResourceDecl {
  std::string resource;
  std::function<TextureDesc(const ParamSet&, const ViewState&)> texture;  // set for textures
  std::function<size_t(const ParamSet&, const ViewState&)> bufferBytes;   // set for buffers
  bool pool = false;
};

struct StageDecl {
  std::vector<std::string> reads;     // resources (and kViewResource) this stage reads
  // Reads that happen only under a parameter condition ("param=value", "param>=number" or
  // "param>number", as conditionHolds reads them): outputs on demand follow such a read only when
  // it holds (the composite reads the soft-shadow image only when it is the chosen visibility, and
  // an indirect term only when its weight is above 0).
  std::map<std::string, std::string> readConditions;
  std::vector<std::string> writes;    // resources it writes that are not outputs
  std::vector<OutputDesc> outputs;    // resources it writes that can be inspected
  std::vector<ParamDesc> params;
  std::vector<ProbeDesc> probes;      // where its probe parameters point
  std::vector<ResourceDecl> resources;  // blackboard allocations, for the resource budget
};

class StageBuilder {
 public:
  explicit StageBuilder(StageDecl& decl) : decl_(decl) {}
  StageBuilder& read(const std::string& resource) { decl_.reads.push_back(resource); return *this; }
  StageBuilder& readView() { return read(kViewResource); }
  StageBuilder& readWhen(const std::string& resource, const std::string& condition) {
    decl_.readConditions[resource] = condition;
    return read(resource);
  }
  StageBuilder& write(const std::string& resource) { decl_.writes.push_back(resource); return *this; }
  OutputDesc& output(const std::string& name, OutputKind kind, Semantic semantic, const std::string& help);
  // Marks outputs declared above as written alongside what the final image needs
  // (OutputDesc::alongside); throws Error on a name not declared yet.
  StageBuilder& alongside(std::initializer_list<std::string> outputs);
  StageBuilder& param(const ParamDesc& p) { decl_.params.push_back(p); return *this; }
  // The named parameters (declared with param()) point at one element of 'probe.space'.
  StageBuilder& probe(const ProbeDesc& p) { decl_.probes.push_back(p); return *this; }
  // The blackboard texture / buffer 'resource' this stage allocates (see ResourceDecl).
  // pool: the desc is the starting size (the smallest the stage allocates); the stage grows it
  // from counts at run time (e.g. svo's brick pool), so the estimate is a lower bound.
  StageBuilder& texture(const std::string& resource,
                        std::function<TextureDesc(const ParamSet&, const ViewState&)> desc, bool pool = false) {
    decl_.resources.push_back({resource, std::move(desc), nullptr, pool});
    return *this;
  }
  StageBuilder& buffer(const std::string& resource, std::function<size_t(const ParamSet&, const ViewState&)> bytes,
                       bool pool = false) {
    decl_.resources.push_back({resource, nullptr, std::move(bytes), pool});
    return *this;
  }

 private:
  StageDecl& decl_;
};

// The camera and image size a run renders with.
struct ViewState {
  int width = 512;
  int height = 512;
  glm::vec3 position{0.0f};
  glm::mat4 view{1.0f};
  glm::mat4 projection{1.0f};
  glm::mat4 viewProjection() const { return projection * view; }
};

// Numbers a stage reports about what it did (counts, sizes); they go into the manifest.
using StageStats = std::map<std::string, double>;

struct StageContext {
  const Scene& scene;
  const GpuScene& gpuScene;
  const ParamSet& params;
  Blackboard& board;
  ShaderLibrary& shaders;
  const ViewState& view;
  StageStats& stats;
  int iteration = 0;  // 0..iterations()-1 for iterative stages
  // Outputs on demand: the names of this stage's outputs the run needs (demanded by the caller, or
  // read by a later stage that runs); null when every output is wanted. A stage computes an output
  // it declares onDemand (OutputDesc::onDemand) only when wants() says so, and then does not even
  // allocate it; every other output it computes whenever it runs.
  const std::set<std::string>* wantedOutputs = nullptr;
  bool wants(const std::string& output) const { return !wantedOutputs || wantedOutputs->count(output) != 0; }
};

class Stage {
 public:
  virtual ~Stage() = default;
  virtual const char* id() const = 0;     // "voxelize": short, stable, used in addresses
  virtual const char* title() const = 0;  // "Voxelize the scene"
  virtual const char* summary() const = 0;  // one or two sentences for the timeline and lessons
  virtual void declare(StageBuilder& b) const = 0;
  // Iterative stages (octree levels, propagation steps) return how many iterations they run;
  // execute() is called once per iteration with context.iteration set.
  virtual int iterations(const ParamSet&) const { return 1; }
  virtual void execute(StageContext& context) = 0;
  // A stage that keeps what it built between runs, to update it incrementally on the next one
  // (clipmap's update keeps the origins its atlas holds), drops it here, so its next run starts
  // from scratch. StepCursor::invalidateAll calls it: after a shader reload, and before each of
  // bench's timed runs (a timed run is a run from scratch).
  virtual void forgetHeldResults() {}
};

}  // namespace voxlab
