// The gpu method: the GPU's raster (GlScene). Flat mirrors and hard shadows exact (the
// stencil test, shadow volumes), curved mirrors and glass from its cube texture around the
// eye; shadow maps and the environment only where the scene needs them.
#include <memory>

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "gl/gl_passes.hpp"
#include "render/method.hpp"
#include "render/render_methods.hpp"

namespace abcube {

using nlohmann::json;

namespace {

// The passes: shadow maps, the environment map, the camera's raster at the 4x8 samples.
Image render_gpu(MethodContext& mc) {
  const SceneData& scene = mc.scene;
  json& stats = mc.stats;
  GlScene& gl = *mc.gl_scene;
  const GpuTimings& before = mc.gl_before;
  // Model only what the scene needs: shadow maps for shadow-casting lights, the
  // environment map for reflecting or refracting materials (none at max_depth 0).
  json passes = json::array(), skipped = json::array();
  const int n = scene.render.cube_resolution;
  pass_progress(mc, "gpu passes", 0.0);
  const int maps = gl.build_shadow_maps(n);
  pass_progress(mc, "gpu passes", 0.25);
  if (maps > 0) {
    passes.push_back("shadow_maps");
  } else {
    skipped.push_back({{"pass", "shadow_maps"}, {"why", "no light casts shadows"}});
  }
  bool mirrors = false;
  for (const Material& m : scene.materials) mirrors = mirrors || m.reflect > 0 || m.transmit > 0;
  const bool needed = mirrors && scene.render.max_depth > 0;
  if (needed || mc.request.plan_everything) {
    gl.build_environment(scene.camera.position, n);
    pass_progress(mc, "gpu passes", 0.5);
    passes.push_back(needed ? "environment_map" : "environment_map (unused: --plan everything)");
  }
  if (!needed) {
    gl.drop_environment();
    if (!mc.request.plan_everything) {
      skipped.push_back(
          {{"pass", "environment_map"},
           {"why", mirrors ? "max_depth 0: no reflected or refracted ray" : "no material reflects or transmits"}});
    }
  }
  stats["plan"]["mode"] = mc.request.plan_everything ? "everything" : "needed";
  gl.set_environment_lookup(mc.request.map.lookup, scene.render.fresnel);
  gl.set_exact_camera(mc.request.gpu);
  check_deadline();
  // The camera view at the A-buffer's 4x8 sample positions, box-filtered as its resolve
  // weighs the masks: the same edges as abuffer.
  Image image = gl.camera_color(scene.camera, CameraSamples::mask_4x8);
  pass_progress(mc, "gpu passes", 1.0);
  passes.push_back("camera_raster");
  skipped.push_back({{"pass", "cube_distance"}, {"why", "method gpu does no map search"}});
  const GpuTimings& t = gl.timings();
  mc.record.timings_ms["upload"] = t.upload_ms - before.upload_ms;
  if (maps > 0) mc.record.timings_ms["shadow_maps"] = t.shadow_maps_ms - before.shadow_maps_ms;
  if (needed || mc.request.plan_everything)
    mc.record.timings_ms["environment_map"] = t.environment_ms - before.environment_ms;
  mc.record.timings_ms["camera_raster"] = t.camera_ms - before.camera_ms;
  mc.record.timings_ms["readback"] = t.readback_ms - before.readback_ms;
  stats["counts"]["shadow_maps"] = maps;
  stats["counts"]["shadow_translucent_layers"] = maps > 0 ? gl.shadow_peels() : 0;
  stats["counts"]["shadow_translucent_layers_capped"] = maps > 0 && gl.shadow_peels_capped();
  stats["counts"]["camera_samples_per_pixel"] = MASK_SAMPLES;
  stats["counts"]["camera_layers"] = gl.camera_layers();  // > 1: coverage transparency peeled
  stats["counts"]["camera_layers_capped"] = gl.camera_layers_capped();
  stats["gpu_paths"] = gpu_paths_json(gl, mc.request, needed ? "environment_map" : "none", maps > 0);
  const ExactCameraStats& ex = gl.exact_camera_stats();
  if (ex.volumes) mc.record.timings_ms["shadow_volumes_build"] = ex.volume_build_ms;
  stats["plan"]["passes"] = passes;
  stats["plan"]["skipped"] = skipped;
  return image;
}

class GpuMethod : public RenderMethod {
 public:
  std::string name() const override { return "gpu"; }
  std::string summary() const override {
    return "the GPU's raster: planar mirrors and shadows exact, curved mirrors and glass from a cube texture";
  }
  std::vector<std::string> reads() const override {
    std::vector<std::string> keys = {"cube_res", "error_target", "plan", "envmap_lookup"};
    for (const std::string& k : gpu_camera_option_keys()) keys.push_back(k);
    return keys;
  }
  void read_options(const RenderOptions& options, const SceneData& view, RenderRequest* request) const override {
    request->map.lookup = parse_checked(options.envmap_lookup, parse_envmap_lookup);
    read_gpu_options(options, view.render.max_depth, request);
  }
  bool needs_gl() const override { return true; }
  Image render(MethodContext& mc) const override { return render_gpu(mc); }
};

}  // namespace

std::unique_ptr<RenderMethod> make_gpu_method() { return std::make_unique<GpuMethod>(); }

}  // namespace abcube
