// Platform: where a GL 4.5 core context comes from.
//
// The renderer never draws into a window's default framebuffer; it draws into its own framebuffer
// objects, and a window (when there is one) only presents. So the same pipeline runs headless
// (OSMesa on llvmpipe, the default here) and in the viewer (GLFW).
#pragma once
#include <initializer_list>
#include <memory>
#include <string>

namespace voxlab {

class GLContext {
 public:
  virtual ~GLContext() = default;
  virtual void makeCurrent() = 0;
  virtual const char* kind() const = 0;  // "osmesa", "egl", "glfw"
};

// An offscreen GL 4.5 core context, made current, with the GL loader initialised. The
// environment variable VOXLAB_GL picks where it comes from: "osmesa" (the default: OSMesa on
// llvmpipe) or "egl" (EGL without a surface: a GPU's EGL device when there is one, else Mesa's
// surfaceless platform). Throws Error naming what is missing and what would be valid.
std::unique_ptr<GLContext> createOffscreenContext();
std::unique_ptr<GLContext> createOsmesaContext();
std::unique_ptr<GLContext> createEglContext();

// dlopen()s the first of 'names' that loads (RTLD_NOW | RTLD_LOCAL); nullptr when none does.
void* openFirstLibrary(std::initializer_list<const char*> names);

// Loads GL entry points through 'getProc' and checks the version is at least 4.5; throws Error.
void loadGL(void* (*getProc)(const char*));

// GL_RENDERER and GL_VERSION of the current context.
std::string glRenderer();
std::string glVersion();

}  // namespace voxlab
