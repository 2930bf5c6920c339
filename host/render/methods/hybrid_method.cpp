// The hybrid method (docs/design/gpu-exact-paths.md): the GPU's exact camera pass, and the
// abuffer method on the CPU for the pixels whose samples meet a surface the GPU only
// approximates.
#include <algorithm>
#include <memory>

#include "base/parallel.hpp"
#include "base/timer.hpp"
#include "raster/edge_ties.hpp"
#include "reference/raytrace.hpp"
#include "gl/gl_context.hpp"
#include "gl/gl_passes.hpp"
#include "render/method.hpp"
#include "render/render_methods.hpp"

namespace abcube {

using nlohmann::json;

namespace {

// The pixels of `from` that `mask` marks, into `to` (the same size, RGB).
void copy_pixels(const Image& from, const std::vector<uint8_t>& mask, Image* to) {
  for (size_t p = 0; p < mask.size(); ++p) {
    if (!mask[p]) continue;
    for (size_t c = 0; c < 3; ++c) to->data[3 * p + c] = from.data[3 * p + c];
  }
}

// The hybrid method's pixels the GPU kept but where its snapped vertices may have decided a
// sample unlike the exact rules (edge_ties.hpp: exact only up to its sub-pixel grid): their
// surfaces are all exact ones, so the exact tracer renders them into `image`. Returns how
// many.
size_t trace_edge_ties(MethodContext& mc, const std::vector<uint8_t>& on_gpu, Image* image) {
  const Clock::time_point t0 = Clock::now();
  std::vector<uint8_t> traced = edge_tie_pixels(mc.scene);
  size_t traced_pixels = 0;
  for (size_t p = 0; p < traced.size(); ++p) {
    traced[p] = traced[p] && on_gpu[p] ? 1 : 0;
    traced_pixels += traced[p];
  }
  mc.record.timings_ms["edge_ties"] = ms_since(t0);
  if (traced_pixels == 0) return 0;
  RaytraceOptions options;
  options.threads = mc.request.threads;
  options.bvh = mc.cache.bvh();
  options.only = &traced;
  const Clock::time_point t1 = Clock::now();
  const Image part = render_raytrace(mc.scene, options, nullptr);
  mc.record.timings_ms["edge_ties_traced"] = ms_since(t1);
  copy_pixels(part, traced, image);
  return traced_pixels;
}

// The abuffer method for the pixels `only` marks (null: every pixel, `image` replaced),
// copied into `image`; its timings as "cpu.*", and its stats returned.
json render_cpu_pixels(MethodContext& mc, const std::vector<uint8_t>* only, Image* image) {
  json cpu_stats, out;
  RenderRecord cpu_record;
  cpu_record.gl_renderer = mc.record.gl_renderer;  // --search-on auto reads it
  // On a hardware GPU its A-buffers are built there (gl_abuffer.hpp, the same lists as the
  // CPU core's); on Mesa's software GL the CPU core builds them faster.
  RenderRequest request = mc.request;
  request.abuffers_on_gl = !software_renderer(mc.record.gl_renderer);
  MethodContext cpu_mc{mc.scene, mc.cache, request, cpu_stats, cpu_record, mc.progress, mc.gl_scene, {}, mc.fallback};
  const Image part = render_map_method(cpu_mc, only);
  if (only) {
    copy_pixels(part, *only, image);
  } else {
    *image = part;
  }
  for (const auto& [k, v] : cpu_record.timings_ms) mc.record.timings_ms["cpu." + k] = v;
  for (const char* key : {"plan", "cube_abuffer", "abuffer", "searches", "resolve_plan"}) {
    if (cpu_stats.contains(key)) out[key] = cpu_stats[key];
  }
  out["abuffers_built_on"] = request.abuffers_on_gl ? "gpu" : "cpu";
  return out;
}

// HYBRID: each kind of surface by the path that is exact and cheaper. The GPU renders the
// camera view by its exact camera pass (planar mirrors by the stencil test, opaque shadows
// by volumes, textures point-sampled as the CPU does), building no cube map at all; each
// sample counts the surfaces on its path the GPU would only approximate (curved mirrors,
// refraction, light through translucent casters: camera_exact.frag). The pixels with such a
// sample are rendered again, alone, by the abuffer method on the CPU (its cube map searches,
// its shadow searches); the others keep the GPU's colour. So hybrid is abuffer wherever the
// GPU is not exact, and exact elsewhere.
Image render_hybrid(MethodContext& mc) {
  const SceneData& scene = mc.scene;
  json& stats = mc.stats;
  GlScene& gl = *mc.gl_scene;
  const GpuTimings& before = mc.gl_before;
  gl.drop_environment();
  ExactCameraOptions exact = mc.request.gpu;
  exact.always = true;
  gl.set_exact_camera(exact);
  check_deadline();
  // Where the exact pass cannot run (coverage transparency, a GL without dual-source
  // blending) every pixel is the CPU's: the GPU's camera pass is not drawn at all.
  const bool exact_pass = gl.exact_camera_possible();
  Image image;
  if (exact_pass) {
    pass_progress(mc, "gpu passes", 0.0);
    gl.set_texture_level0(true);
    image = gl.camera_color(scene.camera, CameraSamples::mask_4x8);
    gl.set_texture_level0(false);
    pass_progress(mc, "gpu passes", 1.0);
  }
  const ExactCameraStats& ex = gl.exact_camera_stats();
  std::vector<uint8_t> cpu(static_cast<size_t>(scene.camera.width) * static_cast<size_t>(scene.camera.height), 1);
  // The pixels the GPU would have kept but where its snapped vertices may have decided a
  // sample unlike the exact rules (edge_ties.hpp: exact only up to its sub-pixel grid):
  // their surfaces are all exact ones, so the exact tracer renders them.
  size_t traced_pixels = 0;
  if (exact_pass) {
    const std::vector<uint8_t>& on_gpu = gl.exact_pixels();
    for (size_t p = 0; p < cpu.size(); ++p) cpu[p] = on_gpu[p] ? 0 : 1;
    traced_pixels = trace_edge_ties(mc, on_gpu, &image);
  }
  const size_t cpu_pixels = static_cast<size_t>(std::count(cpu.begin(), cpu.end(), 1));
  const GpuTimings& t = gl.timings();
  mc.record.timings_ms["upload"] = t.upload_ms - before.upload_ms;
  if (exact_pass) {
    mc.record.timings_ms["camera_raster"] = t.camera_ms - before.camera_ms;
    mc.record.timings_ms["readback"] = t.readback_ms - before.readback_ms;
  }
  stats["gpu_paths"] = gpu_paths_json(gl, mc.request, cpu_pixels > 0 ? "cpu_searches" : "none", false);
  if (ex.volumes) mc.record.timings_ms["shadow_volumes_build"] = ex.volume_build_ms;
  json hybrid = {{"pixels", cpu.size()},
                 {"pixels_gpu", cpu.size() - cpu_pixels - traced_pixels},
                 {"pixels_cpu", cpu_pixels},
                 {"pixels_traced_edge_ties", traced_pixels}};
  if (!exact_pass) hybrid["why_all_cpu"] = ex.mirrors_why.empty() ? ex.volumes_why : ex.mirrors_why;
  if (cpu_pixels > 0) {
    const json cpu_stats = render_cpu_pixels(mc, exact_pass ? &cpu : nullptr, &image);
    if (!cpu_stats.is_null()) hybrid["cpu"] = cpu_stats;
  } else {
    hybrid["cpu"] = "skipped: every pixel is exact on the GPU (no cube map built)";
  }
  stats["hybrid"] = hybrid;
  json passes = json::array();
  if (!exact_pass) passes.push_back("cpu abuffer for every pixel");
  if (exact_pass) passes.push_back("camera_raster (exact pass)");
  if (traced_pixels > 0) passes.push_back("exact tracer for the pixels with a sample at an edge (edge ties)");
  if (exact_pass && cpu_pixels > 0) passes.push_back("cpu abuffer for the pixels left");
  stats["plan"]["passes"] = passes;
  stats["plan"]["mode"] = "needed";
  stats["counts"]["camera_samples_per_pixel"] = MASK_SAMPLES;
  return image;
}

class HybridMethod : public RenderMethod {
 public:
  std::string name() const override { return "hybrid"; }
  std::string summary() const override {
    return "the GPU's exact camera pass, and abuffer on the CPU for the pixels the GPU only approximates";
  }
  std::vector<std::string> reads() const override {
    std::vector<std::string> keys = map_option_keys();  // abuffer's, with the lens transfer
    keys.push_back("refraction");
    for (const std::string& k : gpu_camera_option_keys()) keys.push_back(k);
    keys.push_back("search_on");
    keys.push_back("resolve_on");
    return keys;
  }
  void read_options(const RenderOptions& options, const SceneData& view, RenderRequest* request) const override {
    read_map_options(options, MapVariant::abuffer, request);  // abuffer's searches
    read_search_on(options, request);
    read_resolve_on(options, request);
    read_gpu_options(options, view.render.max_depth, request);
  }
  bool needs_gl() const override { return true; }
  Image render(MethodContext& mc) const override { return render_hybrid(mc); }
};

}  // namespace

std::unique_ptr<RenderMethod> make_hybrid_method() { return std::make_unique<HybridMethod>(); }

}  // namespace abcube
