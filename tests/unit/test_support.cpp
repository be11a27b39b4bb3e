#include "test_support.h"

#include <map>

#include <glm/gtx/string_cast.hpp>

namespace voxlab::testing_support {

HeadlessSession& session(const RunRequest& r) {
  static std::map<std::string, std::unique_ptr<HeadlessSession>> sessions;
  std::string key = r.technique + "|" + r.scene + "|" + r.until + "|" + std::to_string(r.width) + "x" +
                    std::to_string(r.height) + "|" + std::to_string(r.camera);
  auto point = [](const glm::vec3& p) { return std::to_string(p.x) + "," + std::to_string(p.y) + "," + std::to_string(p.z); };
  if (r.lookFrom) key += "|from " + point(*r.lookFrom);
  if (r.lookAt) key += "|at " + point(*r.lookAt);
  for (const auto& s : r.sets) key += "|" + s;
  if (r.lookFrom) key += "|from " + glm::to_string(*r.lookFrom) + " at " + glm::to_string(*r.lookAt);
  auto& slot = sessions[key];
  if (!slot) {
    // One GL context per process: drop the others first (each session owns its context).
    sessions.clear();
    auto& fresh = sessions[key];
    fresh = std::make_unique<HeadlessSession>(r);
    fresh->run();
    return *fresh;
  }
  return *slot;
}

CapturedOutput capture(HeadlessSession& s, const std::string& stage, const std::string& output) {
  auto [index, desc] = s.cursor().technique().findOutput(stage, output);
  (void)index;
  return captureOutput(s.cursor().board(), *desc);
}

}  // namespace voxlab::testing_support
