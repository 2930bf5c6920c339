// The passes of each method, as the Renderer runs them (renderer.cpp): what the scene
// needs and nothing more (the plan), with the per-scene data from the SceneCache.
#pragma once
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <abcube/renderer.hpp>
#include <nlohmann/json.hpp>

#include "gl/gl_context.hpp"
#include "gl/gl_passes.hpp"
#include "raster/abuffer.hpp"
#include "scene/scene_data.hpp"
#include "shading/map_shading.hpp"
#include "shading/scene_cache.hpp"

namespace abcube {

// One render's settings after validation (RenderOptions resolved against the scene).
struct RenderRequest {
  int threads = 0;
  bool reference = false;
  std::string reference_image;  // the exact image, rendered before
  bool plan_everything = false;
  ABufferOptions abuffer;  // threads, layer cap, memory budget
  MapShadingOptions map;   // search mode, refinement, theta_max, refraction, envmap lookup
  std::vector<std::string> aovs;
  ExactCameraOptions gpu;  // the gpu method's exact camera pass (gl_passes.hpp)
};

// What every method's passes read and write.
struct MethodContext {
  const SceneData& scene;  // with this render's camera and settings
  const SceneCache& cache;
  const RenderRequest& request;
  nlohmann::json& stats;
  const std::function<void(const std::string&, double)>& progress;
  GlScene* gl_scene;     // the scene on the GPU (gpu method only)
  GpuTimings gl_before;  // its timings before this render (zero when it uploaded now)
  // Filled by the map methods for the "fallback" AOV: per pixel, the share of secondary
  // searches that found nothing.
  Image* fallback;
};

// The GPU's raster (GlScene): flat mirrors and hard shadows exact, curved mirrors and glass
// from its cube texture; shadow maps and the environment only where the scene needs them.
Image render_gpu(MethodContext& mc);
// The cube-map methods (abuffer, zbuffer, envmap): the map is built only when something
// needs it (a reflecting or refracting material, a shadow-casting light). `only`
// (optional): the pixels to render, the others black.
Image render_map_method(MethodContext& mc, const std::vector<uint8_t>* only = nullptr);
// A cube map at one N and the shader that searches it.
struct CubeMap {
  int n = 0;
  std::unique_ptr<CubeABuffer> cube;  // by pointer: the shader refers to it
  ABufferStats stats;
  double build_ms = 0, setup_ms = 0;
  std::unique_ptr<MapShader> shader;
};
// The map methods' shading options for this render.
MapShadingOptions map_shading_options(const MethodContext& mc);
// The cube A-buffer around the camera at `n`, within `options`' memory budget, and its
// shader with `shading`. `reference` (optional): the tracer the searches' ray errors are
// measured against.
CubeMap build_cube_map(const MethodContext& mc, int n, const ABufferOptions& options, const RayTracer* reference,
                       const MapShadingOptions& shading);

// The hybrid method (docs/design/gpu-exact-paths.md): the GPU's exact camera pass,
// and the abuffer method on the CPU for the pixels whose samples meet a surface the GPU
// only approximates.
Image render_hybrid(MethodContext& mc);
// The exact Whitted tracer; its stats go under `key` ("raytrace" or "reference").
Image render_reference(MethodContext& mc, const char* key);
// The image's error against the exact image (traced now, or --reference-image); PSNR.
double add_reference_error(MethodContext& mc, const Image& image);

nlohmann::json gl_json(const GlContext* ctx);

// The scene as a render with `options` sees it: its camera and render settings with the
// options' overrides, checked (renderer.cpp). Shares the triangles.
SceneData scene_view(const SceneData& base, const RenderOptions& options);

}  // namespace abcube
