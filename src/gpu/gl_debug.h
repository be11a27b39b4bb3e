// GL debug output (KHR_debug) for every context: messages are collected with the scope they
// happened in (the stage running, the object being created: GLDebugScope), printed once per
// distinct message, and errors of severity high or medium are kept so that tests fail on them.
//
// - Headless and windowed runs: each distinct message is printed once to stderr (high/medium as
//   warnings, low at VOXLAB_LOG=info); notifications are ignored, and the shader compiler's
//   messages are not failures (ShaderLibrary reports compile errors as file:line Errors).
// - Tests: tests/unit/test_main.cpp fails any test after which takeGLFailures() is not empty;
//   commands exit with status 3 at the end when VOXLAB_GL_ERRORS_FATAL=1 (set for every CTest
//   test) and a high/medium message arrived (app/main.cpp).
#pragma once
#include <string>
#include <vector>

#include "gpu/gl.h"

namespace voxlab {

struct GLDebugMessage {
  GLenum source = 0, type = 0, severity = 0;
  GLuint id = 0;
  std::string text;   // the driver's message
  std::string scope;  // innermost GLDebugScope when it arrived: "stage vct-grid/mipmap > texture 'radiance'"
  std::string describe() const;  // one line: severity, type, message, scope
};

// Enables synchronous debug output on the current context with voxlab's callback. Called by
// loadGL() for every context (platform/gl_context.cpp).
void installDebugOutput();

// Names what the following GL calls work on, for the messages they cause (and as a debug group
// for GL tools). Nest freely; RAII.
class GLDebugScope {
 public:
  explicit GLDebugScope(const std::string& what);
  ~GLDebugScope();
  GLDebugScope(const GLDebugScope&) = delete;
  GLDebugScope& operator=(const GLDebugScope&) = delete;
};

// High- and medium-severity messages since the last call (and forgets them).
std::vector<GLDebugMessage> takeGLFailures();
// High- and medium-severity messages since the process started.
size_t glFailureCount();
// Every distinct message so far (with repeats counted), for a log panel.
struct GLDebugLogEntry {
  GLDebugMessage message;
  int count = 0;
};
std::vector<GLDebugLogEntry> glDebugLog();
// "high", "medium", "low", "notification"; and whether a message counts as a failure (high or
// medium, not from the shader compiler), as takeGLFailures() counts them.
const char* glDebugSeverityName(GLenum severity);
bool isGLFailure(const GLDebugMessage& m);

// GL objects alive in the current context, by kind: names 1..N probed with glIs*, N a fresh
// name of that kind (created and deleted for the count). For leak checks (the viewer's soak).
struct GLObjectCounts {
  int textures = 0, buffers = 0, framebuffers = 0, vertexArrays = 0, programs = 0, queries = 0;
  int total() const { return textures + buffers + framebuffers + vertexArrays + programs + queries; }
  std::string describe() const;  // "12 textures, 30 buffers, ..."
};
GLObjectCounts liveGLObjects();

}  // namespace voxlab
