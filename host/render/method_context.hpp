// What every method's passes read and write (MethodContext), the render's settings after
// validation (RenderRequest), and the cube map at one N with its shader: the layer under
// both the methods (render_methods.hpp) and --target-db's pilots (target_db.hpp), so that
// neither calls back into the other.
#pragma once
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gl/gl_types.hpp"
#include "raster/abuffer.hpp"
#include "scene/scene_data.hpp"
#include "shading/map_shading.hpp"
#include "shading/scene_cache.hpp"

namespace abcube {

class GlScene;  // gl/gl_passes.hpp: the GL methods' units include it

// One render's settings after validation (RenderOptions resolved against the scene).
struct RenderRequest {
  int threads = 0;
  bool reference = false;
  std::string reference_image;  // the exact image, rendered before
  bool plan_everything = false;
  ABufferOptions abuffer;  // threads, layer cap, memory budget
  // What the method read of its own options (RenderMethod::read_options):
  MapShadingOptions map;       // the map searches: variant, mode, refinement, refraction, lookup, plan
  ExactCameraOptions gpu;      // the GPU's exact camera pass (gl_types.hpp)
  bool target_pilots = false;  // --target-db picks the cube map's N and shading by pilots
  // The camera's and the cube's A-buffers built by GL compute shaders (gl_abuffer.hpp) on
  // MethodContext::gl_scene's context, not by the CPU core: the same lists.
  bool abuffers_on_gl = false;
  // Where the map searches walk (--search-on, gpu_abuffer and hybrid): on GL compute, the
  // DEFERRED SEARCHES over GlCandidateScan (gl_cube_scan.hpp), or on the CPU; `automatic`: GL
  // where it is a hardware GPU and the options allow it, else the CPU.
  enum class SearchOn { cpu, gpu, automatic };
  SearchOn search_on = SearchOn::cpu;
  // Where the camera's resolve is planned (--resolve-on, gpu_abuffer): THE RESOLVE PLAN on GL
  // compute (gl_resolve_plan.hpp), or pack_under_mask alone on the CPU; unset for a method
  // that does not read it.
  std::optional<SearchOn> resolve_on;
  std::vector<std::string> aovs;
};

// What a render measured that RenderStats carries, typed. The passes write it; after them
// the Renderer writes it into the stats JSON, once ("timings_ms", each tracer's
// "timings_ms", the "gl" object's path and renderer), and fills RenderStats from it.
struct RenderRecord {
  std::map<std::string, double> timings_ms;  // per pass
  // The exact tracer's passes (bvh_build, trace) by its stats key: "raytrace", "reference".
  std::map<std::string, std::map<std::string, double>> tracer_timings_ms;
  std::string gl_path = "none";  // the GL path the render drew with, or "none"
  std::string gl_renderer = "none (CPU)";
};

// What every method's passes read and write.
struct MethodContext {
  const SceneData& scene;  // with this render's camera and settings
  const SceneCache& cache;
  const RenderRequest& request;
  nlohmann::json& stats;  // the figures of the passes, beside the record's
  RenderRecord& record;
  const std::function<void(const std::string&, double)>& progress;
  GlScene* gl_scene;     // the scene on the GPU (a method that needs_gl)
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
// The camera's A-buffer: build_camera_abuffer, or its GL twin where request.abuffers_on_gl.
ABuffer build_camera_abuffer(const MethodContext& mc, const ABufferOptions& options, ABufferStats* stats);
// The map searches' options for this render (request.map, and --plan everything's walks).
MapShadingOptions map_shading_options(const MethodContext& mc);
// The cube A-buffer around the camera at `n` (built on GL where request.abuffers_on_gl),
// within `options`' memory budget, and its shader with `shading`. `reference` (optional): the
// tracer the searches' ray errors are measured against.
CubeMap build_cube_map(const MethodContext& mc, int n, const ABufferOptions& options, const RayTracer* reference,
                       const MapShadingOptions& shading);

}  // namespace abcube
