#include "gpu/shader_library.h"

#include <functional>
#include <regex>
#include <set>
#include <sstream>

#include <glm/gtc/type_ptr.hpp>

#include "core/paths.h"

namespace voxlab {
namespace fs = std::filesystem;

namespace {

GLenum stageTypeOf(const std::string& file) {
  auto has = [&](const char* ext) { return file.find(ext) != std::string::npos; };
  if (has(".vert.")) return GL_VERTEX_SHADER;
  if (has(".geom.")) return GL_GEOMETRY_SHADER;
  if (has(".frag.")) return GL_FRAGMENT_SHADER;
  if (has(".comp.")) return GL_COMPUTE_SHADER;
  throw ShaderError("shader file '" + file + "' has no stage extension (.vert/.geom/.frag/.comp.glsl)");
}

std::string keyOf(const std::vector<std::string>& files, const std::string& defines) {
  std::string k;
  for (const auto& f : files) k += f + "|";
  return k + defines;
}

// Every file's lines are numbered from kFileLineBase * its index in the file table (the #line
// directives below), because Mesa reports the line but not the source-string number of an error.
constexpr long kFileLineBase = 100000;

// Rewrites driver messages "S:L(C): text" (Mesa) or "S(L) : text" (NVIDIA) to "file:L: text".
std::string mapLog(const std::string& log, const std::vector<std::string>& fileTable) {
  static const std::regex mesa(R"(^(\d+):(\d+)\((\d+)\):\s*(.*)$)");
  static const std::regex nvidia(R"(^(\d+)\((\d+)\)\s*:\s*(.*)$)");
  std::istringstream in(log);
  std::string line, out;
  while (std::getline(in, line)) {
    std::smatch m;
    size_t file = 0;
    std::string rest, lineNo;
    if (std::regex_match(line, m, mesa)) {
      file = std::stoul(m[1]); lineNo = m[2]; rest = m[4];
    } else if (std::regex_match(line, m, nvidia)) {
      file = std::stoul(m[1]); lineNo = m[2]; rest = m[3];
    } else {
      if (!line.empty()) out += line + "\n";
      continue;
    }
    long encoded = std::stol(lineNo);
    if (encoded >= kFileLineBase) file = size_t(encoded / kFileLineBase);
    std::string name = file < fileTable.size() ? fileTable[file] : "?";
    out += name + ":" + std::to_string(encoded % kFileLineBase) + ": " + rest + "\n";
  }
  return out;
}

// The info log of a shader or program object.
std::string infoLog(GLuint object, bool isProgram) {
  GLint len = 0;
  if (isProgram)
    glGetProgramiv(object, GL_INFO_LOG_LENGTH, &len);
  else
    glGetShaderiv(object, GL_INFO_LOG_LENGTH, &len);
  std::string log(std::max(len, 1), '\0');
  if (isProgram)
    glGetProgramInfoLog(object, len, nullptr, log.data());
  else
    glGetShaderInfoLog(object, len, nullptr, log.data());
  return log.c_str();
}

std::string lineDirective(int line, int file) {
  return "#line " + std::to_string(kFileLineBase * file + line) + " " + std::to_string(file) + "\n";
}

std::string firstLine(const std::string& s) {
  auto nl = s.find('\n');
  return nl == std::string::npos ? s : s.substr(0, nl);
}

}  // namespace

ShaderLibrary::ShaderLibrary(std::string root) : root_(root.empty() ? projectPath("shaders") : root) {}

ShaderLibrary::~ShaderLibrary() {
  for (auto& [k, e] : programs_) glDeleteProgram(e.program);
}

std::string ShaderLibrary::expand(const std::string& file, const std::string& defines,
                                  std::vector<std::string>& fileTable) const {
  std::set<std::string> included;
  std::string out;
  bool versionSeen = false;
  // Recursive include with #line markers; source-string number = index in fileTable.
  std::function<void(const std::string&, const std::string&, int)> emit =
      [&](const std::string& name, const std::string& from, int fromLine) {
        if (included.count(name)) return;
        included.insert(name);
        std::string path = root_ + "/" + name;
        if (!fileExists(path)) {
          if (from.empty()) throw ShaderError("shader file '" + name + "' not found under " + root_);
          throw ShaderError(from + ":" + std::to_string(fromLine) + ": #include \"" + name + "\" not found");
        }
        std::string text = readTextFile(path);
        int id = int(fileTable.size());
        fileTable.push_back(name);
        std::istringstream in(text);
        std::string line;
        int lineNo = 0;
        static const std::regex includeRe(R"(^\s*#\s*include\s+\"([^\"]+)\"\s*$)");
        static const std::regex versionRe(R"(^\s*#\s*version\b.*$)");
        while (std::getline(in, line)) {
          ++lineNo;
          std::smatch m;
          if (std::regex_match(line, m, versionRe)) {
            if (!versionSeen) {
              out += line + "\n" + defines + (defines.empty() || defines.back() == '\n' ? "" : "\n");
              versionSeen = true;
            }
            out += lineDirective(lineNo + 1, id);
            continue;
          }
          if (std::regex_match(line, m, includeRe)) {
            emit(m[1].str(), name, lineNo);
            out += lineDirective(lineNo + 1, id);
            continue;
          }
          if (lineNo == 1) out += lineDirective(1, id);
          out += line + "\n";
        }
      };
  emit(file, "", 0);
  if (!versionSeen) throw ShaderError(file + ":1: the file has no #version line");
  return out;
}

GLuint ShaderLibrary::build(const std::vector<std::string>& files, const std::string& defines,
                            std::map<std::string, fs::file_time_type>& sources) {
  GLuint program = glCreateProgram();
  {
    std::string label;
    for (const auto& f : files) label += (label.empty() ? "" : " + ") + f;
    label = label.substr(0, 255);  // GL_MAX_LABEL_LENGTH is at least 256 (with the terminator)
    glObjectLabel(GL_PROGRAM, program, -1, label.c_str());
  }
  std::vector<GLuint> shaders;
  std::string errors;
  for (const auto& file : files) {
    std::vector<std::string> table;
    std::string src;
    try {
      src = expand(file, defines, table);
    } catch (...) {
      glDeleteProgram(program);
      throw;
    }
    for (const auto& f : table) {
      std::error_code ec;
      sources[f] = fs::last_write_time(root_ + "/" + f, ec);
    }
    GLuint shader = glCreateShader(stageTypeOf(file));
    glObjectLabel(GL_SHADER, shader, -1, file.c_str());
    const char* ptr = src.c_str();
    glShaderSource(shader, 1, &ptr, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) errors += mapLog(infoLog(shader, false), table);
    glAttachShader(program, shader);
    shaders.push_back(shader);
  }
  if (errors.empty()) {
    glLinkProgram(program);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
      std::string log = infoLog(program, true);
      std::string names;
      for (const auto& f : files) names += (names.empty() ? "" : " + ") + f;
      errors = names + ": link error: " + firstLine(log) + "\n";
    }
  }
  for (GLuint s : shaders) glDeleteShader(s);
  if (!errors.empty()) {
    glDeleteProgram(program);
    lastErrorLog_ = errors;
    throw ShaderError(firstLine(errors));
  }
  glObjectLabel(GL_PROGRAM, program, -1, files.back().c_str());
  return program;
}

GLuint ShaderLibrary::program(const std::vector<std::string>& files, const std::string& defines) {
  std::string key = keyOf(files, defines);
  auto it = programs_.find(key);
  if (it != programs_.end()) return it->second.program;
  Entry e;
  e.stageFiles = files;
  e.defines = defines;
  e.program = build(files, defines, e.sources);
  GLuint p = e.program;
  programs_[key] = std::move(e);
  return p;
}

std::vector<std::string> ShaderLibrary::reloadChanged(bool force) {
  std::vector<std::string> failures;
  lastReloadCount_ = 0;
  for (auto& [key, e] : programs_) {
    bool changed = force;
    for (const auto& [file, time] : e.sources) {
      std::error_code ec;
      auto now = fs::last_write_time(root_ + "/" + file, ec);
      if (ec || now != time) changed = true;
    }
    if (!changed) continue;
    std::map<std::string, fs::file_time_type> sources;
    try {
      GLuint p = build(e.stageFiles, e.defines, sources);
      glDeleteProgram(e.program);
      e.program = p;
      e.sources = sources;
      ++lastReloadCount_;
    } catch (const Error& err) {
      // Keep the last good program; remember the new times so the error is reported once.
      for (auto& [file, time] : e.sources) {
        std::error_code ec;
        time = fs::last_write_time(root_ + "/" + file, ec);
      }
      failures.push_back(err.what());
    }
  }
  return failures;
}

std::vector<std::string> ShaderLibrary::sourcesOf(const std::vector<std::string>& files,
                                                  const std::string& defines) const {
  std::vector<std::string> out;
  auto it = programs_.find(keyOf(files, defines));
  if (it != programs_.end())
    for (const auto& [f, t] : it->second.sources) out.push_back(f);
  return out;
}

void setUniform(GLuint p, const char* n, int v) { glProgramUniform1i(p, glGetUniformLocation(p, n), v); }
void setUniform(GLuint p, const char* n, unsigned v) { glProgramUniform1ui(p, glGetUniformLocation(p, n), v); }
void setUniform(GLuint p, const char* n, float v) { glProgramUniform1f(p, glGetUniformLocation(p, n), v); }
void setUniform(GLuint p, const char* n, const glm::vec2& v) { glProgramUniform2fv(p, glGetUniformLocation(p, n), 1, glm::value_ptr(v)); }
void setUniform(GLuint p, const char* n, const glm::vec3& v) { glProgramUniform3fv(p, glGetUniformLocation(p, n), 1, glm::value_ptr(v)); }
void setUniform(GLuint p, const char* n, const glm::vec4& v) { glProgramUniform4fv(p, glGetUniformLocation(p, n), 1, glm::value_ptr(v)); }
void setUniform(GLuint p, const char* n, const glm::ivec3& v) { glProgramUniform3iv(p, glGetUniformLocation(p, n), 1, glm::value_ptr(v)); }
void setUniform(GLuint p, const char* n, const glm::mat4& v) { glProgramUniformMatrix4fv(p, glGetUniformLocation(p, n), 1, GL_FALSE, glm::value_ptr(v)); }

void dispatchCompute(glm::ivec3 items, glm::ivec3 local) {
  glm::ivec3 groups = (items + local - 1) / local;
  // GL guarantees only 65535 work groups per dimension: a 1D dispatch past that is folded into
  // rows (y). Shaders of 1D work read their item as linearInvocation() (shaders/common/invocation.glsl)
  // and bound-check it, so the extra invocations of the last row do nothing.
  const int kMaxGroups = 65535;
  if (groups.y <= 1 && groups.z <= 1 && groups.x > kMaxGroups) {
    const int rows = (groups.x + kMaxGroups - 1) / kMaxGroups;
    groups = glm::ivec3((groups.x + rows - 1) / rows, rows, 1);
  }
  glDispatchCompute(std::max(groups.x, 1), std::max(groups.y, 1), std::max(groups.z, 1));
}

}  // namespace voxlab
