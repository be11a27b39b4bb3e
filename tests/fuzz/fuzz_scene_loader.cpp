// libFuzzer target for loadScene() (glTF JSON and GLB). Each input is written to a scratch file
// (loadScene reads paths; the loader tells GLB from JSON by the "glTF" magic, not the name) and
// loaded. A clean rejection is voxlab::Error; anything else - a crash, a sanitizer report, an
// escaping exception, a hang (-timeout) or an allocation over -malloc_limit_mb - is a finding.
// Run it through scripts/fuzz.sh; docs/testing.md#fuzzing-the-scene-loader.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "scene/animation.h"
#include "scene/scene.h"

namespace {

const std::string& scratchFile() {
  static const std::string path = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::filesystem::path dir = std::filesystem::path(tmp && *tmp ? tmp : "/tmp") /
                                ("voxlab-fuzz-" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    return (dir / "input.gltf").string();
  }();
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = scratchFile();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  }
  try {
    voxlab::SceneAnimation animation;
    voxlab::Scene scene = voxlab::loadScene(path, animation);
    // Touch what the renderers read so that inconsistent arrays show up as reports here.
    for (const voxlab::DrawRange& d : scene.draws) {
      if (d.material >= scene.materials.size()) std::abort();
      if (uint64_t(d.firstIndex) + d.indexCount > scene.indices.size()) std::abort();
    }
    for (uint32_t i : scene.indices)
      if (i >= scene.positions.size()) std::abort();
    // An animated scene is posed again halfway and past its end, as the frame loop does.
    if (animation.animated()) {
      voxlab::poseScene(scene, animation, 0.5f * animation.duration);
      voxlab::poseScene(scene, animation, animation.duration + 1.0f);
      for (const voxlab::MovingVertices& m : animation.moving)
        if (uint64_t(m.first) + m.count > scene.positions.size()) std::abort();
    }
  } catch (const voxlab::Error&) {
    // A clean one-line rejection: what the loader promises for bad files.
  }
  return 0;
}
