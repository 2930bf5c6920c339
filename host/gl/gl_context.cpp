#include "gl/gl_context.hpp"

#include <glad/gl.h>

#include <cstdlib>

#include "base/error.hpp"

namespace abcube {

bool parse_gl_choice(const std::string& s, GlChoice* out) {
  static const std::pair<const char*, GlChoice> names[] = {
      {"auto", GlChoice::automatic},        {"egl", GlChoice::egl},
      {"egl-device", GlChoice::egl_device}, {"egl-surfaceless", GlChoice::egl_surfaceless},
      {"osmesa", GlChoice::osmesa},         {"none", GlChoice::none}};
  for (const auto& [name, value] : names) {
    if (s == name) {
      *out = value;
      return true;
    }
  }
  return false;
}

namespace {
int device_from_environment(int device_index) {
  if (device_index >= 0) return device_index;
  const char* env = std::getenv("ABCUBE_EGL_DEVICE");
  if (!env || !*env) return -1;
  char* end = nullptr;
  const long v = std::strtol(env, &end, 10);
  if (*end != '\0' || v < 0) throw InputError(std::string("ABCUBE_EGL_DEVICE: not a device index: ") + env);
  return static_cast<int>(v);
}
}  // namespace

void read_gl_strings(GlInfo* info) {
  auto get = [](GLenum name) {
    const GLubyte* s = glGetString(name);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string();
  };
  info->gl_version = get(GL_VERSION);
  info->gl_renderer = get(GL_RENDERER);
  info->gl_vendor = get(GL_VENDOR);
}

std::unique_ptr<GlContext> open_gl_context(GlChoice choice, int device_index, std::string* log) {
  const bool uses_devices = choice == GlChoice::automatic || choice == GlChoice::egl || choice == GlChoice::egl_device;
  if (device_index >= 0 && !uses_devices) {
    throw InputError("--gl-device applies to EGL devices only (--gl auto, egl or egl-device)");
  }
  if (uses_devices) device_index = device_from_environment(device_index);
  if (device_index >= 0) choice = GlChoice::egl_device;  // a named device is forced
  std::string why;
  std::unique_ptr<GlContext> ctx;
  auto note = [&](const char* api) {
    if (log) *log += std::string(api) + ": " + why + "\n";
  };
  switch (choice) {
    case GlChoice::none: return nullptr;
    case GlChoice::egl_device:
      if ((ctx = create_egl_device_context(device_index, &why))) return ctx;
      throw RuntimeFailure("--gl egl-device failed: " + why);
    case GlChoice::egl_surfaceless:
      if ((ctx = create_egl_surfaceless_context(&why))) return ctx;
      throw RuntimeFailure("--gl egl-surfaceless failed: " + why);
    case GlChoice::osmesa:
      if ((ctx = create_osmesa_context(&why))) return ctx;
      throw RuntimeFailure("--gl osmesa failed: " + why);
    case GlChoice::egl: {
      // EGL in whichever form works: a hardware device, else surfaceless.
      if ((ctx = create_egl_device_context(device_index, &why))) return ctx;
      const std::string device_why = why;
      if ((ctx = create_egl_surfaceless_context(&why))) return ctx;
      throw RuntimeFailure("--gl egl failed: device: " + device_why + "; surfaceless: " + why);
    }
    case GlChoice::automatic:
      if ((ctx = create_egl_device_context(device_index, &why))) return ctx;
      note("egl-device");
      if ((ctx = create_egl_surfaceless_context(&why))) return ctx;
      note("egl-surfaceless");
      if ((ctx = create_osmesa_context(&why))) return ctx;
      note("osmesa");
      if (log && !log->empty() && log->back() == '\n') log->pop_back();
      return nullptr;
  }
  return nullptr;
}

std::string describe_gl(const GlContext* ctx) {
  if (!ctx) return "none (CPU only)";
  return ctx->info().gl_renderer + " (" + ctx->info().api + ")";
}

}  // namespace abcube
