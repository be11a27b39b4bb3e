#include "gpu/gl_debug.h"

#include <map>
#include <mutex>
#include <utility>

#include "core/log.h"

namespace voxlab {
namespace {

struct DebugState {
  std::mutex mutex;
  std::vector<GLDebugLogEntry> log;            // distinct messages in order of arrival
  std::map<std::string, size_t> indexOf;       // describe() -> index into log
  std::vector<GLDebugMessage> failures;        // since the last takeGLFailures()
  size_t failureCount = 0;
};

DebugState& state() {
  static DebugState s;
  return s;
}

thread_local std::vector<std::string> scopes;

const char* severityName(GLenum s) {
  switch (s) {
    case GL_DEBUG_SEVERITY_HIGH: return "high";
    case GL_DEBUG_SEVERITY_MEDIUM: return "medium";
    case GL_DEBUG_SEVERITY_LOW: return "low";
    default: return "notification";
  }
}

const char* typeName(GLenum t) {
  switch (t) {
    case GL_DEBUG_TYPE_ERROR: return "error";
    case GL_DEBUG_TYPE_DEPRECATED_BEHAVIOR: return "deprecated";
    case GL_DEBUG_TYPE_UNDEFINED_BEHAVIOR: return "undefined behaviour";
    case GL_DEBUG_TYPE_PORTABILITY: return "portability";
    case GL_DEBUG_TYPE_PERFORMANCE: return "performance";
    case GL_DEBUG_TYPE_MARKER: return "marker";
    default: return "other";
  }
}

std::string currentScope() {
  std::string s;
  for (const auto& part : scopes) s += (s.empty() ? "" : " > ") + part;
  return s;
}

void GLAPIENTRY onDebugMessage(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei length,
                               const GLchar* message, const void*) {
  if (severity == GL_DEBUG_SEVERITY_NOTIFICATION) return;
  if (type == GL_DEBUG_TYPE_PUSH_GROUP || type == GL_DEBUG_TYPE_POP_GROUP) return;
  GLDebugMessage m;
  m.source = source;
  m.type = type;
  m.severity = severity;
  m.id = id;
  m.text = length >= 0 ? std::string(message, size_t(length)) : std::string(message);
  while (!m.text.empty() && (m.text.back() == '\n' || m.text.back() == ' ')) m.text.pop_back();
  m.scope = currentScope();
  const std::string line = m.describe();
  // The shader compiler's messages repeat the info log, which ShaderLibrary reports itself as
  // file:line errors (a failed compile is an Error there, a kept last good program in the viewer).
  const bool compiler = source == GL_DEBUG_SOURCE_SHADER_COMPILER;
  const bool failure = !compiler && (severity == GL_DEBUG_SEVERITY_HIGH || severity == GL_DEBUG_SEVERITY_MEDIUM);
  bool first = false;
  {
    DebugState& s = state();
    std::lock_guard<std::mutex> lock(s.mutex);
    auto [it, fresh] = s.indexOf.emplace(line, s.log.size());
    if (fresh) s.log.push_back({m, 0});
    ++s.log[it->second].count;
    first = fresh;
    if (failure) {
      s.failures.push_back(m);
      ++s.failureCount;
    }
  }
  if (!first) return;  // each distinct message is printed once
  if (failure) log::warn(line);
  else if (compiler) log::debug(line);
  else log::info(line);
}

}  // namespace

const char* glDebugSeverityName(GLenum severity) { return severityName(severity); }

bool isGLFailure(const GLDebugMessage& m) {
  return m.source != GL_DEBUG_SOURCE_SHADER_COMPILER &&
         (m.severity == GL_DEBUG_SEVERITY_HIGH || m.severity == GL_DEBUG_SEVERITY_MEDIUM);
}

GLObjectCounts liveGLObjects() {
  auto count = [](GLuint fresh, GLboolean (*is)(GLuint)) {
    int n = 0;
    for (GLuint id = 1; id < fresh; ++id) n += is(id) == GL_TRUE;
    return n;
  };
  GLObjectCounts c;
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &id);
  c.textures = count(id, [](GLuint i) { return glIsTexture(i); });
  glDeleteTextures(1, &id);
  glCreateBuffers(1, &id);
  c.buffers = count(id, [](GLuint i) { return glIsBuffer(i); });
  glDeleteBuffers(1, &id);
  glCreateFramebuffers(1, &id);
  c.framebuffers = count(id, [](GLuint i) { return glIsFramebuffer(i); });
  glDeleteFramebuffers(1, &id);
  glCreateVertexArrays(1, &id);
  c.vertexArrays = count(id, [](GLuint i) { return glIsVertexArray(i); });
  glDeleteVertexArrays(1, &id);
  id = glCreateProgram();  // programs share their names with shaders
  c.programs = count(id, [](GLuint i) { return glIsProgram(i); });
  glDeleteProgram(id);
  glCreateQueries(GL_TIME_ELAPSED, 1, &id);
  c.queries = count(id, [](GLuint i) { return glIsQuery(i); });
  glDeleteQueries(1, &id);
  return c;
}

std::string GLObjectCounts::describe() const {
  return std::to_string(textures) + " textures, " + std::to_string(buffers) + " buffers, " + std::to_string(framebuffers) +
         " framebuffers, " + std::to_string(vertexArrays) + " vertex arrays, " + std::to_string(programs) +
         " programs, " + std::to_string(queries) + " queries";
}

std::string GLDebugMessage::describe() const {
  std::string s = std::string("GL ") + typeName(type) + " (" + severityName(severity) + "): " + text;
  if (!scope.empty()) s += " [in " + scope + "]";
  return s;
}

void installDebugOutput() {
  glEnable(GL_DEBUG_OUTPUT);
  glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
  glDebugMessageCallback(onDebugMessage, nullptr);
  glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, nullptr, GL_TRUE);
}

GLDebugScope::GLDebugScope(const std::string& what) {
  scopes.push_back(what);
  if (glPushDebugGroup) glPushDebugGroup(GL_DEBUG_SOURCE_APPLICATION, 0, -1, what.c_str());
}

GLDebugScope::~GLDebugScope() {
  if (glPopDebugGroup) glPopDebugGroup();
  scopes.pop_back();
}

std::vector<GLDebugMessage> takeGLFailures() {
  DebugState& s = state();
  std::lock_guard<std::mutex> lock(s.mutex);
  return std::exchange(s.failures, {});
}

size_t glFailureCount() {
  DebugState& s = state();
  std::lock_guard<std::mutex> lock(s.mutex);
  return s.failureCount;
}

std::vector<GLDebugLogEntry> glDebugLog() {
  DebugState& s = state();
  std::lock_guard<std::mutex> lock(s.mutex);
  return s.log;
}

}  // namespace voxlab
