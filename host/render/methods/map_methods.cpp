// The map methods (thesis ch. 7): abuffer, zbuffer and envmap. One pipeline, three
// variants of the search (MapVariant): the camera's A-buffer, the cube map around the
// camera only when a material reflects or refracts or a light casts shadows, each camera
// fragment shaded by searches in that map, and the resolve of the masks.
#include <memory>

#include <glm/glm.hpp>

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "base/timer.hpp"
#include "gl/gl_context.hpp"
#include "gl/gl_cube_scan.hpp"
#include "gl/gl_passes.hpp"
#include "gl/gl_resolve_plan.hpp"
#include "io/metrics.hpp"
#include "reference/raytrace.hpp"
#include "render/method.hpp"
#include "render/render_methods.hpp"
#include "render/stats_json.hpp"
#include "render/target_db.hpp"
#include "scene/plan.hpp"
#include "scene/scene_load.hpp"
#include "search/deferred_searches.hpp"
#include "shading/fragment_texture.hpp"
#include "shading/resolve.hpp"

namespace abcube {

using nlohmann::json;

namespace {

// --resolve-on: THE RESOLVE PLAN of `camera` made on GL compute, or none (pack_under_mask on
// the CPU), with where and why in stats["plan"]["resolve_on"]. `held_bytes`: the A-buffers'
// (the memory budget's share the plan may not take). `only` (optional): the pixels to plan,
// those the render resolves (the others, if resolved, go through pack).
std::unique_ptr<ResolvePlan> gl_resolve_plan(MethodContext& mc, const ABuffer& camera, uint64_t held_bytes,
                                             const std::vector<uint8_t>* only) {
  using SearchOn = RenderRequest::SearchOn;
  const RenderRequest& r = mc.request;
  std::unique_ptr<ResolvePlan> plan;
  if (!mc.gl_scene || !r.resolve_on) return plan;
  const SearchOn asked = *r.resolve_on;
  bool on = asked == SearchOn::gpu;
  std::string why = on ? "asked: --resolve-on gpu" : "asked: --resolve-on cpu";
  if (asked == SearchOn::automatic) {
    on = !software_renderer(mc.record.gl_renderer);
    why = on ? "auto: GL is a hardware GPU"
             : "auto: GL is software (" + mc.record.gl_renderer + "), where the CPU's resolve alone is faster";
  }
  if (on) {
    const uint64_t budget = memory_budget_bytes(r.abuffer.max_memory_bytes);
    const uint64_t held = r.abuffer.reserved_bytes + held_bytes;
    ResolvePlanOptions o;
    o.exact_priority = r.map.exact_priority;
    o.max_bytes = budget > held ? budget - held : 1;
    o.only = only;
    ResolvePlanStats s;
    try {
      // THE PROBE first (once a GL scene): a GL whose plans would change the image is refused.
      double probe_ms = 0;
      const GlResolvePlanner& planner = mc.gl_scene->resolve_planner();
      if (const std::string& off = planner.probe(&probe_ms); !off.empty()) {
        throw RuntimeFailure("GPU resolve plan: " + off + "; resolve on the CPU");
      }
      plan = std::make_unique<ResolvePlan>(planner.plan(camera, mc.scene, o, &s));
      mc.record.timings_ms["gpu_resolve_plan"] = probe_ms + s.ms;
      mc.stats["resolve_plan"] = {{"pixels", s.pixels}, {"planned", s.planned}, {"steps", s.steps}, {"bytes", s.bytes}};
    } catch (const RenderTimeout&) {
      throw;
    } catch (const Interrupted&) {
      throw;
    } catch (const std::runtime_error& e) {  // the budget (InputError) or the GL (RuntimeFailure)
      if (asked == SearchOn::gpu) throw;
      why += std::string(", but the GPU's plan was refused: ") + e.what();
      on = false;
    }
  }
  mc.stats["plan"]["resolve_on"] = {{"where", on ? "gpu" : "cpu"}, {"why", why}};
  return plan;
}

// The camera view through the CPU A-buffer with local Phong, for a scene with nothing to
// search: the resolve's rule for intersecting fragments and the texture lookups as the
// request's map options say. `only` (optional): the pixels to render (ResolveOptions::only).
Image render_abuffer_local(MethodContext& mc, const std::vector<uint8_t>* only) {
  const SceneData& scene = mc.scene;
  const RenderRequest& r = mc.request;
  ABufferStats s;
  Clock::time_point t0 = Clock::now();
  const ABuffer camera = build_camera_abuffer(mc, r.abuffer, &s);
  const double build_ms = ms_since(t0);
  ResolveOptions ro;
  ro.threads = r.abuffer.threads;
  ro.exact_priority = r.map.exact_priority;
  ro.only = only;
  const std::unique_ptr<ResolvePlan> plan = gl_resolve_plan(mc, camera, s.bytes_total, only);  // timed on its own
  ro.plan = plan.get();
  t0 = Clock::now();
  const PixelShader shade = local_phong_shader(scene, camera, r.map.plan.texture_samples());
  Image image = resolve_image(camera, *scene.triangles, shade, scene.background, ro);
  mc.record.timings_ms["camera_abuffer"] = build_ms;
  mc.record.timings_ms["resolve"] = ms_since(t0);
  mc.stats["abuffer"] = abuffer_json(s, true);
  return image;
}

// --search-on: the map searches on GL compute, GlCandidateScan's candidates answered by the
// DEFERRED SEARCHES, set on the shader for the render; or none, the CPU walking them.
struct GlSearches {
  std::unique_ptr<GlCandidateScan> scan;
  std::unique_ptr<DeferredSearches> deferred;
  double upload_ms = 0;
  uint64_t scan_bytes = 0;  // the most the scan holds: its upload and one batch
};

// The fewest rays a batch of the GPU's scan takes: below that, its dispatches and read-backs
// cost more than the scan.
constexpr size_t GPU_SCAN_MIN_BATCH = 1024;

// Where the searches walk and why, in stats["plan"]["searches_on"]; the GL's scan when there.
// `held_bytes`: the A-buffers' (the memory budget's share the searches may not take).
GlSearches gl_searches(MethodContext& mc, MapShader& shader, uint64_t held_bytes) {
  using SearchOn = RenderRequest::SearchOn;
  const RenderRequest& r = mc.request;
  GlSearches g;
  bool on = r.search_on == SearchOn::gpu;
  std::string why = on ? "asked: --search-on gpu" : "asked: --search-on cpu";
  if (r.search_on == SearchOn::automatic) {
    why = "auto: ";
    if (software_renderer(mc.record.gl_renderer)) {
      why += "GL is software (" + mc.record.gl_renderer + "), where the CPU's walks are faster";
    } else if (shader.options().search.mode != SearchMode::crossing) {
      why += "the thesis mode's searches walk on the CPU";
    } else {
      on = true;
      why += "GL is a hardware GPU";
    }
  }
  // The memory budget: the rest of the render and the A-buffers, then the scan's upload, then
  // its batches (at most a quarter of what is left) and the answers' store (half).
  const uint64_t budget = memory_budget_bytes(r.abuffer.max_memory_bytes);
  const uint64_t held = r.abuffer.reserved_bytes + held_bytes;
  const uint64_t upload = on ? GlCandidateScan::upload_bytes(shader.context()) : 0;
  const uint64_t left = budget > held + upload ? budget - held - upload : 0;
  DeferredSearchOptions d;
  d.batch_rays = std::min<size_t>(d.batch_rays, left / 4 / GPU_SCAN_RAY_BYTES);
  if (on && d.batch_rays < GPU_SCAN_MIN_BATCH) {
    ABufferOptions o = r.abuffer;
    o.reserved_bytes = held;
    const uint64_t need = upload + 4 * GPU_SCAN_MIN_BATCH * GPU_SCAN_RAY_BYTES;
    try {
      check_abuffer_budget("the GPU's search scan", need, "its upload and a batch of 1024 rays", o, budget);
    } catch (const InputError& e) {
      if (r.search_on == SearchOn::gpu) throw;
      on = false;
      why += std::string(", but the memory budget cannot hold the GPU's scan: ") + e.what();
    }
  }
  if (on) {
    const Clock::time_point t0 = Clock::now();
    try {
      g.scan = std::make_unique<GlCandidateScan>(shader.context());
    } catch (const RuntimeFailure& e) {
      if (r.search_on == SearchOn::gpu) throw;
      on = false;
      why += std::string(", but the GPU cannot hold the map: ") + e.what();
    }
    g.upload_ms = ms_since(t0);
  }
  if (on) {
    const GlCandidateScan& scan = *g.scan;
    // Searches past the store's room walk on the CPU (the same answers). The long way's walks
    // (rays past the scan's loop budget) leave their texels on the GPU in batches within the
    // batch's share.
    d.threads = r.threads;
    d.max_bytes = std::max<uint64_t>(left / 2, DEFERRED_ENTRY_BYTES);
    ScanBatching batching;
    batching.batch_bytes = std::min<uint64_t>(batching.batch_bytes, d.batch_rays * GPU_SCAN_RAY_BYTES);
    g.scan_bytes = upload + d.batch_rays * GPU_SCAN_RAY_BYTES + batching.batch_bytes;
    g.deferred = std::make_unique<DeferredSearches>(
        shader.context(), shader.options().search,
        [&scan, batching](const std::vector<SearchRay>& rays, const SearchOptions& o,
                          const std::vector<ScanStop>& stops) { return scan.scan(rays, o, batching, stops); },
        d);
    shader.defer_searches(g.deferred.get());
  }
  mc.stats["plan"]["searches_on"] = {{"where", on ? "gpu" : "cpu"}, {"why", why}};
  return g;
}

// The GL searches' figures, after the render.
void record_gl_searches(const GlSearches& g, MethodContext& mc) {
  if (!g.deferred) return;
  const DeferredSearchStats d = g.deferred->stats();
  mc.stats["searches"]["deferred"] = {{"passes", d.passes},
                                      {"batches", d.batches},
                                      {"rays", d.rays},
                                      {"candidates", d.candidates},
                                      {"answers_used", d.answers_used},
                                      {"walked_now", d.walked_now},
                                      {"rows_shaded", d.rows_shaded},
                                      {"edge_rows_shaded", d.edge_rows_shaded},
                                      {"texels", d.texels},
                                      {"stopped", d.stopped},
                                      {"rescanned", d.rescanned},
                                      {"bytes", d.bytes},
                                      {"scan_bytes", g.scan_bytes}};
  mc.record.timings_ms["gpu_search_upload"] = g.upload_ms;
  mc.record.timings_ms["gpu_search_scan"] = d.scan_ms;
  mc.record.timings_ms["search_answers"] = d.answer_ms;
}

}  // namespace

std::vector<std::string> map_option_keys() {
  return {"cube_res",        "error_target", "plan",           "search",       "refine",
          "theta_max_deg",   "map_only",     "shading_points", "shadow_edges", "secondary_edges",
          "texture_lookups", "resolve",      "max_layers"};
}

void read_map_options(const RenderOptions& o, MapVariant variant, RenderRequest* r) {
  r->map.variant = variant;
  r->map.threads = r->threads;
  r->map.search.mode = parse_checked(o.search, parse_search_mode);
  r->map.search.refine = parse_checked(o.refine, parse_search_refine);
  r->map.search.theta_max = glm::radians(o.theta_max_deg);
  r->map.search.side_structure = o.side_structure;
  r->map.refraction = parse_checked(o.refraction, parse_refraction_mode);
  r->map.lookup = parse_checked(o.envmap_lookup, parse_envmap_lookup);
  r->map.exact_priority = o.resolve == "exact";
  r->map.plan = ShadingPlan::from_names(o.shading_points, o.shadow_edges, o.secondary_edges, o.texture_lookups);
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
    Image image = render_abuffer_local(mc, only);
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
  const ABuffer camera = build_camera_abuffer(mc, r.abuffer, &as);
  pass_progress(mc, "camera A-buffer", 1.0);
  const double camera_ms = ms_since(camera_start);
  ABufferOptions cube_options = r.abuffer;
  cube_options.reserved_bytes += as.bytes_total;
  const bool target = r.map.variant == MapVariant::abuffer && r.target_pilots && scene.render.target_db > 0;
  const char* cube_pass = target ? "choosing N and the shading (pilots)" : "cube A-buffer";
  pass_progress(mc, cube_pass, 0.0);
  const CubeMap map =
      target ? cube_map_for_target(mc, camera, cube_options, reference.get())
             : build_cube_map(mc, scene.render.cube_resolution, cube_options, reference.get(), map_shading_options(mc));
  pass_progress(mc, cube_pass, 1.0);
  mc.record.timings_ms["cube_abuffer"] = map.build_ms;
  stats["cube_abuffer"] = cube_abuffer_json(map.stats);
  mc.record.timings_ms["map_setup"] = map.setup_ms;
  mc.record.timings_ms["camera_abuffer"] = camera_ms;
  const std::unique_ptr<ResolvePlan> resolve_plan =
      gl_resolve_plan(mc, camera, as.bytes_total + map.stats.bytes_total, only);
  const uint64_t plan_bytes =
      resolve_plan ? resolve_plan->steps.size() * sizeof(ResolveStep) + resolve_plan->offsets.size() * sizeof(uint32_t)
                   : 0;
  map.shader->plan_resolve(resolve_plan.get());
  const GlSearches on_gl =
      mc.gl_scene ? gl_searches(mc, *map.shader, as.bytes_total + map.stats.bytes_total + plan_bytes) : GlSearches{};
  const Clock::time_point t0 = Clock::now();
  MapShadingStats ms;
  std::function<void(double)> shading;
  if (mc.progress) shading = [&mc](double done) { mc.progress("shading", done); };
  Image image = render_with_map(scene, camera, *map.shader, r.threads, &ms, mc.fallback, only, true, &shading);
  mc.record.timings_ms["shade_and_resolve"] = ms_since(t0);
  stats["abuffer"] = abuffer_json(as, false);
  stats["searches"] = map_shading_json(ms);
  record_gl_searches(on_gl, mc);
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

namespace {

// The three variants differ in what a search returns and so in the options they read: the
// lens transfer replaces an exit search (not envmap's lookups), the lookup direction is
// envmap's, and only abuffer chooses its N and shading from --target-db.
class MapMethod : public RenderMethod {
 public:
  MapMethod(MapVariant variant, std::string name, std::string summary)
      : variant_(variant), name_(std::move(name)), summary_(std::move(summary)) {}
  std::string name() const override { return name_; }
  std::string summary() const override { return summary_; }
  std::vector<std::string> reads() const override {
    std::vector<std::string> keys = map_option_keys();
    if (variant_ != MapVariant::envmap) keys.push_back("refraction");
    if (variant_ == MapVariant::envmap) keys.push_back("envmap_lookup");
    if (variant_ == MapVariant::abuffer) keys.push_back("target_db");
    return keys;
  }
  void read_options(const RenderOptions& options, const SceneData& view, RenderRequest* request) const override {
    (void)view;
    read_map_options(options, variant_, request);
    request->target_pilots = variant_ == MapVariant::abuffer;
  }
  Image render(MethodContext& mc) const override {
    Image image = render_map_method(mc);
    mc.record.gl_renderer = "none (CPU A-buffer)";
    return image;
  }

 private:
  MapVariant variant_;
  std::string name_, summary_;
};

}  // namespace

std::unique_ptr<RenderMethod> make_map_method(MapVariant variant) {
  switch (variant) {
    case MapVariant::zbuffer:
      return std::make_unique<MapMethod>(variant, "zbuffer",
                                         "the cube map's nearest layer only: the Z-buffer searches (thesis 7.3)");
    case MapVariant::envmap:
      return std::make_unique<MapMethod>(variant, "envmap",
                                         "environment-map lookups in the cube map's colours, no search (thesis 5.6)");
    case MapVariant::abuffer: break;
  }
  return std::make_unique<MapMethod>(
      variant, "abuffer", "the A-buffered cube map's linear searches (thesis 7.2): the method of this renderer");
}

}  // namespace abcube
