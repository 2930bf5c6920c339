// EGL contexts: the device platform (EGL_EXT_platform_device) and Mesa's surfaceless
// platform (EGL_MESA_platform_surfaceless). No window, no pbuffer: the context is made
// current with EGL_NO_SURFACE (EGL_KHR_surfaceless_context) and renders into FBOs.
#include <glad/egl.h>
#include <glad/gl.h>

#include <cstring>
#include <sstream>

#include "gl/gl_context.hpp"

namespace abcube {

namespace {

bool has_extension(const char* list, const char* name) {
  if (!list) return false;
  const size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n) {
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  }
  return false;
}

std::string egl_error_name(EGLint e) {
  std::ostringstream s;
  s << "EGL error 0x" << std::hex << e;
  return s.str();
}

// glad 2 loads only EGL 1.0 before a display exists; load the client extensions first.
bool load_egl_client(std::string* why) {
  if (!gladLoaderLoadEGL(EGL_NO_DISPLAY)) {
    *why = "libEGL.so.1 not found or not loadable";
    return false;
  }
  return true;
}

class EglContext : public GlContext {
 public:
  ~EglContext() override {
    if (display_ != EGL_NO_DISPLAY) {
      // Release only our own context: another display's may be current on this thread.
      if (context_ != EGL_NO_CONTEXT && eglGetCurrentContext() == context_) {
        eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      }
      if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display_, context_);
      // The display stays initialised for the process: it is one per platform or device,
      // shared by every context on it (another Renderer's, on another thread, may still be
      // using it), and Mesa keeps memory at every eglInitialize/eglTerminate cycle, which
      // would grow with every Renderer made (bench_soak measures it).
      // eglInitialize on an initialised display is a no-op.
      eglReleaseThread();
    }
  }

  // Initialises `display`, creates a GL 4.5 core context and makes it current.
  bool start(EGLDisplay display, const char* api, std::string* why) {
    display_ = display;
    EGLint major = 0, minor = 0;
    if (display == EGL_NO_DISPLAY || !eglInitialize(display, &major, &minor)) {
      *why = "eglInitialize failed (" + egl_error_name(eglGetError()) + ")";
      display_ = EGL_NO_DISPLAY;
      return false;
    }
    // Reload now that the display's version and extensions are known (glad 2).
    if (!gladLoaderLoadEGL(display)) {
      *why = "glad could not load EGL entry points for the display";
      return false;
    }
    const char* dext = eglQueryString(display, EGL_EXTENSIONS);
    if (!has_extension(dext, "EGL_KHR_surfaceless_context")) {
      *why = "display lacks EGL_KHR_surfaceless_context";
      return false;
    }
    if (!eglBindAPI(EGL_OPENGL_API)) {
      *why = "eglBindAPI(EGL_OPENGL_API) failed (" + egl_error_name(eglGetError()) + ")";
      return false;
    }
    EGLConfig config = nullptr;
    if (!has_extension(dext, "EGL_KHR_no_config_context")) {
      // Device and surfaceless displays have no window configs (EGL's default type).
      const EGLint attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_NONE};
      EGLint count = 0;
      if (!eglChooseConfig(display, attribs, &config, 1, &count) || count < 1) {
        *why = "no EGL config with EGL_OPENGL_BIT";
        return false;
      }
    }
    const EGLint ctx_attribs[] = {
        EGL_CONTEXT_MAJOR_VERSION,           4,       EGL_CONTEXT_MINOR_VERSION, 5, EGL_CONTEXT_OPENGL_PROFILE_MASK,
        EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    context_ = eglCreateContext(display, config, EGL_NO_CONTEXT, ctx_attribs);
    if (context_ == EGL_NO_CONTEXT) {
      *why = "no OpenGL 4.5 core context (" + egl_error_name(eglGetError()) + ")";
      return false;
    }
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
      *why = "eglMakeCurrent failed (" + egl_error_name(eglGetError()) + ")";
      return false;
    }
    if (!gladLoadGL(reinterpret_cast<GLADloadfunc>(eglGetProcAddress))) {
      *why = "glad could not load OpenGL 4.5 core entry points";
      return false;
    }
    info_.api = api;
    const char* vendor = eglQueryString(display, EGL_VENDOR);
    info_.egl_vendor = vendor ? vendor : "";
    info_.egl_version = std::to_string(major) + "." + std::to_string(minor);
    read_gl_strings(&info_);
    return true;
  }

  void set_device(int index) { info_.device_index = index; }

 private:
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
};

std::vector<EGLDeviceEXT> query_devices(std::string* why) {
  if (!load_egl_client(why)) return {};
  const char* cext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  // EGL_EXT_device_base is the older name of enumeration + query together.
  const bool enumeration =
      has_extension(cext, "EGL_EXT_device_enumeration") || has_extension(cext, "EGL_EXT_device_base");
  if (!enumeration || !has_extension(cext, "EGL_EXT_platform_device") || !eglQueryDevicesEXT) {
    *why = "EGL_EXT_device_enumeration / EGL_EXT_platform_device not offered";
    return {};
  }
  EGLint count = 0;
  if (!eglQueryDevicesEXT(0, nullptr, &count) || count <= 0) {
    *why = "no EGL devices";
    return {};
  }
  std::vector<EGLDeviceEXT> devices(static_cast<size_t>(count));
  eglQueryDevicesEXT(count, devices.data(), &count);
  devices.resize(static_cast<size_t>(count));
  return devices;
}

EglDeviceInfo describe_device(EGLDeviceEXT device, int index) {
  EglDeviceInfo d;
  d.index = index;
  const char* ext = eglQueryDeviceStringEXT(device, EGL_EXTENSIONS);
  d.extensions = ext ? ext : "";
  d.software = has_extension(ext, "EGL_MESA_device_software");
  if (has_extension(ext, "EGL_EXT_device_drm")) {
    const char* node = eglQueryDeviceStringEXT(device, EGL_DRM_DEVICE_FILE_EXT);
    if (node) d.drm_node = node;
  }
  return d;
}

}  // namespace

std::vector<EglDeviceInfo> list_egl_devices(std::string* why) {
  std::vector<EglDeviceInfo> out;
  const std::vector<EGLDeviceEXT> devices = query_devices(why);
  for (size_t i = 0; i < devices.size(); ++i) out.push_back(describe_device(devices[i], static_cast<int>(i)));
  return out;
}

namespace {

std::unique_ptr<EglContext> start_device(EGLDeviceEXT device, int index, std::string* why) {
  EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, device, nullptr);
  auto ctx = std::make_unique<EglContext>();
  if (!ctx->start(display, "egl-device", why)) {
    *why = "device " + std::to_string(index) + ": " + *why;
    return nullptr;
  }
  ctx->set_device(index);
  return ctx;
}

}  // namespace

bool software_renderer(const std::string& renderer) {
  for (const char* name : {"llvmpipe", "softpipe", "swrast", "Software Rasterizer"}) {
    if (renderer.find(name) != std::string::npos) return true;
  }
  return false;
}

std::unique_ptr<GlContext> create_egl_device_context(int device_index, std::string* why) {
  const std::vector<EGLDeviceEXT> devices = query_devices(why);
  if (devices.empty()) return nullptr;
  if (device_index >= static_cast<int>(devices.size())) {
    *why = "EGL device " + std::to_string(device_index) + " requested, " + std::to_string(devices.size()) + " found";
    return nullptr;
  }
  if (device_index >= 0) {
    return start_device(devices[static_cast<size_t>(device_index)], device_index, why);
  }
  // No device named: the first that works with a hardware renderer.
  std::string tried;
  for (size_t i = 0; i < devices.size(); ++i) {
    const int index = static_cast<int>(i);
    if (describe_device(devices[i], index).software) {
      tried += (tried.empty() ? "" : ", ") + ("device " + std::to_string(index) + ": software");
      continue;
    }
    auto ctx = start_device(devices[i], index, why);
    if (ctx && !software_renderer(ctx->info().gl_renderer)) return ctx;
    tried += (tried.empty() ? "" : ", ") +
             (ctx ? "device " + std::to_string(index) + ": software renderer " + ctx->info().gl_renderer : *why);
  }
  *why = "no hardware EGL device (" + tried + "; choose one with --gl-device K)";
  return nullptr;
}

std::unique_ptr<GlContext> create_egl_surfaceless_context(std::string* why) {
  if (!load_egl_client(why)) return nullptr;
  const char* cext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!has_extension(cext, "EGL_MESA_platform_surfaceless") || !eglGetPlatformDisplayEXT) {
    *why = "EGL_MESA_platform_surfaceless not offered";
    return nullptr;
  }
  EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  auto ctx = std::make_unique<EglContext>();
  if (!ctx->start(display, "egl-surfaceless", why)) return nullptr;
  return ctx;
}

}  // namespace abcube
