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
// Captures an output of a session's technique ("stage", "output").
CapturedOutput capture(HeadlessSession& s, const std::string& stage, const std::string& output);

}  // namespace voxlab::testing_support
