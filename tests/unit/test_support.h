// Shared helpers for tests that need the GPU pipeline: one headless session per distinct request,
// kept for the life of the test process (an OSMesa context is created once).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "run/session.h"
#include "capture/capture.h"

namespace voxlab::testing_support {

// Runs (once per process, cached by its arguments) the technique up to 'until' on 'scene'.
HeadlessSession& session(const RunRequest& request);
// A new session for 'request' that has not run yet (for tests that set a demand or parameters
// first); the cached sessions are dropped, as session() does, since a process holds one context.
HeadlessSession& freshSession(const RunRequest& request);
// Loading 'path' must throw Error in one line naming the file and containing 'expected'.
void expectSceneRejected(const std::string& path, const std::string& expected);
// Captures an output of a session's technique ("stage", "output").
CapturedOutput capture(HeadlessSession& s, const std::string& stage, const std::string& output);

// Writes TempDir/voxlab-<name>/<name>.gltf (and its .bin) and returns its path: a 2 x 2 m floor of
// albedo 0.5 at y = 0 (+y up), a wall as a closed box at x 0.60..0.62, y 0..0.5, z -0.2..0.2, a
// camera 2.5 m above the origin looking straight down (yfov 0.9), and one KHR_lights_punctual
// light: 'lightJson' is its entry ({"type": ..., "intensity": ...}), 'lightNodeJson' the members
// of its node ("\"translation\":[...]" and/or "\"rotation\":[...]").
std::string writeFloorAndWallScene(const std::string& name, const std::string& lightJson,
                                   const std::string& lightNodeJson);

}  // namespace voxlab::testing_support
