// Picks the offscreen platform (VOXLAB_GL) and loads the GL entry points of the current context.
#include "platform/gl_context.h"

#include <dlfcn.h>

#include <cstdlib>
#include <string>

#include "core/error.h"
#include "gpu/gl.h"
#include "gpu/gl_debug.h"

namespace voxlab {

void* openFirstLibrary(std::initializer_list<const char*> names) {
  for (const char* name : names)
    if (void* handle = dlopen(name, RTLD_NOW | RTLD_LOCAL)) return handle;
  return nullptr;
}

std::unique_ptr<GLContext> createOffscreenContext() {
  const char* e = std::getenv("VOXLAB_GL");
  const std::string which = e ? e : "";
  if (which.empty() || which == "osmesa") return createOsmesaContext();
  if (which == "egl") return createEglContext();
  throw Error("VOXLAB_GL='" + which + "' is not a GL platform; valid: osmesa (default), egl");
}

void loadGL(void* (*getProc)(const char*)) {
  int version = gladLoadGL(reinterpret_cast<GLADloadfunc>(getProc));
  if (!version) throw Error("could not load OpenGL entry points");
  int major = GLAD_VERSION_MAJOR(version), minor = GLAD_VERSION_MINOR(version);
  if (major < 4 || (major == 4 && minor < 5))
    throw Error("OpenGL 4.5 core is needed, the context offers " + std::to_string(major) + "." +
                std::to_string(minor));
  installDebugOutput();  // every context: KHR_debug messages are collected (gpu/gl_debug.h)
}

std::string glRenderer() {
  const GLubyte* s = glGetString(GL_RENDERER);
  return s ? reinterpret_cast<const char*>(s) : "";
}

std::string glVersion() {
  const GLubyte* s = glGetString(GL_VERSION);
  return s ? reinterpret_cast<const char*>(s) : "";
}

}  // namespace voxlab
