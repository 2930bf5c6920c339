// abcube::Renderer: the one render pipeline. The CLI's `render` and `batch`, the Python
// module and the tests call it; each method's passes are in render_methods.cpp.
#include <abcube/renderer.hpp>

#include <abcube/options.hpp>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <thread>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "base/error.hpp"
#include "base/memory.hpp"
#include "base/parallel.hpp"
#include "base/timer.hpp"
#include "gl/gl_context.hpp"
#include "gl/gl_passes.hpp"
#include "render/aovs.hpp"
#include "render/method.hpp"
#include "render/render_methods.hpp"
#include "render/stats_json.hpp"
#include "scene/framing.hpp"
#include "scene/plan.hpp"
#include "scene/radiance.hpp"
#include "scene/scene_load.hpp"
#include "shading/scene_cache.hpp"

namespace abcube {

using nlohmann::json;

namespace {

// A finite 3-vector, or InputError naming the option.
glm::dvec3 finite_vec3(const std::array<double, 3>& v, const char* name) {
  for (double x : v) {
    if (!std::isfinite(x)) throw InputError(std::string("camera.") + name + ": must be finite numbers");
  }
  return {v[0], v[1], v[2]};
}

// The scene's camera with the keys the override gives, validated as the scene file's is.
Camera override_camera(Camera c, const CameraOverride& o) {
  if (o.position) c.position = finite_vec3(*o.position, "position");
  if (o.look_at) c.look_at = finite_vec3(*o.look_at, "look_at");
  if (o.up) c.up = finite_vec3(*o.up, "up");
  if (o.fov_y) {
    if (!(*o.fov_y > 0 && *o.fov_y < 180)) {
      throw InputError("camera.fov_y: must be > 0 and < 180 (degrees), got " + std::to_string(*o.fov_y));
    }
    c.fov_y_deg = *o.fov_y;
  }
  for (auto [value, name, out] : {std::tuple{o.width, "width", &c.width}, std::tuple{o.height, "height", &c.height}}) {
    if (!value) continue;
    if (*value < 1 || *value > 65536) {
      throw InputError(std::string("camera.") + name + ": must be in [1, 65536], got " + std::to_string(*value));
    }
    *out = *value;
  }
  const glm::dvec3 view = c.look_at - c.position;
  if (!(glm::length(view) > 0)) throw InputError("camera.look_at: must differ from camera.position");
  if (!(glm::length(glm::cross(glm::normalize(view), c.up)) > 1e-9)) {
    throw InputError("camera.up: must not be parallel to the view direction");
  }
  return c;
}

// The render request: the scene's settings with the options' overrides, validated, and
// what the method reads of its own options.
RenderRequest make_request(const SceneData& base, const RenderOptions& o, int renderer_threads, SceneData* view,
                           const RenderMethod** method) {
  check_render_options(o);  // every value in range, with the option table's messages
  RenderRequest r;
  *view = base;  // shares the triangles (SharedTriangles)
  RenderSettings& rs = view->render;
  if (!o.method.empty()) rs.method = o.method;
  *method = &method_named(rs.method);
  if (o.target_db > 0) rs.target_db = o.target_db;
  // An N or samples the render asks for, or a bound that gives an N, wins over the scene's
  // target; the scene's target wins over its own samples (as over its own N).
  if (o.cube_resolution != 0 || o.error_target >= 0 || o.samples != 0) rs.target_db = 0;
  if (o.samples != 0) rs.samples = o.samples;
  if (o.error_target >= 0) rs.error_target = o.error_target;
  if (rs.target_db > 0) rs.error_target = 0;  // the scene's target wins over its bound
  if (rs.error_target > 0 && o.cube_resolution == 0) {
    // thesis 9.3.4: the N whose bound 1/(2 N^2) meets the target (plan.hpp).
    rs.cube_resolution = resolution_for_error(rs.error_target);
  }
  if (o.cube_resolution != 0) rs.cube_resolution = o.cube_resolution;
  if (o.max_depth >= 0) {
    rs.max_depth = o.max_depth;
    check_radiance(*view, rs.max_depth, view->file + ": ");  // deeper bounces, a larger bound
  }
  if (o.fresnel) rs.fresnel = *o.fresnel;
  view->camera = override_camera(view->camera, o.camera);
  // A framed camera (model files, "frame": "all") given a new size or field of view frames
  // the scene again, as the file would have with those values, unless the render places
  // the camera itself.
  const CameraOverride& oc = o.camera;
  if (base.frame_direction && !oc.position && !oc.look_at && (oc.width || oc.height || oc.fov_y || oc.up)) {
    view->camera = frame_camera(view->bounds(), *base.frame_direction, view->camera);
  }
  const uint64_t pixels = static_cast<uint64_t>(view->camera.width) * static_cast<uint64_t>(view->camera.height);
  if (o.max_pixels > 0 && pixels > o.max_pixels) {
    throw InputError(view->file + ": camera: " + std::to_string(view->camera.width) + "x" +
                     std::to_string(view->camera.height) + " = " + std::to_string(pixels) +
                     " pixels exceeds --max-pixels " + std::to_string(o.max_pixels));
  }
  r.threads = o.threads > 0 ? o.threads : renderer_threads;
  r.reference_image = o.reference_image;
  r.reference = o.reference || !o.reference_image.empty();
  r.plan_everything = o.plan_everything;
  r.abuffer.threads = r.threads;
  r.abuffer.max_layers = o.max_layers;
  r.abuffer.max_memory_bytes = o.max_memory_mib << 20;  // the whole render's budget
  r.aovs = o.aovs;
  (*method)->read_options(o, *view, &r);
  // Everything but the A-buffers' fragments, from the declared sizes, before any pass; the
  // A-buffers get what is left when they have counted their fragments.
  const uint64_t budget = memory_budget_bytes(r.abuffer.max_memory_bytes);
  r.abuffer.reserved_bytes = (*method)->render_bytes(*view);
  if (r.abuffer.reserved_bytes > budget) {
    check_render_size(*view, (*method)->needs_gl(), budget, o.max_memory_mib > 0);  // names the sizes
    throw InputError(view->file + ": render: method " + view->render.method + " estimates " +
                     std::to_string(r.abuffer.reserved_bytes >> 20) + " MiB before its A-buffers, " +
                     budget_words(budget, o.max_memory_mib > 0));
  }
  return r;
}

// What a render's stats say before any pass: the scene, sizes, method and its options.
json request_stats(const SceneData& view, const RenderRequest& request, const RenderOptions& o) {
  json stats;
  stats["scene"] = view.file;
  stats["method"] = view.render.method;
  stats["counts"] = {{"triangles", view.triangles->triangle_count()},
                     {"dropped_triangles", view.dropped_triangles},
                     {"objects", view.objects.size()},
                     {"lights", view.lights.size()}};
  const std::vector<std::string> targeted = methods_reading("target_db");
  if (view.render.target_db > 0 && std::find(targeted.begin(), targeted.end(), view.render.method) == targeted.end()) {
    stats["target_db"] = {{"target", view.render.target_db},
                          {"why", "not used: only " + join(targeted, " and ") +
                                      " choose their cost from a target, the method is " + view.render.method}};
  }
  if (view.render.error_target > 0) {
    stats["error_target"] = {{"target", view.render.error_target},
                             {"cube_resolution", view.render.cube_resolution},
                             {"bound_at_that_n", parallax_bound(view.render.cube_resolution)}};
  }
  stats["size"] = {{"width", view.camera.width},
                   {"height", view.camera.height},
                   {"cube_resolution", view.render.cube_resolution},
                   {"max_depth", view.render.max_depth}};
  stats["threads"] = thread_count(request.threads, SIZE_MAX);
  // The options as given, whichever the method reads (the same keys for every method).
  stats["method_options"] = {{"search", o.search},
                             {"refine", o.refine},
                             {"theta_max_deg", glm::degrees(glm::radians(o.theta_max_deg))},
                             {"refraction", o.refraction},
                             {"envmap_lookup", o.envmap_lookup},
                             {"resolve", o.resolve},
                             {"side_structure", o.side_structure},
                             {"fresnel", view.render.fresnel}};
  const ShadingPlan plan =
      ShadingPlan::from_names(o.shading_points, o.shadow_edges, o.secondary_edges, o.texture_lookups);
  for (const auto& [key, value] : plan.settings()) stats["method_options"][key] = value;
  return stats;
}

// The record into the stats JSON, once: the passes' timings, the tracers' and the GL's path.
void write_record(const RenderRecord& record, json* stats) {
  (*stats)["timings_ms"] = record.timings_ms;
  for (const auto& [tracer, timings] : record.tracer_timings_ms) (*stats)[tracer]["timings_ms"] = timings;
  (*stats)["gl"]["path"] = record.gl_path;
  (*stats)["gl"]["renderer"] = record.gl_renderer;
}

// RenderStats (renderer.hpp) from the record, beside the JSON.
RenderStats render_stats(const RenderRecord& record, const json& stats, int built, std::optional<double> psnr,
                         bool with_json) {
  RenderStats rs;
  rs.total_ms = record.timings_ms.at("total");
  rs.timings_ms = record.timings_ms;
  for (const auto& [tracer, timings] : record.tracer_timings_ms) {  // "raytrace.trace", "reference.bvh_build"
    for (const auto& [pass, ms] : timings) rs.timings_ms[tracer + "." + pass] = ms;
  }
  rs.gl_path = record.gl_path;
  rs.gl_renderer = record.gl_renderer;
  rs.scene_data_built = built;
  rs.psnr_db = psnr;
  if (with_json) rs.json = stats.dump(2);
  return rs;
}

// The render's time limit from `start` (none when timeout_s is 0).
Deadline render_deadline(Clock::time_point start, double timeout_s) {
  if (timeout_s < 0 || std::isnan(timeout_s)) {
    throw InputError("timeout: must be >= 0 seconds, got " + std::to_string(timeout_s));
  }
  Deadline deadline;
  if (timeout_s > 0) {
    deadline.seconds = timeout_s;
    deadline.at = start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
  }
  return deadline;
}

// What a render built of the per-scene data, between the cache's counts `before` and `after`.
json scene_data_stats(const SceneCache::Builds& before, const SceneCache::Builds& after, int built, double load_ms) {
  return {{"built_by_this_render", built},
          {"scene_load_ms", load_ms},
          {"mesh_neighbours", {{"built", after.neighbours - before.neighbours}, {"ms", after.neighbours_ms}}},
          {"lens_fits", {{"built", after.lenses - before.lenses}, {"ms", after.lenses_ms}}},
          {"bvh", {{"built", after.bvh - before.bvh}, {"ms", after.bvh_ms}}}};
}

}  // namespace

struct Renderer::Impl {
  RendererOptions options;
  GlChoice gl_choice = GlChoice::automatic;
  std::mutex mutex;  // one render at a time per Renderer
  uint64_t renders = 0;
  // GL: opened on the first render that needs it, on that render's thread.
  bool gl_tried = false;
  std::unique_ptr<GlContext> gl;
  std::string gl_log;
  std::thread::id gl_thread;
  // The scene uploaded to GL last, kept while the next render draws the same scene.
  std::optional<Scene> gl_scene_owner;
  std::unique_ptr<GlScene> gl_scene;

  GlContext* open_gl() {
    if (!gl_tried) {
      gl_tried = true;
      gl = open_gl_context(gl_choice, options.gl_device, &gl_log);
      gl_thread = std::this_thread::get_id();
    }
    if (gl && std::this_thread::get_id() != gl_thread) {
      throw RuntimeFailure(
          "this Renderer opened GL on another thread; GL contexts are current per thread: "
          "use one Renderer per thread");
    }
    return gl.get();
  }

  GlScene& gl_scene_for(const Scene& scene, bool* uploaded) {
    *uploaded = !gl_scene_owner || &gl_scene_owner->data() != &scene.data();
    if (*uploaded) {
      gl_scene.reset();
      gl_scene_owner = scene;
      gl_scene = std::make_unique<GlScene>(scene.data());
    }
    return *gl_scene;
  }

  // A method that draws with GL: GL opened (a clear error where no path works), the scene
  // uploaded unless it is the last one's, then the method.
  Image render_on_gl(const Scene& scene, const RenderMethod& method, MethodContext& mc) {
    const SceneData& view = mc.scene;
    json& stats = mc.stats;
    const Clock::time_point t0 = Clock::now();
    const bool first_open = !gl_tried;
    GlContext* ctx = open_gl();
    const std::string which = "--method " + method.name();
    if (!ctx) {
      if (gl_choice == GlChoice::none) throw InputError(which + " needs OpenGL, but --gl none was given");
      std::string log = gl_log;
      for (char& c : log) c = c == '\n' ? ';' : c;
      throw RuntimeFailure(which + " needs OpenGL and no GL path works here: " + log);
    }
    stats["gl"] = gl_json(*ctx);
    mc.record.gl_path = ctx->info().api;
    mc.record.gl_renderer = ctx->info().gl_renderer;
    mc.record.timings_ms["gl_init"] = first_open ? ms_since(t0) : 0.0;
    check_gl_limits(view);  // before the upload
    bool uploaded = false;
    mc.gl_scene = &gl_scene_for(scene, &uploaded);
    // The soup's positions and normals as the GL's vertex buffers: the same memory, or a copy.
    stats["gl"]["scene_buffers"] = mc.gl_scene->soup_pinned() ? "pinned" : "copied";
    // Each triangle's ids: read by the vertex stage from the soup's arrays, or carried by every vertex.
    stats["gl"]["scene_ids"] = mc.gl_scene->triangle_ids() ? "per triangle" : "per vertex";
    if (!uploaded) mc.gl_before = mc.gl_scene->timings();  // else its upload is this render's
    return method.render(mc);
  }
};

Renderer::Renderer(const RendererOptions& options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  if (!parse_gl_choice(options.gl, &impl_->gl_choice)) {
    throw InputError("gl: unknown path " + quote(options.gl) +
                     " (auto, egl, egl-device, egl-surfaceless, osmesa, none)");
  }
  if (options.threads < 0) throw InputError("threads: must be >= 0, got " + std::to_string(options.threads));
  if (options.gl_device < -1) throw InputError("gl-device: must be >= 0, got " + std::to_string(options.gl_device));
}

Renderer::~Renderer() {
  // The GL objects go before the context they live in.
  if (impl_) {
    impl_->gl_scene.reset();
    impl_->gl.reset();
  }
}

std::string Renderer::gl_path() const {
  if (!impl_->gl_tried) return "";
  return impl_->gl ? impl_->gl->info().api : "none";
}

std::string Renderer::gl_renderer() const { return impl_->gl ? impl_->gl->info().gl_renderer : ""; }

uint64_t Renderer::renders() const { return impl_->renders; }

void request_stop(int signal) { stop_request().store(signal > 0 ? signal : 1, std::memory_order_relaxed); }
void clear_stop_request() { stop_request().store(0, std::memory_order_relaxed); }
bool stop_requested() { return stop_request().load(std::memory_order_relaxed) != 0; }

RenderResult Renderer::render(const Scene& scene, const RenderOptions& options) {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  const Clock::time_point start = Clock::now();
  const Deadline deadline = render_deadline(start, options.timeout_s);
  const ScopedDeadline scope(options.timeout_s > 0 ? &deadline : nullptr);

  SceneData view;
  const RenderMethod* method = nullptr;
  const RenderRequest request = make_request(scene.data(), options, impl_->options.threads, &view, &method);
  const SceneCache::Builds before = scene.cache().builds();
  json stats = request_stats(view, request, options);
  Image fallback;  // the map methods' "fallback" AOV, when asked
  const bool wants_fallback = std::find(request.aovs.begin(), request.aovs.end(), "fallback") != request.aovs.end();
  RenderRecord record;
  MethodContext mc{
      view, scene.cache(), request, stats, record, options.progress, nullptr, {}, wants_fallback ? &fallback : nullptr};
  Image image = method->needs_gl() ? impl_->render_on_gl(scene, *method, mc) : method->render(mc);
  std::optional<double> psnr;
  if (request.reference) psnr = add_reference_error(mc, image);
  RenderResult result;
  if (!request.aovs.empty()) {
    const Clock::time_point t0 = Clock::now();
    result.aovs = render_aovs(mc, request.aovs);
    record.timings_ms["aovs"] = ms_since(t0);
  }

  // What this render built of the per-scene data (0 when an earlier render did).
  const SceneCache::Builds after = scene.cache().builds();
  const int built = (after.neighbours - before.neighbours) + (after.lenses - before.lenses) + (after.bvh - before.bvh);
  stats["scene_data"] = scene_data_stats(before, after, built, scene.load_ms());
  ++impl_->renders;
  stats["renderer"] = {{"renders", impl_->renders}};
  record.timings_ms["total"] = ms_since(start);
  stats["memory"] = {{"peak_rss_bytes", peak_rss_bytes()}};
  write_record(record, &stats);

  result.image = std::move(image);
  result.stats = render_stats(record, stats, built, psnr, options.stats);
  return result;
}

// What each method honours (docs/methods.md; renderer.hpp).
SceneData scene_view(const SceneData& base, const RenderOptions& options) {
  SceneData view;
  const RenderMethod* method = nullptr;
  make_request(base, options, 0, &view, &method);
  return view;
}

void refuse_unused_options(const Scene& scene, const RenderOptions& options) {
  refuse_options_unused_by(scene.method(), options);
}

}  // namespace abcube
