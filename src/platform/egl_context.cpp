// EGL offscreen context without any surface: on a machine with a GPU driver, the first EGL device
// that is not a software rasterizer (EGL_EXT_platform_device); otherwise Mesa's surfaceless
// platform (llvmpipe here). libEGL is opened at run time, like libOSMesa, so the binary starts
// without it and runs where it is missing. Selected by VOXLAB_GL=egl (platform/gl_context.h).
#include <dlfcn.h>

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>
#include <string>
#include <vector>

#include "core/error.h"
#include "gpu/gl.h"
#include "platform/gl_context.h"

namespace voxlab {
namespace {

struct EglApi {
  void* library = nullptr;
  PFNEGLGETPROCADDRESSPROC getProc = nullptr;
  PFNEGLINITIALIZEPROC initialize = nullptr;
  PFNEGLTERMINATEPROC terminate = nullptr;
  PFNEGLBINDAPIPROC bindApi = nullptr;
  PFNEGLCREATECONTEXTPROC createContext = nullptr;
  PFNEGLDESTROYCONTEXTPROC destroyContext = nullptr;
  PFNEGLMAKECURRENTPROC makeCurrent = nullptr;
  PFNEGLQUERYSTRINGPROC queryString = nullptr;
  PFNEGLGETERRORPROC getError = nullptr;
  PFNEGLGETPLATFORMDISPLAYEXTPROC platformDisplay = nullptr;
  PFNEGLQUERYDEVICESEXTPROC queryDevices = nullptr;
  PFNEGLQUERYDEVICESTRINGEXTPROC queryDeviceString = nullptr;
};

const EglApi& egl() {
  static EglApi api = [] {
    EglApi a;
    a.library = openFirstLibrary({"libEGL.so.1", "libEGL.so"});
    if (!a.library) throw Error("VOXLAB_GL=egl: cannot load libEGL.so.1; install libegl1 (scripts/setup.sh)");
    a.getProc = reinterpret_cast<PFNEGLGETPROCADDRESSPROC>(dlsym(a.library, "eglGetProcAddress"));
    if (!a.getProc) throw Error("VOXLAB_GL=egl: libEGL has no eglGetProcAddress");
    auto get = [&](auto& fn, const char* name) { fn = reinterpret_cast<std::decay_t<decltype(fn)>>(a.getProc(name)); };
    get(a.initialize, "eglInitialize");
    get(a.terminate, "eglTerminate");
    get(a.bindApi, "eglBindAPI");
    get(a.createContext, "eglCreateContext");
    get(a.destroyContext, "eglDestroyContext");
    get(a.makeCurrent, "eglMakeCurrent");
    get(a.queryString, "eglQueryString");
    get(a.getError, "eglGetError");
    get(a.platformDisplay, "eglGetPlatformDisplayEXT");
    get(a.queryDevices, "eglQueryDevicesEXT");
    get(a.queryDeviceString, "eglQueryDeviceStringEXT");
    if (!a.initialize || !a.createContext || !a.makeCurrent || !a.platformDisplay)
      throw Error("VOXLAB_GL=egl: libEGL lacks EGL 1.5 / EGL_EXT_platform_base");
    return a;
  }();
  return api;
}

bool hasExtension(const char* list, const char* name) {
  if (!list) return false;
  const size_t n = std::strlen(name);
  for (const char* p = std::strstr(list, name); p; p = std::strstr(p + n, name))
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

class EglContext final : public GLContext {
 public:
  EglContext() {
    const EglApi& e = egl();
    std::string tried;
    // Hardware devices first (a GPU's driver), then Mesa's surfaceless platform (llvmpipe).
    std::vector<std::pair<EGLenum, void*>> candidates;
    const char* clientExtensions = e.queryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (e.queryDevices && hasExtension(clientExtensions, "EGL_EXT_platform_device")) {
      EGLDeviceEXT devices[16];
      EGLint count = 0;
      if (e.queryDevices(16, devices, &count))
        for (EGLint i = 0; i < count; ++i) {
          const char* ext = e.queryDeviceString ? e.queryDeviceString(devices[i], EGL_EXTENSIONS) : nullptr;
          if (!hasExtension(ext, "EGL_MESA_device_software")) candidates.emplace_back(EGL_PLATFORM_DEVICE_EXT, devices[i]);
        }
    }
    if (hasExtension(clientExtensions, "EGL_MESA_platform_surfaceless"))
      candidates.emplace_back(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY);
    for (const auto& [platform, native] : candidates) {
      if (tryCreate(platform, native)) return;
      tried += (tried.empty() ? "" : ", ") + std::string(platform == EGL_PLATFORM_DEVICE_EXT ? "device" : "surfaceless");
    }
    throw Error("VOXLAB_GL=egl: no EGL display gave an OpenGL 4.5 core context (tried: " +
                (tried.empty() ? std::string("none available") : tried) + "); unset VOXLAB_GL to use OSMesa");
  }
  ~EglContext() override {
    egl().makeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    egl().destroyContext(display_, context_);
    egl().terminate(display_);
  }
  void makeCurrent() override {
    if (!egl().makeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
      throw Error("eglMakeCurrent failed (EGL error " + std::to_string(egl().getError()) + ")");
  }
  const char* kind() const override { return "egl"; }

 private:
  bool tryCreate(EGLenum platform, void* native) {
    const EglApi& e = egl();
    EGLDisplay d = e.platformDisplay(platform, native, nullptr);
    EGLint major = 0, minor = 0;
    if (d == EGL_NO_DISPLAY || !e.initialize(d, &major, &minor)) return false;
    // Surfaceless: no config and no surface (EGL_KHR_no_config_context, EGL_KHR_surfaceless_context).
    const char* ext = e.queryString(d, EGL_EXTENSIONS);
    if (!hasExtension(ext, "EGL_KHR_surfaceless_context") || !hasExtension(ext, "EGL_KHR_no_config_context") ||
        !e.bindApi(EGL_OPENGL_API)) {
      e.terminate(d);
      return false;
    }
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                              EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext c = e.createContext(d, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
    if (c == EGL_NO_CONTEXT) {
      e.terminate(d);
      return false;
    }
    display_ = d;
    context_ = c;
    makeCurrent();
    loadGL(reinterpret_cast<void* (*)(const char*)>(e.getProc));
    return true;
  }

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
};

}  // namespace

std::unique_ptr<GLContext> createEglContext() { return std::make_unique<EglContext>(); }

}  // namespace voxlab
