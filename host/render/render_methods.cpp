#include "render/render_methods.hpp"

#include <cmath>
#include <memory>
#include <optional>

#include <abcube/image.hpp>

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "base/timer.hpp"
#include "io/metrics.hpp"
#include "raster/edge_ties.hpp"
#include "base/samples.hpp"
#include "reference/raytrace.hpp"
#include "render/crosscheck.hpp"
#include "render/stats_json.hpp"
#include "render/target_db.hpp"
#include "scene/plan.hpp"

namespace abcube {

using nlohmann::json;

// A pass of the render starts (0) or ends (1), for the progress callback when there is one.
void pass_progress(const MethodContext& mc, const char* pass, double done) {
  if (mc.progress) mc.progress(pass, done);
}

json gl_json(const GlContext* ctx) {
  if (!ctx) return {{"path", "none"}, {"renderer", describe_gl(nullptr)}};
  const GlInfo& i = ctx->info();
  json j = {{"path", i.api}, {"renderer", i.gl_renderer}, {"gl_version", i.gl_version}, {"gl_vendor", i.gl_vendor}};
  if (!i.egl_vendor.empty()) j["egl_vendor"] = i.egl_vendor;
  if (i.device_index >= 0) j["egl_device"] = i.device_index;
  return j;
}

// What the exact camera pass rendered: per kind of surface, the path it took and why.
// `curved`: what curved mirrors and refraction took; `maps`: shadow maps were built.
json gpu_paths_json(const GlScene& gl, const RenderRequest& request, const std::string& curved, bool maps) {
  const ExactCameraStats& ex = gl.exact_camera_stats();
  return {
      {"planar_mirrors",
       {{"technique", ex.mirrors ? "stencil" : curved},
        {"why", ex.mirrors                   ? "exact: virtual views through the stencil test, to max_depth"
                : request.gpu.planar_mirrors ? ex.mirrors_why
                                             : "asked: --gpu-mirrors envmap"},
        {"reflectors", ex.reflectors},
        {"views", ex.mirror_views},
        {"views_empty", ex.mirror_views_empty},
        {"views_over_budget", ex.mirror_views_over_budget},
        {"max_views_per_tile", request.gpu.max_views},
        {"deepest_level", ex.deepest_level}}},
      {"curved_mirrors_and_refraction",
       {{"technique", curved},
        {"curved_reflective_triangles", ex.curved_reflective_triangles},
        {"why", curved == "environment_map" ? "approximate: Blinn-Newell lookups in the cube texture around the eye"
                : curved == "none"          ? "none in the view's reach (or max_depth 0)"
                                            : "the CPU's A-buffer searches, for the pixels they reach"}}},
      {"shadows",
       {{"technique", ex.volumes ? "shadow_volumes"
                      : maps     ? "shadow_maps"
                                 : "none"},
        {"why", ex.volumes                   ? "exact: depth-fail counting of every opaque blocker's prism"
                : request.gpu.shadow_volumes ? ex.volumes_why
                                             : "asked: --gpu-shadows maps"},
        {"volume_lights", ex.volumes ? ex.volume_lights : 0},
        {"volume_triangles", ex.volumes ? ex.volume_triangles : 0},
        {"translucent_casters", maps && gl.shadow_peels() > 0 ? "shadow maps' peeled layers" : "none"}}},
      {"shading",
       {{"technique", ex.shading_pixels ? "pixels" : "samples"},
        {"why", ex.shading_pixels ? "once a pixel and surface: its samples grouped by triangle and shadow-volume set"
                                  : ex.shading_why}}},
      {"camera_samples_approximate", ex.samples_approximate},
      {"pixels_exact", ex.pixels_exact}};
}

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
  stats["timings_ms"]["upload"] = t.upload_ms - before.upload_ms;
  if (maps > 0) stats["timings_ms"]["shadow_maps"] = t.shadow_maps_ms - before.shadow_maps_ms;
  if (needed || mc.request.plan_everything)
    stats["timings_ms"]["environment_map"] = t.environment_ms - before.environment_ms;
  stats["timings_ms"]["camera_raster"] = t.camera_ms - before.camera_ms;
  stats["timings_ms"]["readback"] = t.readback_ms - before.readback_ms;
  stats["counts"]["shadow_maps"] = maps;
  stats["counts"]["shadow_translucent_layers"] = maps > 0 ? gl.shadow_peels() : 0;
  stats["counts"]["shadow_translucent_layers_capped"] = maps > 0 && gl.shadow_peels_capped();
  stats["counts"]["camera_samples_per_pixel"] = MASK_SAMPLES;
  stats["counts"]["camera_layers"] = gl.camera_layers();  // > 1: coverage transparency peeled
  stats["counts"]["camera_layers_capped"] = gl.camera_layers_capped();
  stats["gpu_paths"] = gpu_paths_json(gl, mc.request, needed ? "environment_map" : "none", maps > 0);
  const ExactCameraStats& ex = gl.exact_camera_stats();
  if (ex.volumes) stats["timings_ms"]["shadow_volumes_build"] = ex.volume_build_ms;
  stats["plan"]["passes"] = passes;
  stats["plan"]["skipped"] = skipped;
  return image;
}

namespace {

// The pixels of `from` that `mask` marks, into `to` (the same size, RGB).
void copy_pixels(const Image& from, const std::vector<uint8_t>& mask, Image* to) {
  for (size_t p = 0; p < mask.size(); ++p) {
    if (!mask[p]) continue;
    for (size_t c = 0; c < 3; ++c) to->data[3 * p + c] = from.data[3 * p + c];
  }
}

}  // namespace

namespace {

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
  mc.stats["timings_ms"]["edge_ties"] = ms_since(t0);
  if (traced_pixels == 0) return 0;
  RaytraceOptions options;
  options.threads = mc.request.threads;
  options.bvh = mc.cache.bvh();
  options.only = &traced;
  const Clock::time_point t1 = Clock::now();
  const Image part = render_raytrace(mc.scene, options, nullptr);
  mc.stats["timings_ms"]["edge_ties_traced"] = ms_since(t1);
  copy_pixels(part, traced, image);
  return traced_pixels;
}

// The abuffer method for the pixels `only` marks (null: every pixel, `image` replaced),
// copied into `image`; its timings as "cpu.*", and its stats returned.
json render_cpu_pixels(MethodContext& mc, const std::vector<uint8_t>* only, Image* image) {
  json cpu_stats, out;
  MethodContext cpu_mc{mc.scene, mc.cache, mc.request, cpu_stats, mc.progress, nullptr, {}, mc.fallback};
  const Image part = render_map_method(cpu_mc, only);
  if (only) {
    copy_pixels(part, *only, image);
  } else {
    *image = part;
  }
  for (const auto& [k, v] : cpu_stats["timings_ms"].items()) mc.stats["timings_ms"]["cpu." + k] = v;
  for (const char* key : {"plan", "cube_abuffer", "abuffer", "searches"}) {
    if (cpu_stats.contains(key)) out[key] = cpu_stats[key];
  }
  return out;
}

}  // namespace

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
  stats["timings_ms"]["upload"] = t.upload_ms - before.upload_ms;
  if (exact_pass) {
    stats["timings_ms"]["camera_raster"] = t.camera_ms - before.camera_ms;
    stats["timings_ms"]["readback"] = t.readback_ms - before.readback_ms;
  }
  stats["gpu_paths"] = gpu_paths_json(gl, mc.request, cpu_pixels > 0 ? "cpu_searches" : "none", false);
  if (ex.volumes) stats["timings_ms"]["shadow_volumes_build"] = ex.volume_build_ms;
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

Image render_reference(MethodContext& mc, const char* key) {
  RaytraceOptions options;
  options.threads = mc.request.threads;
  // The raytrace method at its rung of THE SAMPLE LADDER; the reference of the other methods
  // always at all 32.
  if (std::string(key) == "raytrace") {
    if (mc.scene.render.target_db > 0) return raytrace_for_target(mc);
    options.samples_per_pixel = mc.scene.render.samples;
    mc.stats["counts"]["camera_samples_per_pixel"] = options.samples_per_pixel;
    mc.stats["method_options"]["samples"] = options.samples_per_pixel;
  }
  if (mc.progress) {
    const std::string stage = key;
    options.progress = [&mc, stage](double done) { mc.progress(stage, done); };
  }
  options.bvh = mc.cache.bvh();
  RaytraceStats rs;
  Image image = render_raytrace(mc.scene, options, &rs);
  mc.stats[key].update(raytrace_json(rs));  // beside what the map method put there (ray_error)
  return image;
}

Image render_map_method(MethodContext& mc, const std::vector<uint8_t>* only) {
  const SceneData& scene = mc.scene;
  const RenderRequest& r = mc.request;
  json& stats = mc.stats;
  const RenderPlan plan = make_plan(scene, r.plan_everything);
  json passes = json::array(), skipped = json::array();
  for (const PlanStep& s : plan.steps) (s.run ? passes : skipped).push_back({{"pass", s.pass}, {"why", s.why}});
  stats["plan"]["passes"] = passes;
  stats["plan"]["skipped"] = skipped;
  stats["plan"]["mode"] = r.plan_everything ? "everything" : "needed";
  if (!plan.cube_map) {
    if (scene.render.target_db > 0) {
      stats["target_db"] = {{"target", scene.render.target_db},
                            {"why", "no cube map: nothing reflects, refracts or casts a shadow, so N is not used"}};
    }
    pass_progress(mc, "shading", 0.0);
    Image image =
        render_abuffer_local(scene, r.abuffer, &stats, r.map.exact_priority, r.map.plan.texture_samples(), only);
    pass_progress(mc, "shading", 1.0);
    return image;
  }
  std::unique_ptr<RayTracer> reference;
  if (r.reference) reference = std::make_unique<RayTracer>(scene, mc.cache.bvh());
  // The camera's A-buffer first, then the cube's, budgeted with the camera's held: the
  // camera build's per-triangle bins are gone before the cube's A-buffer, its mesh
  // neighbours and its side structure are made (peak memory), and every pilot of
  // --target-db shades the same camera fragments.
  ABufferStats as;
  const Clock::time_point camera_start = Clock::now();
  pass_progress(mc, "camera A-buffer", 0.0);
  const ABuffer camera = build_camera_abuffer(scene, r.abuffer, &as);
  pass_progress(mc, "camera A-buffer", 1.0);
  const double camera_ms = ms_since(camera_start);
  ABufferOptions cube_options = r.abuffer;
  cube_options.reserved_bytes += as.bytes_total;
  const bool target = scene.render.method == Method::abuffer && scene.render.target_db > 0;
  const char* cube_pass = target ? "choosing N and the shading (pilots)" : "cube A-buffer";
  pass_progress(mc, cube_pass, 0.0);
  const CubeMap map =
      target ? cube_map_for_target(mc, camera, cube_options, reference.get())
             : build_cube_map(mc, scene.render.cube_resolution, cube_options, reference.get(), map_shading_options(mc));
  pass_progress(mc, cube_pass, 1.0);
  stats["timings_ms"]["cube_abuffer"] = map.build_ms;
  stats["cube_abuffer"] = cube_abuffer_json(map.stats);
  stats["timings_ms"]["map_setup"] = map.setup_ms;
  stats["timings_ms"]["camera_abuffer"] = camera_ms;
  const Clock::time_point t0 = Clock::now();
  MapShadingStats ms;
  std::function<void(double)> shading;
  if (mc.progress) shading = [&mc](double done) { mc.progress("shading", done); };
  Image image = render_with_map(scene, camera, *map.shader, r.threads, &ms, mc.fallback, only, true, &shading);
  stats["timings_ms"]["shade_and_resolve"] = ms_since(t0);
  stats["abuffer"] = abuffer_json(as, false);
  stats["searches"] = map_shading_json(ms);
  if (reference) {
    const double bound = parallax_bound(map.n);
    stats["reference"]["ray_error"] = {{"rays", "reflection rays of camera-visible surfaces"},
                                       {"error_cp", error_stats_json(ms.errors.error_cp)},
                                       {"error_parallax", error_stats_json(ms.errors.error_parallax)},
                                       {"false_hits", ms.errors.false_hits},
                                       {"wrong_object", ms.errors.wrong_object},
                                       {"bound_1_over_2n2", bound},
                                       {"error_parallax_within_bound", ms.errors.error_parallax.share_within(bound)}};
  }
  return image;
}

double add_reference_error(MethodContext& mc, const Image& image) {
  json& stats = mc.stats;
  const RenderRequest& r = mc.request;
  Image ref;
  if (!r.reference_image.empty()) {
    ref = read_image(r.reference_image);
    if (ref.width != image.width || ref.height != image.height) {
      throw InputError(r.reference_image + ": is " + std::to_string(ref.width) + "x" + std::to_string(ref.height) +
                       ", the render is " + std::to_string(image.width) + "x" + std::to_string(image.height));
    }
    stats["reference"]["image"] = r.reference_image;
  } else {
    // The tracer's own image is the reference only at the reference's 32 samples.
    const bool reference_itself = mc.scene.render.method == Method::raytrace && mc.scene.render.target_db <= 0 &&
                                  mc.scene.render.samples == MASK_SAMPLES;
    ref = reference_itself ? image : render_reference(mc, "reference");
  }
  const ImageError e = image_error(image, ref);
  stats["reference"]["image_error"] = image_error_json(e);
  if (!stats["reference"].contains("ray_error")) {
    stats["reference"]["ray_error"] = std::string("n/a: method ") + method_name(mc.scene.render.method) +
                                      " does no map search (Error_CP and Error_Parallax measure searches)";
  }
  return e.psnr;
}

}  // namespace abcube
