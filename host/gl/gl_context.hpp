// Headless OpenGL contexts: one small class per context API behind one interface.
//
// `--gl auto` tries, in order: an EGL device with a hardware renderer (how a GPU is picked
// on NVIDIA servers), EGL on Mesa's surfaceless platform, OSMesa, then none (CPU only).
// A forced path that fails is an error naming the reason, never a silent fallback.
// Every context is GL 4.5 core (the minimum abcube needs: glClipControl for the infinite
// reversed-Z projection, SSBOs, compute shaders in tests) and renders only into FBOs.
#pragma once
#include <memory>
#include <string>
#include <vector>

namespace abcube {

enum class GlChoice { automatic, egl, egl_device, egl_surfaceless, osmesa, none };
bool parse_gl_choice(const std::string& s, GlChoice* out);

struct GlInfo {
  std::string api;          // "egl-device", "egl-surfaceless", "osmesa"
  std::string egl_vendor;   // empty for OSMesa
  std::string egl_version;  // or the OSMesa library name
  std::string gl_version, gl_renderer, gl_vendor;
  int device_index = -1;  // EGL device used, -1 if none
};

class GlContext {
 public:
  virtual ~GlContext() = default;
  const GlInfo& info() const { return info_; }

 protected:
  GlInfo info_;
};

// An EGL device as enumerated by EGL_EXT_device_enumeration.
struct EglDeviceInfo {
  int index = 0;
  std::string extensions;  // device extension string
  std::string drm_node;    // EGL_DRM_DEVICE_FILE_EXT where known
  bool software = false;   // EGL_MESA_device_software
};

// Each factory returns nullptr and sets *why when the path does not work here.
// device_index < 0 picks the first device with a hardware renderer.
std::unique_ptr<GlContext> create_egl_device_context(int device_index, std::string* why);
std::unique_ptr<GlContext> create_egl_surfaceless_context(std::string* why);
std::unique_ptr<GlContext> create_osmesa_context(std::string* why);

// Fills gl_version, gl_renderer and gl_vendor from the current context ("" if GL has none).
void read_gl_strings(GlInfo* info);

// Whether a GL_RENDERER string names one of Mesa's software rasterizers (llvmpipe, softpipe,
// swrast): Mesa may serve a DRM device in software too (kms_swrast), so the renderer decides.
bool software_renderer(const std::string& renderer);

// EGL devices visible here (empty with *why set if enumeration is unavailable).
std::vector<EglDeviceInfo> list_egl_devices(std::string* why);

// Opens a context as `choice` says (see the top of this file). Returns nullptr for
// GlChoice::none, and for automatic when nothing works (then *log says why each failed).
// Throws RuntimeFailure when a forced path fails. device_index: --gl-device, or
// ABCUBE_EGL_DEVICE when < 0 and that variable is set; a named device forces the EGL
// device path under auto and egl too (it fails rather than fall back).
std::unique_ptr<GlContext> open_gl_context(GlChoice choice, int device_index, std::string* log);

// The renderer string for --stats: "GL_RENDERER (api)" or "none (CPU only)".
std::string describe_gl(const GlContext* ctx);

}  // namespace abcube
