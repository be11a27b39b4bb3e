// A headless session: an offscreen GL context, the shader library, a scene and a step cursor for
// one technique. `voxlab run`, `voxlab bench` and the test suites open one of these.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gpu/shader_library.h"
#include "graph/output.h"
#include "graph/step_cursor.h"
#include "platform/gl_context.h"
#include "scene/animation.h"

namespace voxlab {

struct RunRequest {
  std::string technique;
  std::string scene = "cornell-box";  // name in scenes/ or a path
  std::string until;                  // stage id; "" = all stages
  std::vector<std::string> sets;      // "name=value"
  int width = 512;
  int height = 512;
  int camera = 0;
  // A free camera instead of scene camera 'camera' (whose field of view it keeps): set by
  // --look-from/--look-at, as the viewer's orbit and fly cameras reproduce.
  std::optional<glm::vec3> lookFrom, lookAt;
};

// The camera of a request: scene camera 'camera', or one at lookFrom looking at lookAt.
// Throws Error when the two points coincide.
Camera requestCamera(const Scene& scene, const RunRequest& request);

class HeadlessSession {
 public:
  // Validates the whole request (technique, stage, parameters, scene file) before any GL work;
  // throws Error with one line naming the first problem.
  explicit HeadlessSession(const RunRequest& request);
  ~HeadlessSession();

  StepCursor& cursor() { return *cursor_; }
  // The scene the cursor renders, which the session loaded and alone holds non-const (posing an
  // animated scene moves it in place), and the animation read from its file in the same load.
  Scene& scene() { return *scene_; }
  const SceneAnimation& animation() const { return animation_; }
  const RunRequest& request() const { return request_; }
  double sceneLoadMs() const { return sceneLoadMs_; }  // wall time of loadScene()
  int untilStage() const { return untilStage_; }  // index of the last stage to run
  void run();                                     // runs stages 0..untilStage
  // What run() computes: every output (the default); with finalOnly, only what the final output
  // needs; with 'only', only what those outputs need (outputs on demand, StepCursor::demandOutputs).
  void demand(bool finalOnly, const std::vector<OutputAddress>& only = {});

  // Writes every computed output of every stage 0..untilStage (only the final output when
  // finalOnly; only the listed outputs, and levels, when 'only' is not empty) into dir, then
  // dir/manifest.json last. Returns the manifest.
  nlohmann::json writeOutputs(const std::string& dir, bool finalOnly = false,
                              const std::vector<OutputAddress>& only = {});
  nlohmann::json manifestHeader() const;  // technique, scene, parameters, GL strings, view

 private:
  RunRequest request_;
  double sceneLoadMs_ = 0.0;
  std::shared_ptr<Scene> scene_;
  SceneAnimation animation_;
  std::unique_ptr<GLContext> context_;
  std::unique_ptr<ShaderLibrary> shaders_;
  std::unique_ptr<StepCursor> cursor_;
  int untilStage_ = 0;
};

}  // namespace voxlab
