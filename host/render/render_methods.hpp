// What the method units (render/methods/) share: the map methods' pipeline (abuffer,
// zbuffer and envmap run it; hybrid runs it for the pixels the GPU is not exact on), the
// options of the map searches and of the GPU's camera pass, the exact tracer as the
// reference, and the stats every method writes alike. Each method's own passes are in its
// unit; what they read and write is the MethodContext (method_context.hpp).
#pragma once
#include <string>
#include <vector>

#include <abcube/render_options.hpp>
#include <nlohmann/json.hpp>

#include "base/error.hpp"
#include "gl/gl_context.hpp"
#include "render/method_context.hpp"

namespace abcube {

// A name the option table has checked (check_render_options) parsed into its enum.
template <class Enum>
Enum parse_checked(const std::string& value, bool (*parse)(const std::string&, Enum*)) {
  Enum e{};
  const bool known = parse(value, &e);
  ABCUBE_CHECK(known, "a checked option's value " + quote(value) + " has no enum value");
  return e;
}

// A pass of the render starts (0) or ends (1), for the progress callback when there is one.
void pass_progress(const MethodContext& mc, const char* pass, double done);

// The map searches' options (--search, --refine, --theta-max, --map-only, --refraction,
// --envmap-lookup, --resolve, the shading plan) into request->map, for `variant`.
void read_map_options(const RenderOptions& options, MapVariant variant, RenderRequest* request);
// --search-on into request->search_on (refuse_options_unused_by refuses gpu with the thesis
// mode).
void read_search_on(const RenderOptions& options, RenderRequest* request);
// --resolve-on into request->resolve_on.
void read_resolve_on(const RenderOptions& options, RenderRequest* request);
// The GPU camera pass's options (--gpu-*) into request->gpu.
void read_gpu_options(const RenderOptions& options, int max_depth, RenderRequest* request);
// The table's keys of what read_map_options reads for every variant (the cube map's N and
// plan, the searches, the shading plan, the resolve, the layer cap; refraction and the
// lookup are the variants' own), and of what read_gpu_options reads: the units' reads().
std::vector<std::string> map_option_keys();
std::vector<std::string> gpu_camera_option_keys();

// The map methods' passes: the camera's A-buffer, and the cube map only when something
// needs it (a reflecting or refracting material, a shadow-casting light), searched by the
// variant of request.map. `only` (optional): the pixels to render, the others black.
Image render_map_method(MethodContext& mc, const std::vector<uint8_t>* only = nullptr);

// What the GPU's exact camera pass rendered: per kind of surface, the path it took and why.
// `curved`: what curved mirrors and refraction took; `maps`: shadow maps were built.
nlohmann::json gpu_paths_json(const GlScene& gl, const RenderRequest& request, const std::string& curved, bool maps);

// The exact Whitted tracer; its stats go under `key` ("raytrace" or "reference").
Image render_reference(MethodContext& mc, const char* key);
// The image's error against the exact image (traced now, or --reference-image); PSNR.
double add_reference_error(MethodContext& mc, const Image& image);

// The GL's version and vendor, and its EGL vendor and device where it has them (its path and
// renderer are the RenderRecord's).
nlohmann::json gl_json(const GlContext& ctx);

// The scene as a render with `options` sees it: its camera and render settings with the
// options' overrides, checked (renderer.cpp). Shares the triangles.
SceneData scene_view(const SceneData& base, const RenderOptions& options);

}  // namespace abcube
