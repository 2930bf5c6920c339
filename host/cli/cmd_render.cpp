// abcube render: load a scene, run the passes its method needs, write the image and stats.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_common.hpp"
#include "base/parallel.hpp"
#include "base/error.hpp"
#include "gl/gl_context.hpp"
#include "render/crosscheck.hpp"
#include "gl/gl_passes.hpp"
#include "io/image_io.hpp"
#include "base/memory.hpp"
#include "shading/map_shading.hpp"
#include "io/metrics.hpp"
#include "scene/plan.hpp"
#include "reference/raytrace.hpp"
#include "scene/scene_load.hpp"

namespace abcube {

namespace {

using nlohmann::json;

struct RenderRequest {
  std::string scene_path, output, stats_path;
  GlChoice gl = GlChoice::automatic;
  int gl_device = -1;
  int threads = 0;
  bool reference = false;
  std::string reference_image;  // --reference-image: the exact image, rendered before
  bool plan_everything = false;  // --plan everything
  ABufferOptions abuffer;  // --threads, --max-layers, --max-memory (MiB)
  MapShadingOptions map;   // --search, --refine, --theta-max, --refraction, --envmap-lookup
};

// Parses the command line and applies its overrides to the scene (cli.md).
RenderRequest parse_request(const std::vector<std::string>& words, SceneData* scene) {
  const Args args(words,
                  {"-o", "--output", "--method", "--cube-res", "--max-depth", "--threads", "--gl",
                   "--gl-device", "--stats", "--max-memory", "--max-layers", "--search", "--refine", "--theta-max",
                   "--refraction", "--envmap-lookup", "--error-target", "--reference-image", "--plan"},
                  {"--reference", "--fresnel"});
  args.expect_positional(1, "SCENE.json");
  RenderRequest r;
  r.scene_path = args.positional()[0];
  r.output = args.has("-o") ? args.get("-o") : args.get("--output");
  if (r.output.empty()) throw InputError("-o OUT: an output image is required");
  if (!image_format_supported(r.output)) {
    throw InputError(r.output + ": no image writer for this file extension");
  }
  r.stats_path = args.get("--stats");
  for (const std::string* path : {&r.output, &r.stats_path}) {
    // Refuse before any work a folder the output cannot be written to.
    if (path->empty()) continue;
    const std::filesystem::path dir = std::filesystem::path(*path).parent_path();
    if (!dir.empty() && !std::filesystem::is_directory(dir)) {
      throw InputError(*path + ": folder " + dir.string() + " does not exist");
    }
  }
  if (args.has("--gl") && !parse_gl_choice(args.get("--gl"), &r.gl)) {
    throw InputError("--gl: unknown path '" + args.get("--gl") +
                     "' (auto, egl, egl-device, egl-surfaceless, osmesa, none)");
  }
  r.gl_device = args.get_int("--gl-device", -1, 0, 1024);
  r.threads = args.get_int("--threads", 0, 0, 4096);
  r.reference_image = args.get("--reference-image");
  r.reference = args.has("--reference") || !r.reference_image.empty();
  const std::string plan = args.get("--plan", "needed");
  if (plan != "needed" && plan != "everything") {
    throw InputError("--plan: must be needed or everything, got '" + plan + "'");
  }
  r.plan_everything = plan == "everything";
  r.abuffer.threads = r.threads;
  r.map.threads = r.threads;
  if (args.has("--search") && !parse_search_mode(args.get("--search"), &r.map.search.mode)) {
    throw InputError("--search: unknown mode '" + args.get("--search") + "' (crossing, thesis)");
  }
  if (args.has("--refine") && !parse_search_refine(args.get("--refine"), &r.map.search.refine)) {
    throw InputError("--refine: unknown refinement '" + args.get("--refine") + "' (mesh, plane)");
  }
  r.map.search.theta_max = glm::radians(args.get_double("--theta-max", 2.0, 1e-6, 90.0));
  if (args.has("--refraction") && !parse_refraction_mode(args.get("--refraction"), &r.map.refraction)) {
    throw InputError("--refraction: unknown mode '" + args.get("--refraction") + "' (search, thick_lens, thin_lens)");
  }
  if (args.has("--envmap-lookup") && !parse_envmap_lookup(args.get("--envmap-lookup"), &r.map.lookup)) {
    throw InputError("--envmap-lookup: unknown lookup '" + args.get("--envmap-lookup") + "' (R, bisector, position)");
  }
  r.abuffer.max_layers = static_cast<uint32_t>(args.get_int("--max-layers", 0, 0, 1 << 20));
  r.abuffer.max_memory_bytes = static_cast<uint64_t>(args.get_int("--max-memory", 0, 0, 1 << 30)) << 20;
  Method method{};
  if (args.has("--method") && !parse_method(args.get("--method"), &method)) {
    throw InputError("--method: unknown method '" + args.get("--method") +
                     "' (abuffer, zbuffer, envmap, raytrace, gpu)");
  }

  *scene = load_scene(r.scene_path);
  if (args.has("--method")) scene->render.method = method;
  scene->render.error_target = args.get_double("--error-target", scene->render.error_target, 0.0, 0.5);
  if (scene->render.error_target > 0 && !args.has("--cube-res")) {
    // thesis 9.3.4: the N whose bound 1/(2 N^2) meets the target (plan.hpp).
    scene->render.cube_resolution = resolution_for_error(scene->render.error_target);
  }
  scene->render.cube_resolution = args.get_int("--cube-res", scene->render.cube_resolution, 1, 16384);
  scene->render.max_depth = args.get_int("--max-depth", scene->render.max_depth, 0, 64);
  if (args.has("--fresnel")) scene->render.fresnel = true;
  check_render_size(*scene, available_memory_bytes());
  return r;
}

json gl_json(const GlContext* ctx) {
  if (!ctx) return {{"path", "none"}, {"renderer", describe_gl(nullptr)}};
  const GlInfo& i = ctx->info();
  json j = {{"path", i.api}, {"renderer", i.gl_renderer}, {"gl_version", i.gl_version},
            {"gl_vendor", i.gl_vendor}};
  if (!i.egl_vendor.empty()) j["egl_vendor"] = i.egl_vendor;
  if (i.device_index >= 0) j["egl_device"] = i.device_index;
  return j;
}

// The Z-buffer raster on the GPU: camera view only, Phong, aliased (--method gpu).
Image render_gpu(const SceneData& scene, const RenderRequest& r, json* stats) {
  std::string log;
  Clock::time_point t0 = Clock::now();
  std::unique_ptr<GlContext> ctx = open_gl_context(r.gl, r.gl_device, &log);
  if (!ctx) {
    if (r.gl == GlChoice::none) throw InputError("--method gpu needs OpenGL, but --gl none was given");
    for (char& c : log) c = c == '\n' ? ';' : c;  // one line (main flattens too)
    throw RuntimeFailure("--method gpu needs OpenGL and no GL path works here: " + log);
  }
  (*stats)["gl"] = gl_json(ctx.get());
  (*stats)["timings_ms"]["gl_init"] = ms_since(t0);
  GlScene gl(scene);
  // Model only what the scene needs: shadow maps for shadow-casting lights, the
  // environment map for reflecting or refracting materials.
  json passes = json::array(), skipped = json::array();
  const int n = scene.render.cube_resolution;
  const int maps = gl.build_shadow_maps(n);
  if (maps > 0) {
    passes.push_back("shadow_maps");
  } else {
    skipped.push_back({{"pass", "shadow_maps"}, {"why", "no light casts shadows"}});
  }
  bool mirrors = false;
  for (const Material& m : scene.materials) mirrors = mirrors || m.reflect > 0 || m.transmit > 0;
  if (mirrors) {
    gl.build_environment(scene.camera.position, n);
    passes.push_back("environment_map");
  } else {
    skipped.push_back({{"pass", "environment_map"}, {"why", "no material reflects or transmits"}});
  }
  Image image = gl.camera_color(scene.camera);
  passes.push_back("camera_raster");
  skipped.push_back({{"pass", "cube_distance"}, {"why", "method gpu does no map search"}});
  const GpuTimings& t = gl.timings();
  (*stats)["timings_ms"]["upload"] = t.upload_ms;
  if (maps > 0) (*stats)["timings_ms"]["shadow_maps"] = t.shadow_maps_ms;
  if (mirrors) (*stats)["timings_ms"]["environment_map"] = t.environment_ms;
  (*stats)["timings_ms"]["camera_raster"] = t.camera_ms;
  (*stats)["timings_ms"]["readback"] = t.readback_ms;
  (*stats)["counts"]["shadow_maps"] = maps;
  (*stats)["plan"]["passes"] = passes;
  (*stats)["plan"]["skipped"] = skipped;
  return image;
}

// Shows "label NN%" on stderr when it is a terminal; quiet otherwise (cli.md).
std::function<void(double)> progress_printer(const char* label) {
  if (!stderr_is_terminal()) return nullptr;
  return [label](double done) { std::fprintf(stderr, "\r%s %3d%%%s", label, int(done * 100), done >= 1 ? "\n" : ""); };
}

// The exact Whitted tracer (--method raytrace, and the --reference image).
Image render_reference(const SceneData& scene, const RenderRequest& r, json* stats, const char* key) {
  RaytraceOptions options;
  options.threads = r.threads;
  options.progress = progress_printer(key);
  RaytraceStats rs;
  Image image = render_raytrace(scene, options, &rs);
  json& j = (*stats)[key];
  j["timings_ms"] = {{"bvh_build", rs.build_ms}, {"trace", rs.trace_ms}};
  j["counts"] = {{"primary_rays", rs.primary_rays}, {"secondary_rays", rs.secondary_rays},
                 {"shadow_rays", rs.shadow_rays}, {"bvh_nodes", rs.bvh_nodes}, {"bvh_depth", rs.bvh_depth}};
  j["threads"] = rs.threads;
  return image;
}

json search_kind_json(const SearchKindStats& s) {
  return {{"rays", s.rays}, {"texels_mean", s.mean_texels()}, {"texels_max", s.max_texels},
          {"fragments_tested", s.fragments}, {"candidates", s.candidates}, {"hits", s.hits},
          {"misses", s.misses}, {"threshold_rejections", s.threshold_rejections},
          {"zero_area_misses", s.zero_area}, {"aborted", s.aborted}};
}

json error_stats_json(const ErrorStats& e) {
  return {{"mean", e.mean()}, {"p99", e.percentile(0.99)}, {"max", e.max()}, {"count", e.count()},
          {"misses", e.miss_count()}, {"miss_share", e.miss_share()}};
}

// The cube-map methods (abuffer, zbuffer, envmap; map_shading.hpp). The map is built only
// when something needs it: a reflecting or refracting material, or a shadow-casting light.
Image render_map_method(const SceneData& scene, const RenderRequest& r, json* stats) {
  const RenderPlan plan = make_plan(scene, r.plan_everything);
  json passes = json::array(), skipped = json::array();
  for (const PlanStep& s : plan.steps) (s.run ? passes : skipped).push_back({{"pass", s.pass}, {"why", s.why}});
  (*stats)["plan"]["passes"] = passes;
  (*stats)["plan"]["skipped"] = skipped;
  (*stats)["plan"]["mode"] = r.plan_everything ? "everything" : "needed";
  if (!plan.cube_map) return render_abuffer_local(scene, r.abuffer, stats);
  Clock::time_point t0 = Clock::now();
  ABufferStats cs;
  const CubeABuffer cube =
      build_cube_abuffer(scene, scene.camera.position, scene.render.cube_resolution, r.abuffer, &cs);
  (*stats)["timings_ms"]["cube_abuffer"] = ms_since(t0);
  (*stats)["cube_abuffer"] = {{"fragments", cs.fragments}, {"raw_fragments", cs.raw_fragments},
                              {"max_list_length", cs.max_list_length}, {"bytes_total", cs.bytes_total},
                              {"dropped_by_cap", cs.dropped_by_cap}};
  std::unique_ptr<RayTracer> reference;
  if (r.reference) reference = std::make_unique<RayTracer>(scene);
  MapShadingOptions options = r.map;
  options.method = scene.render.method;
  options.walk_all_shadows = r.plan_everything;
  t0 = Clock::now();
  const MapShader shader(scene, cube, options, reference.get());
  (*stats)["timings_ms"]["map_setup"] = ms_since(t0);
  t0 = Clock::now();
  ABufferStats as;
  const ABuffer camera = build_camera_abuffer(scene, r.abuffer, &as);
  (*stats)["timings_ms"]["camera_abuffer"] = ms_since(t0);
  t0 = Clock::now();
  MapShadingStats ms;
  Image image = render_with_map(scene, camera, shader, r.threads, &ms);
  (*stats)["timings_ms"]["shade_and_resolve"] = ms_since(t0);
  (*stats)["abuffer"] = {{"fragments", as.fragments}, {"bytes_per_fragment", as.bytes_per_fragment},
                         {"max_list_length", as.max_list_length}, {"dropped_by_cap", as.dropped_by_cap}};
  (*stats)["searches"] = {{"reflection", search_kind_json(ms.searches.reflection)},
                          {"refraction_exit", search_kind_json(ms.searches.refraction_exit)},
                          {"shadow", search_kind_json(ms.searches.shadow)},
                          {"lens_transfers", ms.lens_transfers}, {"lens_fallbacks", ms.lens_fallbacks},
                          {"envmap_lookups", ms.envmap_lookups}};
  if (reference) {
    const double bound = parallax_bound(scene.render.cube_resolution);
    (*stats)["reference"]["ray_error"] = {
        {"rays", "reflection rays of camera-visible surfaces"},
        {"error_cp", error_stats_json(ms.errors.error_cp)},
        {"error_parallax", error_stats_json(ms.errors.error_parallax)},
        {"false_hits", ms.errors.false_hits},
        {"wrong_object", ms.errors.wrong_object},
        {"bound_1_over_2n2", bound},
        {"error_parallax_within_bound", ms.errors.error_parallax.share_within(bound)}};
  }
  return image;
}

json image_error_json(const ImageError& e) {
  const bool identical = !std::isfinite(e.psnr);
  return {{"rmse", e.rmse}, {"psnr_db", identical ? json("inf") : json(e.psnr)}, {"max_abs", e.max_abs},
          {"share_over_1_255", e.share_over_1}, {"share_over_2_255", e.share_over_2},
          {"compared_as", "sRGB-encoded, clamped to [0,1] (metrics.hpp)"}};
}

}  // namespace

int cmd_render(const std::vector<std::string>& words) {
  const Clock::time_point start = Clock::now();
  SceneData scene;
  const RenderRequest r = parse_request(words, &scene);
  json stats;
  stats["scene"] = r.scene_path;
  stats["method"] = method_name(scene.render.method);
  stats["timings_ms"]["load"] = ms_since(start);
  stats["counts"] = {{"triangles", scene.triangles->triangle_count()},
                     {"dropped_triangles", scene.dropped_triangles},
                     {"objects", scene.objects.size()},
                     {"lights", scene.lights.size()}};
  if (scene.render.error_target > 0) {
    stats["error_target"] = {{"target", scene.render.error_target},
                             {"cube_resolution", scene.render.cube_resolution},
                             {"bound_at_that_n", parallax_bound(scene.render.cube_resolution)}};
  }
  stats["size"] = {{"width", scene.camera.width}, {"height", scene.camera.height},
                   {"cube_resolution", scene.render.cube_resolution},
                   {"max_depth", scene.render.max_depth}};
  stats["threads"] = thread_count(r.threads, SIZE_MAX);

  Image image;
  stats["method_options"] = {{"search", search_mode_name(r.map.search.mode)},
                             {"refine", search_refine_name(r.map.search.refine)},
                             {"theta_max_deg", glm::degrees(r.map.search.theta_max)},
                             {"refraction", refraction_mode_name(r.map.refraction)},
                             {"envmap_lookup", envmap_lookup_name(r.map.lookup)},
                             {"fresnel", scene.render.fresnel}};
  switch (scene.render.method) {
    case Method::gpu:
      image = render_gpu(scene, r, &stats);
      break;
    case Method::abuffer:
    case Method::zbuffer:
    case Method::envmap:
      image = render_map_method(scene, r, &stats);
      stats["gl"] = {{"path", "none"}, {"renderer", "none (CPU A-buffer)"}};
      break;
    case Method::raytrace:
      image = render_reference(scene, r, &stats, "raytrace");
      stats["plan"]["passes"] = {"raytrace"};
      stats["plan"]["skipped"] = {{{"pass", "gl"}, {"why", "the exact tracer needs no GL"}}};
      stats["gl"] = {{"path", "none"}, {"renderer", "none (the tracer is CPU only)"}};
      break;
    default:
      throw RuntimeFailure(std::string("method '") + method_name(scene.render.method) +
                           "' is not in this build yet; use --method gpu");
  }
  if (r.reference) {
    // The error of this image against the exact tracer (the same one image, if raytrace).
    Image ref;
    if (!r.reference_image.empty()) {
      ref = read_image(r.reference_image);
      if (ref.width != image.width || ref.height != image.height) {
        throw InputError(r.reference_image + ": is " + std::to_string(ref.width) + "x" + std::to_string(ref.height) +
                         ", the render is " + std::to_string(image.width) + "x" + std::to_string(image.height));
      }
      stats["reference"]["image"] = r.reference_image;
    } else {
      ref = scene.render.method == Method::raytrace ? image : render_reference(scene, r, &stats, "reference");
    }
    stats["reference"]["image_error"] = image_error_json(image_error(image, ref));
    if (!stats["reference"].contains("ray_error")) {
      stats["reference"]["ray_error"] = std::string("n/a: method ") + method_name(scene.render.method) +
                                        " does no map search (Error_CP and Error_Parallax measure searches)";
    }
  }

  Clock::time_point t0 = Clock::now();
  write_image(r.output, image);
  stats["timings_ms"]["write"] = ms_since(t0);
  stats["timings_ms"]["total"] = ms_since(start);
  stats["memory"] = {{"peak_rss_bytes", peak_rss_bytes()}};
  if (!r.stats_path.empty()) write_text_atomic(r.stats_path, stats.dump(2) + "\n");
  return 0;
}

}  // namespace abcube
