// abcube info: which GL paths work on this machine, and what they are.
#include <cstdio>
#include <string>

#include "cli/cli_common.hpp"
#include "base/parallel.hpp"
#include "gl/gl_context.hpp"
#include "gl/gl_passes.hpp"

namespace abcube {

namespace {

void print_context(const char* label, const GlContext* ctx, const std::string& why) {
  if (!ctx) {
    std::printf("  %-16s no: %s\n", label, why.c_str());
    return;
  }
  const GlInfo& i = ctx->info();
  std::printf("  %-16s yes\n", label);
  if (!i.egl_vendor.empty()) std::printf("    EGL vendor:    %s\n", i.egl_vendor.c_str());
  if (!i.egl_version.empty()) {
    std::printf("    %s %s\n", i.api == "osmesa" ? "library:      " : "EGL version:  ", i.egl_version.c_str());
  }
  std::printf("    GL_VERSION:    %s\n", i.gl_version.c_str());
  std::printf("    GL_RENDERER:   %s\n", i.gl_renderer.c_str());
  std::printf("    GL_VENDOR:     %s\n", i.gl_vendor.c_str());
  std::printf("    shadow-casting lights (gpu): %d\n", gl_shadow_light_limit());
}

}  // namespace

int run_info() {
  std::printf("abcube info\n");
  std::printf("threads: %d hardware\n", thread_count(0, SIZE_MAX));

  std::string why;
  const std::vector<EglDeviceInfo> devices = list_egl_devices(&why);
  std::printf("EGL devices: %zu%s%s\n", devices.size(), devices.empty() ? " (" : "",
              devices.empty() ? (why + ")").c_str() : "");
  for (const EglDeviceInfo& d : devices) {
    std::printf("  device %d: %s%s%s\n", d.index, d.software ? "software" : "hardware", d.drm_node.empty() ? "" : ", ",
                d.drm_node.c_str());
  }

  std::printf("GL paths (auto tries them in this order):\n");
  std::string auto_pick;  // what --gl auto opens, from the probes below
  bool any_device = false;
  for (const EglDeviceInfo& d : devices) {
    why.clear();
    auto ctx = create_egl_device_context(d.index, &why);
    const std::string label = "egl-device " + std::to_string(d.index);
    print_context(label.c_str(), ctx.get(), why);
    if (ctx && d.software) std::printf("    (software device: auto skips it)\n");
    if (ctx && !d.software && auto_pick.empty()) auto_pick = label;
    any_device = true;
  }
  if (!any_device) print_context("egl-device", nullptr, why);
  {
    why.clear();
    auto ctx = create_egl_surfaceless_context(&why);
    print_context("egl-surfaceless", ctx.get(), why);
    if (ctx && auto_pick.empty()) auto_pick = "egl-surfaceless";
  }
  {
    why.clear();
    auto ctx = create_osmesa_context(&why);
    print_context("osmesa", ctx.get(), why);
    if (ctx && auto_pick.empty()) auto_pick = "osmesa";
  }
  std::printf("--gl auto picks: %s\n", auto_pick.empty() ? "none (CPU only)" : auto_pick.c_str());
  return 0;
}

CommandRun add_info_command(CLI::App& app) {
  app.add_subcommand("info", "which GL paths work here, versions, renderer strings, threads");
  return run_info;
}

}  // namespace abcube
