// ShaderLibrary: GLSL programs built from files under shaders/.
//
// - A program is named by its stage files ("vct_grid/voxelize.vert.glsl", ...); the stage type
//   comes from the second extension (.vert .geom .frag .comp).
// - `#include "common/x.glsl"` (relative to shaders/) is resolved, each file once per stage.
// - Compile and link errors are rewritten from the driver's "0:12(5): error" form to
//   "vct_grid/cone_trace.comp.glsl:12: error ..." with the original file names.
// - Each program records every file it used; reloadChanged() rebuilds those whose files changed
//   and keeps the last good program when a rebuild fails (the viewer shows the error).
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/error.h"
#include "gpu/gl.h"

namespace voxlab {

class ShaderError : public Error {
 public:
  using Error::Error;
};

class ShaderLibrary {
 public:
  explicit ShaderLibrary(std::string root = "");
  ~ShaderLibrary();
  ShaderLibrary(const ShaderLibrary&) = delete;
  ShaderLibrary& operator=(const ShaderLibrary&) = delete;

  // The program for these stage files and defines ("#define X 1" lines). Built on first use.
  // Throws ShaderError ("file:line: message", first error only in what(); all in errorLog()).
  GLuint program(const std::vector<std::string>& files, const std::string& defines = "");

  // Rebuilds programs whose source files changed on disk (all of them if force). Returns one
  // message per program that failed; those keep their last good version.
  std::vector<std::string> reloadChanged(bool force = false);

  // Files (relative to the root) that the program for 'files' + 'defines' was built from.
  std::vector<std::string> sourcesOf(const std::vector<std::string>& files, const std::string& defines = "") const;

  // Full expanded source (with #line markers) of one stage file, for inspection.
  std::string expand(const std::string& file, const std::string& defines, std::vector<std::string>& fileTable) const;

  const std::string& root() const { return root_; }
  const std::string& lastErrorLog() const { return lastErrorLog_; }
  int lastReloadCount() const { return lastReloadCount_; }  // programs rebuilt by the last reloadChanged()
  int programCount() const { return int(programs_.size()); }

 private:
  struct Entry {
    GLuint program = 0;
    std::vector<std::string> stageFiles;
    std::string defines;
    std::map<std::string, std::filesystem::file_time_type> sources;  // file -> mtime when built
  };
  GLuint build(const std::vector<std::string>& files, const std::string& defines,
               std::map<std::string, std::filesystem::file_time_type>& sources);
  std::string root_;
  std::map<std::string, Entry> programs_;  // key: files + defines
  std::string lastErrorLog_;
  int lastReloadCount_ = 0;
};

// Uniform setters by name (no-ops for names the linker removed).
void setUniform(GLuint program, const char* name, int v);
void setUniform(GLuint program, const char* name, unsigned v);
void setUniform(GLuint program, const char* name, float v);
void setUniform(GLuint program, const char* name, const glm::vec2& v);
void setUniform(GLuint program, const char* name, const glm::vec3& v);
void setUniform(GLuint program, const char* name, const glm::vec4& v);
void setUniform(GLuint program, const char* name, const glm::ivec3& v);
void setUniform(GLuint program, const char* name, const glm::mat4& v);

// Dispatches ceil(n / local) groups per axis.
void dispatchCompute(glm::ivec3 items, glm::ivec3 localSize);

}  // namespace voxlab
