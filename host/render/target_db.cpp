#include "render/target_db.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "base/parallel.hpp"
#include "base/samples.hpp"
#include "base/timer.hpp"
#include "io/metrics.hpp"
#include "reference/raytrace.hpp"
#include "render/stats_json.hpp"

namespace abcube {

using nlohmann::json;

namespace {

// About 4096 sampled pixels (b rounded; at most one in 4, at least one in 64): per-pixel error is
// heavy-tailed (edges, mirrors), and the lower bound's width follows from the sample; the
// pilots' cost, the exact tracer's above all, follows from the sample's size.
constexpr double SAMPLES_WANTED = 4096;
// A pilot that does not raise the best lower bound by this much has not improved; after
// STALLED_PILOTS of them in a row, larger N is not expected to reach the target.
constexpr double IMPROVEMENT_DB = 0.2;
constexpr int STALLED_PILOTS = 2;

// THE COST MODEL (docs/performance.md "Choosing N by cost"). A render's shading time is close
// to NS_PER_RAY a search ray, NS_PER_FRAGMENT a fragment's z-interval test and
// NS_PER_MESH_TRIANGLE a triangle MESH REFINEMENT tests for a crossing; a cube A-buffer's
// build to NS_PER_TRIANGLE a scene triangle and NS_PER_RAW_FRAGMENT a triangle-texel pair.
// Fitted on the 2-core machine (two threads) over the race's and the generated scenes at
// five N and both shading points: only their ratios decide. As N grows by x, the fragments
// tested grow about as x^FRAGMENTS_POWER and the mesh triangles fall as x^MESH_POWER (the
// texels shrink under the triangles), the raw fragments grow at most as x^2.
constexpr double NS_PER_RAY = 539, NS_PER_FRAGMENT = 13.3, NS_PER_MESH_TRIANGLE = 24.3;
constexpr double NS_PER_TRIANGLE = 1007, NS_PER_RAW_FRAGMENT = 117;
constexpr double FRAGMENTS_POWER = 0.5, MESH_POWER = -1.4;
// A larger N is piloted only when the model expects it to shade at most PROBE_SHARE of the
// current N's time, with a saving over the whole image of at least PROBE_COST_FACTOR times
// the pilot's modelled cost (its build and its shading): a pilot's wall time runs 1.2 to 3.5
// times the model's (scattered pixels, its passes over the whole image).
constexpr double PROBE_SHARE = 0.9, PROBE_COST_FACTOR = 2;

uint64_t mix(uint64_t x) {  // splitmix64's finaliser: a fixed, well-spread hash
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

json number_or_null(double x) { return std::isfinite(x) ? json(x) : json(); }

}  // namespace

std::vector<int> target_ladder(int scene_n) {
  std::vector<int> ladder;
  const int top = std::max(1024, scene_n);
  for (int n : {64, 96, 128, 192, 256, 384, 512, 768, 1024, 1536, 2048, 3072, 4096, 6144, 8192}) {
    if (n <= top) ladder.push_back(n);
  }
  if (ladder.back() < top) ladder.push_back(top);
  return ladder;
}

std::vector<uint8_t> pilot_pixels(int width, int height, int* block) {
  const double pixels = static_cast<double>(width) * static_cast<double>(height);
  const int b = std::clamp(static_cast<int>(std::lround(std::sqrt(pixels / SAMPLES_WANTED))), 2, 8);
  *block = b;
  std::vector<uint8_t> only(static_cast<size_t>(width) * static_cast<size_t>(height), 0);
  for (int by = 0; by < height; by += b) {
    for (int bx = 0; bx < width; bx += b) {
      const uint64_t h = mix(static_cast<uint64_t>(by) * 0x10000ull + static_cast<uint64_t>(bx));
      const int x = bx + static_cast<int>(h % static_cast<uint64_t>(std::min(b, width - bx)));
      const int y = by + static_cast<int>((h >> 32) % static_cast<uint64_t>(std::min(b, height - by)));
      only[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)] = 1;
    }
  }
  return only;
}

namespace {

// The pilots' pixels (pilot_pixels) and the exact tracer's colour there.
struct PilotSample {
  int block = 0;
  std::vector<uint8_t> pixels;
  Image exact;
  double trace_ms = 0;
};

PilotSample pilot_sample(MethodContext& mc) {
  PilotSample s;
  s.pixels = pilot_pixels(mc.scene.camera.width, mc.scene.camera.height, &s.block);
  RaytraceOptions ro;
  ro.threads = mc.request.threads;
  // The scene's tree when a render of it already built one; else the tracer builds one for
  // the sample alone, freed before the cube maps are built: the peak holds no tracer's tree.
  if (mc.cache.builds().bvh) ro.bvh = mc.cache.bvh();
  ro.only = &s.pixels;
  const Clock::time_point t0 = Clock::now();
  s.exact = render_raytrace(mc.scene, ro);
  s.trace_ms = ms_since(t0);
  return s;
}

// A pilot's outcome: the sample's error, and the counts of THE COST MODEL.
struct Pilot {
  SampledError error;
  double rays = 0, fragments = 0, mesh_triangles = 0;
  // The model's shading time of the sampled pixels, ns.
  double shading_ns() const {
    return NS_PER_RAY * rays + NS_PER_FRAGMENT * fragments + NS_PER_MESH_TRIANGLE * mesh_triangles;
  }
  // The same at N grown by x.
  double shading_ns_at(double x) const {
    return NS_PER_RAY * rays + NS_PER_FRAGMENT * fragments * std::pow(x, FRAGMENTS_POWER) +
           NS_PER_MESH_TRIANGLE * mesh_triangles * std::pow(x, MESH_POWER);
  }
};

// A stats line with the shading plan's choices. The target never changes the texture
// lookups; method_options has them.
json with_plan(json line, const ShadingPlan& plan) {
  for (const auto& [key, value] : plan.settings()) {
    if (std::string(key) != "texture_lookups") line[key] = value;
  }
  return line;
}

// A pilot: the sampled pixels rendered by `shader`, their error against the tracer's, and a
// line of the stats' "pilots" (its time counted from `t0`, its cube map's build included).
Pilot run_pilot(MethodContext& mc, const ABuffer& camera, const MapShader& shader, const PilotSample& sample, int n,
                Clock::time_point t0, json* pilots) {
  MapShadingStats ms;
  const Image image =
      render_with_map(mc.scene, camera, shader, mc.request.threads, &ms, nullptr, &sample.pixels, false);
  Pilot p;
  const SampledError& e = p.error = sampled_error(image, sample.exact, sample.pixels);
  for (const SearchKindStats* k : {&ms.searches.reflection, &ms.searches.refraction_exit, &ms.searches.shadow}) {
    p.rays += static_cast<double>(k->rays - k->known_blockers);  // a known blocker's answer walks no map
    p.fragments += static_cast<double>(k->fragments);
    p.mesh_triangles += static_cast<double>(k->mesh_triangles);
  }
  pilots->push_back(with_plan({{"cube_resolution", n}}, shader.options().plan));
  pilots->back().update({{"psnr_db", number_or_null(e.psnr)},
                         {"psnr_db_low", number_or_null(e.psnr_low)},
                         {"model_shading_ms", p.shading_ns() * 1e-6},
                         {"ms", ms_since(t0)}});
  return p;
}

// The pilots' state: the sample, every pilot's stats line, and the best map found so far
// (the highest predicted lower bound; the smaller N keeps a tie) with its plan.
struct Pilots {
  Pilots(MethodContext& m, const ABuffer& cam, const ABufferOptions& cube, double db)
      : mc(m), camera(cam), cube_options(cube), target(db), sample(pilot_sample(m)) {}

  MethodContext& mc;
  const ABuffer& camera;
  const ABufferOptions& cube_options;
  const double target;
  const PilotSample sample;
  json lines = json::array();
  CubeMap best;
  Pilot best_pilot;
  MapShadingOptions best_plan;
  bool reached = false;
  std::string why;

  // A pilot of `plan` at N = n, on the best map when it is at that N (only the plan
  // differs), else on a map built for it; the map is kept as the best when the pilot's lower
  // bound is the highest so far.
  Pilot pilot(int n, const MapShadingOptions& plan) {
    check_deadline();
    const Clock::time_point t0 = Clock::now();
    CubeMap m;
    if (best.cube && best.n == n) {
      m.n = n;
      m.stats = best.stats;
      m.build_ms = best.build_ms;
      m.shader = std::make_unique<MapShader>(*best.shader, plan);
    } else {
      m = build_cube_map(mc, n, cube_options, nullptr, plan);
    }
    const Pilot p = run_pilot(mc, camera, *m.shader, sample, n, t0, &lines);
    if (!best.shader || p.error.psnr_low > best_pilot.error.psnr_low) {
      if (!m.cube) m.cube = std::move(best.cube);  // the shared map moves with its new shader
      best = std::move(m);
      best_pilot = p;
      best_plan = plan;
    }
    return p;
  }

  // Climbs the ladder of N with `plan`, up to the first N that reaches the target, or until
  // STALLED_PILOTS pilots in a row improve on the climb's best by less than IMPROVEMENT_DB.
  void climb(const MapShadingOptions& plan) {
    int stalled = 0;
    double climb_best = -std::numeric_limits<double>::infinity();
    why.clear();
    for (const int n : target_ladder(mc.scene.render.cube_resolution)) {
      const SampledError e = pilot(n, plan).error;
      const bool improved = e.psnr_low >= climb_best + IMPROVEMENT_DB;
      climb_best = std::max(climb_best, e.psnr_low);
      if (e.psnr_low >= target) {
        reached = true;
        why = "the smallest N on the ladder whose predicted PSNR reaches the target";
        return;
      }
      stalled = improved ? 0 : stalled + 1;
      if (stalled >= STALLED_PILOTS) {
        why = "the error stopped improving with N before the target: the best N found";
        return;
      }
    }
    why = "the ladder's largest N did not reach the target: the best N found";
  }

  // At the chosen N, the first of `plans` (cheapest first) that still reaches the target.
  void cheapen(const std::vector<MapShadingOptions>& plans) {
    for (const MapShadingOptions& plan : plans) {
      const Clock::time_point t0 = Clock::now();
      auto shader = std::make_unique<MapShader>(*best.shader, plan);
      const Pilot p = run_pilot(mc, camera, *shader, sample, best.n, t0, &lines);
      if (p.error.psnr_low >= target) {
        best_plan = plan;
        best.shader = std::move(shader);
        best_pilot = p;
        return;
      }
    }
  }

  // THE COST MODEL. Above the chosen N, the next rung is piloted with the chosen plan when
  // the model expects its shading to cost at most PROBE_SHARE of the chosen N's, with a
  // saving over the whole image worth the pilot (PROBE_COST_FACTOR); it becomes the choice
  // when it reaches the target and its counts say it shades for less. MESH REFINEMENT's
  // floods shrink with the texels, so a scene whose meshes are finer than the texels may
  // render faster at a larger N.
  void grow() {
    const std::vector<int> ladder = target_ladder(mc.scene.render.cube_resolution);
    const double pixels = static_cast<double>(mc.scene.camera.width) * static_cast<double>(mc.scene.camera.height);
    const double triangles = static_cast<double>(mc.scene.triangles->triangle_count());
    for (const int n : ladder) {
      if (n <= best.n) continue;
      const double x = static_cast<double>(n) / static_cast<double>(best.n);
      const double scale = pixels / static_cast<double>(std::max<uint64_t>(best_pilot.error.pixels, 1));
      const double now = best_pilot.shading_ns(), then = best_pilot.shading_ns_at(x);
      const double build =
          NS_PER_TRIANGLE * triangles + NS_PER_RAW_FRAGMENT * static_cast<double>(best.stats.raw_fragments) * x * x;
      if (!(then <= PROBE_SHARE * now && (now - then) * scale >= PROBE_COST_FACTOR * (build + then))) break;
      check_deadline();
      const Clock::time_point t0 = Clock::now();
      CubeMap m = build_cube_map(mc, n, cube_options, nullptr, best_plan);
      const Pilot p = run_pilot(mc, camera, *m.shader, sample, n, t0, &lines);
      if (!(p.error.psnr_low >= target && p.shading_ns() < now)) break;
      best = std::move(m);
      best_pilot = p;
      why = "a larger N than the smallest reaching the target: the cost model says it shades for less";
    }
  }
};

// The choice into the render's stats: its size, method_options and target_db.
void write_stats(const Pilots& p, json* out) {
  json& stats = *out;
  const ShadingPlan& chosen = p.best_plan.plan;
  stats["size"]["cube_resolution"] = p.best.n;
  for (const auto& [key, value] : chosen.settings()) stats["method_options"][key] = value;
  stats["target_db"] = with_plan({{"target", p.target}, {"cube_resolution", p.best.n}}, chosen);
  stats["target_db"].update(
      {{"scene_cube_resolution", p.mc.scene.render.cube_resolution},
       {"reached", p.reached},
       {"why", p.why},
       {"predicted_psnr_db", number_or_null(p.best_pilot.error.psnr)},
       {"predicted_psnr_db_low", number_or_null(p.best_pilot.error.psnr_low)},
       {"sample",
        {{"pixels", p.best_pilot.error.pixels}, {"block", p.sample.block}, {"exact_trace_ms", p.sample.trace_ms}}},
       {"pilots", p.lines}});
}

}  // namespace

Image raytrace_for_target(MethodContext& mc) {
  const Clock::time_point start = Clock::now();
  const SceneData& scene = mc.scene;
  const double target = scene.render.target_db;
  int block = 0;
  const std::vector<uint8_t> pixels = pilot_pixels(scene.camera.width, scene.camera.height, &block);
  RaytraceOptions ro;
  ro.threads = mc.request.threads;
  ro.bvh = mc.cache.bvh();
  ro.only = &pixels;
  std::array<Image, LOWER_RUNGS> rungs;
  ro.rungs = &rungs;
  RaytraceStats pilot_stats;
  const Image exact = render_raytrace(scene, ro, &pilot_stats);
  // The smallest rung whose lower bound reaches the target; 32 samples are the reference.
  int samples = MASK_SAMPLES;
  const Image* chosen = &exact;
  SampledError chosen_error;
  chosen_error.pixels = 0;
  chosen_error.psnr = chosen_error.psnr_low = std::numeric_limits<double>::infinity();
  json lines = json::array();
  for (int i = 0; i < LOWER_RUNGS; ++i) {
    const SampledError e = sampled_error(rungs[static_cast<size_t>(i)], exact, pixels);
    lines.push_back(
        {{"samples", 1 << i}, {"psnr_db", number_or_null(e.psnr)}, {"psnr_db_low", number_or_null(e.psnr_low)}});
    if (samples == MASK_SAMPLES && e.psnr_low >= target) {
      samples = 1 << i;
      chosen = &rungs[static_cast<size_t>(i)];
      chosen_error = e;
    }
  }
  const double pilot_ms = ms_since(start);
  // The image at that rung: the pilot's pixels from the pilot, the others traced now.
  std::vector<uint8_t> rest(pixels.size());
  for (size_t k = 0; k < pixels.size(); ++k) rest[k] = pixels[k] ? 0 : 1;
  ro.rungs = nullptr;
  ro.only = &rest;
  ro.samples_per_pixel = samples;
  if (mc.progress) ro.progress = [&mc](double done) { mc.progress("raytrace", done); };
  RaytraceStats rs;
  Image image = render_raytrace(scene, ro, &rs);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (pixels[static_cast<size_t>(y) * static_cast<size_t>(image.width) + static_cast<size_t>(x)])
        image.set_rgb(x, y, chosen->rgb(x, y));
    }
  }
  rs.primary_rays += pilot_stats.primary_rays;
  rs.secondary_rays += pilot_stats.secondary_rays;
  rs.shadow_rays += pilot_stats.shadow_rays;
  mc.stats["raytrace"].update(raytrace_json(rs));
  mc.record.tracer_timings_ms["raytrace"] = tracer_timings(rs);
  mc.stats["counts"]["camera_samples_per_pixel"] = samples;
  mc.stats["method_options"]["samples"] = samples;
  mc.stats["target_db"] = {
      {"target", target},
      {"samples", samples},
      {"reached", true},
      {"why", samples == MASK_SAMPLES
                  ? "no rung below 32 samples is predicted to reach the target: the reference's 32"
                  : "the smallest rung of the sample ladder whose predicted PSNR reaches the target"},
      {"predicted_psnr_db", number_or_null(chosen_error.psnr)},
      {"predicted_psnr_db_low", number_or_null(chosen_error.psnr_low)},
      {"sample",
       {{"pixels", std::count(pixels.begin(), pixels.end(), uint8_t{1})},
        {"block", block},
        {"exact_trace_ms", pilot_ms}}},
      {"rungs", lines}};
  mc.record.timings_ms["target_pilots"] = pilot_ms;
  return image;
}

CubeMap cube_map_for_target(MethodContext& mc, const ABuffer& camera, const ABufferOptions& cube_options,
                            const RayTracer* reference) {
  const Clock::time_point start = Clock::now();
  Pilots p(mc, camera, cube_options, mc.scene.render.target_db);
  // The ladder is climbed with the quarters unrefined at the samples first: their pilots
  // cost a fraction of the refined ones', and they reach most targets. Only when they stop
  // short is it climbed again with the plan asked for, whose edges refined at the samples
  // lift the error's floor.
  const MapShadingOptions asked = map_shading_options(mc);
  const auto options_with = [&asked](const ShadingPlan& plan) {
    MapShadingOptions o = asked;
    o.plan = plan;
    return o;
  };
  const ShadingPlan plain = asked.plan.without_edges();
  // Before them, the cheapest plan at the ladder's first N: one shading point a fragment
  // reaches most targets on open scenes, and its pilot costs a fraction of the quarters'.
  const ShadingPlan one = plain.with_points(ShadingPoints::one);
  const int first_n = target_ladder(mc.scene.render.cube_resolution).front();
  const bool one_first = !plain.one_point();  // asked for one or sparse: no pilot before it
  if (one_first && p.pilot(first_n, options_with(one)).error.psnr_low >= p.target) {
    p.reached = true;
    p.why = "one shading point a fragment reaches the target at the ladder's smallest N";
  }
  if (!p.reached) p.climb(options_with(plain));
  if (!p.reached && plain != asked.plan) p.climb(asked);
  if (p.reached) {
    // The plain plan was piloted at this N on its climb, or stopped short below it; one
    // point, at the first N.
    std::vector<MapShadingOptions> plans;
    for (const ShadingPlan& plan : p.best_plan.plan.cheaper()) {
      if (plan == plain && p.best_plan.plan != plain) continue;
      if (one_first && plan == one && p.best.n == first_n) continue;
      plans.push_back(options_with(plan));
    }
    p.cheapen(plans);
    // Then the cost: a plan cheaper than the one kept fell short at this N, and is not
    // expected to reach the target at a larger one.
    p.grow();
  }
  if (reference) {  // the searches' ray errors, measured on the final render only
    const Clock::time_point t0 = Clock::now();
    p.best.shader = std::make_unique<MapShader>(*p.best.shader, p.best_plan, reference);
    p.best.setup_ms = ms_since(t0);
  }
  write_stats(p, &mc.stats);
  mc.record.timings_ms["target_pilots"] = ms_since(start);
  return std::move(p.best);
}

}  // namespace abcube
