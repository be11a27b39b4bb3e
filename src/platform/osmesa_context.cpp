// OSMesa offscreen context. libOSMesa is opened at run time (dlopen) so the binary does not link
// two GL implementations; the constants below are OSMesa's documented attribute values.
#include <dlfcn.h>

#include <vector>

#include "core/error.h"
#include "gpu/gl.h"
#include "platform/gl_context.h"

namespace voxlab {
namespace {

constexpr int kOsmesaFormat = 0x22;
constexpr int kOsmesaRgba = 0x1908;
constexpr int kOsmesaDepthBits = 0x30;
constexpr int kOsmesaStencilBits = 0x31;
constexpr int kOsmesaProfile = 0x33;
constexpr int kOsmesaCoreProfile = 0x34;
constexpr int kOsmesaMajor = 0x36;
constexpr int kOsmesaMinor = 0x37;

using OSMesaContextHandle = void*;
using CreateFn = OSMesaContextHandle (*)(const int*, OSMesaContextHandle);
using DestroyFn = void (*)(OSMesaContextHandle);
using MakeCurrentFn = unsigned char (*)(OSMesaContextHandle, void*, unsigned int, int, int);
using GetProcFn = void* (*)(const char*);

struct OSMesaApi {
  void* library = nullptr;
  CreateFn create = nullptr;
  DestroyFn destroy = nullptr;
  MakeCurrentFn makeCurrent = nullptr;
  GetProcFn getProc = nullptr;
};

const OSMesaApi& osmesa() {
  static OSMesaApi api = [] {
    OSMesaApi a;
    a.library = openFirstLibrary({"libOSMesa.so.8", "libOSMesa.so"});
    if (!a.library)
      throw Error("cannot load libOSMesa.so.8 for headless rendering; install libosmesa6 (scripts/setup.sh)");
    a.create = reinterpret_cast<CreateFn>(dlsym(a.library, "OSMesaCreateContextAttribs"));
    a.destroy = reinterpret_cast<DestroyFn>(dlsym(a.library, "OSMesaDestroyContext"));
    a.makeCurrent = reinterpret_cast<MakeCurrentFn>(dlsym(a.library, "OSMesaMakeCurrent"));
    a.getProc = reinterpret_cast<GetProcFn>(dlsym(a.library, "OSMesaGetProcAddress"));
    if (!a.create || !a.destroy || !a.makeCurrent || !a.getProc)
      throw Error("libOSMesa lacks OSMesaCreateContextAttribs; Mesa 11.2 or newer is needed");
    return a;
  }();
  return api;
}

class OSMesaContext final : public GLContext {
 public:
  OSMesaContext() : buffer_(4 * 4 * 4) {
    const int attribs[] = {kOsmesaFormat, kOsmesaRgba, kOsmesaDepthBits, 24, kOsmesaStencilBits, 8,
                           kOsmesaProfile, kOsmesaCoreProfile, kOsmesaMajor, 4, kOsmesaMinor, 5, 0};
    handle_ = osmesa().create(attribs, nullptr);
    if (!handle_) throw Error("OSMesa could not create an OpenGL 4.5 core context (llvmpipe needed)");
    makeCurrent();
    loadGL(osmesa().getProc);
  }
  ~OSMesaContext() override { osmesa().destroy(handle_); }
  void makeCurrent() override {
    // The window-system buffer is never drawn to (the renderer uses its own FBOs); 4x4 is enough.
    if (!osmesa().makeCurrent(handle_, buffer_.data(), GL_UNSIGNED_BYTE, 4, 4))
      throw Error("OSMesaMakeCurrent failed");
  }
  const char* kind() const override { return "osmesa"; }

 private:
  OSMesaContextHandle handle_ = nullptr;
  std::vector<unsigned char> buffer_;
};

}  // namespace

std::unique_ptr<GLContext> createOsmesaContext() { return std::make_unique<OSMesaContext>(); }

}  // namespace voxlab
