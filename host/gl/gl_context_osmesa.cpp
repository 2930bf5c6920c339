// OSMesa: Mesa's off-screen software context, the fallback where EGL is missing.
// libOSMesa is opened at run time (dlopen), so abcube runs on systems without it
// (Mesa 25.1 removed OSMesa); the constants below are those of GL/osmesa.h.
#include <dlfcn.h>
#include <glad/gl.h>

#include <vector>

#include "gl/gl_context.hpp"

namespace abcube {

namespace {

constexpr int OSMESA_FORMAT = 0x22;
constexpr int OSMESA_DEPTH_BITS = 0x30;
constexpr int OSMESA_PROFILE = 0x33;
constexpr int OSMESA_CORE_PROFILE = 0x34;
constexpr int OSMESA_CONTEXT_MAJOR_VERSION = 0x36;
constexpr int OSMESA_CONTEXT_MINOR_VERSION = 0x37;

using OSMesaContextHandle = void*;
using CreateContextAttribs = OSMesaContextHandle (*)(const int*, OSMesaContextHandle);
using MakeCurrent = unsigned char (*)(OSMesaContextHandle, void*, unsigned int, int, int);
using DestroyContext = void (*)(OSMesaContextHandle);
using GetProcAddress = GLADapiproc (*)(const char*);

// glad's loader callback with OSMesaGetProcAddress as its user pointer.
GLADapiproc osmesa_load(void* get_proc, const char* name) { return reinterpret_cast<GetProcAddress>(get_proc)(name); }

class OsmesaContext : public GlContext {
 public:
  ~OsmesaContext() override {
    if (context_ && destroy_) destroy_(context_);
    // libOSMesa stays loaded: Mesa does not support being unloaded and reloaded.
  }

  bool start(std::string* why) {
    const char* names[] = {"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"};
    for (const char* name : names) {
      if ((library_ = dlopen(name, RTLD_NOW | RTLD_LOCAL))) {
        info_.egl_version = name;
        break;
      }
    }
    if (!library_) {
      *why = "libOSMesa not found (Debian: libosmesa6; removed from Mesa 25.1)";
      return false;
    }
    auto create = reinterpret_cast<CreateContextAttribs>(dlsym(library_, "OSMesaCreateContextAttribs"));
    auto make_current = reinterpret_cast<MakeCurrent>(dlsym(library_, "OSMesaMakeCurrent"));
    destroy_ = reinterpret_cast<DestroyContext>(dlsym(library_, "OSMesaDestroyContext"));
    void* get_proc = dlsym(library_, "OSMesaGetProcAddress");
    if (!create || !make_current || !destroy_ || !get_proc) {
      *why = "libOSMesa lacks OSMesaCreateContextAttribs";
      return false;
    }
    const int attribs[] = {OSMESA_FORMAT,
                           GL_RGBA,
                           OSMESA_DEPTH_BITS,
                           24,
                           OSMESA_PROFILE,
                           OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION,
                           4,
                           OSMESA_CONTEXT_MINOR_VERSION,
                           5,
                           0};
    context_ = create(attribs, nullptr);
    if (!context_) {
      *why = "OSMesa could not create an OpenGL 4.5 core context";
      return false;
    }
    // OSMesa needs a colour buffer to be current; abcube itself renders into FBOs.
    if (!make_current(context_, buffer_.data(), GL_UNSIGNED_BYTE, 1, 1)) {
      *why = "OSMesaMakeCurrent failed";
      return false;
    }
    if (!gladLoadGLUserPtr(osmesa_load, get_proc)) {
      *why = "glad could not load OpenGL 4.5 core entry points";
      return false;
    }
    info_.api = "osmesa";
    read_gl_strings(&info_);
    return true;
  }

 private:
  void* library_ = nullptr;
  OSMesaContextHandle context_ = nullptr;
  DestroyContext destroy_ = nullptr;
  std::vector<unsigned char> buffer_ = std::vector<unsigned char>(4, 0);
};

}  // namespace

std::unique_ptr<GlContext> create_osmesa_context(std::string* why) {
  auto ctx = std::make_unique<OsmesaContext>();
  if (!ctx->start(why)) return nullptr;
  return ctx;
}

}  // namespace abcube
