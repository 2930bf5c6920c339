// What every method's passes read and write (MethodContext), the render's settings after
// validation (RenderRequest), and the cube map at one N with its shader: the layer under
// both the methods (render_methods.hpp) and --target-db's pilots (target_db.hpp), so that
// neither calls back into the other.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

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

}  // namespace abcube
