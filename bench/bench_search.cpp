// Search benchmark: the cost and the error of reflection and shadow searches in the cube
// A-buffer (search.hpp) against the map's resolution N. Reflection rays leave camera-visible
// points of reflective surfaces (the exact tracer gives W and R: pixel samples on a seeded
// random grid); shadow rays leave camera-visible points of any surface for each light that
// casts shadows. Each is searched in the map (one thread, so ns/ray is per core) and
// answered exactly. Per scene, N, mode, kind and HIERARCHICAL SKIP (search_scan.hpp; off:
// the plain walk): hit rate (shadows: rays with a blocker), agreement with the exact tracer
// (same object or both find nothing; shadows: the same transmittance), same% (answers bit for
// bit those of the plain walk), texels visited per ray (mean, max), pyramid nodes stepped
// over and both together (visits), fragments tested per ray, ns per ray (median of R runs,
// min, max) and its ratio to the previous N (about 2 per doubling if the cost is linear in
// N), Error_Parallax of the found points (reflections: mean, p99, max; thesis 9.3) against
// the thesis bound 1/(2 N^2) and the share of hits above it; misses by reason (no crossing,
// threshold, zero-area surface, walk cap). Per N: the map's build time and the bytes of the
// block bounds and of the pyramid above them.
//
//   bench_search SCENE.json... [--sizes 64,128,256,512,1024] [--runs 3] [--rays 20000]
//                [--modes crossing,thesis] [--kinds reflection,shadow] [--hierarchy off,on]
//                [--layers all|nearest] [--merge on|off] [--seed 1]
#include <algorithm>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "raster/abuffer.hpp"
#include "scene/camera.hpp"
#include "base/error.hpp"
#include "io/metrics.hpp"
#include "reference/raytrace.hpp"
#include "scene/scene_load.hpp"
#include "search/search.hpp"
#include "base/timer.hpp"

namespace abcube {
namespace {

struct Options {
  std::vector<std::string> scenes;
  std::vector<int> sizes{64, 128, 256, 512, 1024};
  std::vector<std::string> modes{"crossing", "thesis"};  // SearchMode names
  std::vector<std::string> kinds{"reflection", "shadow"};
  std::vector<std::string> hierarchy{"off", "on"};  // SearchOptions::hierarchy
  std::string layers = "all";                       // all | nearest (SearchLayers)
  std::string merge = "on";                         // on: the renderer's default map
  int runs = 3;
  int rays = 20000;
  unsigned seed = 1;
};

// The command line: every option with its default and unit in --help.
void add_options(BenchCommandLine& line, Options& o) {
  line.files("scenes", o.scenes, "scene files (SCENE.json...)");
  line.numbers("--sizes", o.sizes, "cube resolutions N, texels per face edge (comma-separated)", 1, 65536);
  line.choices("--modes", o.modes, "search modes (comma-separated)", {"crossing", "thesis"});
  line.choices("--kinds", o.kinds, "searches measured (comma-separated)", {"reflection", "shadow"});
  line.choices("--hierarchy", o.hierarchy, "hierarchical skip off (the plain walk) and/or on (comma-separated)",
               {"off", "on"});
  line.choice("--layers", o.layers, "map layers searched", {"all", "nearest"});
  line.choice("--merge", o.merge, "merge the cube A-buffer's fragments as the renderer does", {"on", "off"});
  line.number("--runs", o.runs, "timed runs per row (median, min and max reported)", 1, 1000000);
  line.number("--rays", o.rays, "rays per scene and kind", 1, 1000000000);
  line.number("--seed", o.seed, "seed of the random pixel samples");
}

// A reflection ray and the exact answer for it.
struct ReflectionRay {
  glm::dvec3 w, r;
  bool exact = false;
  uint32_t object = 0;
};

// A shadow ray and the exact light visibility S_l.
struct ShadowRay {
  glm::dvec3 p;
  size_t light = 0;
  glm::dvec3 exact{1.0};
};

// Camera-visible hits at random pixel samples: calls take(hit, view direction) until it
// has had `count` or after 200 tries per wanted ray.
template <class Take>
void visible_hits(const SceneData& scene, const RayTracer& tracer, int count, unsigned seed, Take&& take) {
  const CameraFrame frame = make_camera_frame(scene.camera);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> x(0.0, frame.width), y(0.0, frame.height);
  int taken = 0;
  for (long tries = 0; taken < count && tries < 200L * count; ++tries) {
    const glm::dvec3 d = glm::normalize(frame.direction(x(rng), y(rng)));
    Hit h;
    if (tracer.intersect(frame.eye, d, &h) && take(h, d)) ++taken;
  }
}

// Up to `count` reflection rays from camera-visible reflective points.
std::vector<ReflectionRay> reflection_rays(const SceneData& scene, const RayTracer& tracer, int count, unsigned seed) {
  std::vector<ReflectionRay> out;
  visible_hits(scene, tracer, count, seed, [&](const Hit& h, const glm::dvec3& d) {
    if (scene.materials[h.material_id].reflect <= 0.0) return false;
    const Ray ray = tracer.reflected_ray(h, d);
    ReflectionRay rr{h.point, ray.dir};
    Hit e;
    rr.exact = tracer.intersect(ray.origin, ray.dir, &e);
    rr.object = e.object_id;
    out.push_back(rr);
    return true;
  });
  return out;
}

// Up to `count` shadow rays: camera-visible points, each towards every light casting shadows.
std::vector<ShadowRay> shadow_rays(const SceneData& scene, const RayTracer& tracer, int count, unsigned seed) {
  std::vector<ShadowRay> out;
  visible_hits(scene, tracer, count, seed, [&](const Hit& h, const glm::dvec3&) {
    bool any = false;
    for (size_t k = 0; k < scene.lights.size() && static_cast<int>(out.size()) < count; ++k) {
      if (!scene.lights[k].cast_shadows) continue;
      out.push_back({h.point, k, tracer.light_visibility(h, scene.lights[k], nullptr)});
      any = true;
    }
    return any;
  });
  return out;
}

struct Row {
  double ns_median = 0, ns_min = 0, ns_max = 0;
  SearchKindStats stats;
  ErrorStats parallax;
  uint64_t agree = 0, over_bound = 0, same = 0;
  bool reflection = true;
};

// ns per ray of `runs` runs of search_all(&stats) over `count` rays.
template <class SearchAll>
void time_runs(int runs, size_t count, SearchAll&& search_all, Row* row) {
  std::vector<double> ns;
  for (int run = 0; run < runs; ++run) {
    SearchKindStats stats;
    const Clock::time_point start = Clock::now();
    search_all(&stats);
    ns.push_back(ms_since(start) * 1e6 / static_cast<double>(count));
    row->stats = stats;
  }
  std::sort(ns.begin(), ns.end());
  row->ns_median = ns[ns.size() / 2];
  row->ns_min = ns.front();
  row->ns_max = ns.back();
}

Row measure(const SearchContext& ctx, const std::vector<ReflectionRay>& rays, const SearchOptions& so, int runs) {
  Row row;
  time_runs(
      runs, rays.size(),
      [&](SearchKindStats* stats) {
        for (const ReflectionRay& rr : rays) stats->add(reflection_search(ctx, rr.w, rr.r, so));
      },
      &row);
  // Errors and the plain walk's answers, outside the timed loop.
  SearchOptions plain = so;
  plain.hierarchy = false;
  const double bound = 1.0 / (2.0 * ctx.cube().n * ctx.cube().n);
  for (const ReflectionRay& rr : rays) {
    const SearchResult r = reflection_search(ctx, rr.w, rr.r, so);
    row.same += same_answer(r, reflection_search(ctx, rr.w, rr.r, plain));
    row.agree += r.hit == rr.exact && (!r.hit || r.object_id == rr.object);
    if (r.hit && glm::length(r.point - rr.w) > 0.0) {
      const double e = error_parallax(r.point, rr.w, rr.r);
      row.parallax.add(e);
      row.over_bound += e > bound;
    } else if (rr.exact) {
      row.parallax.add_miss();
    }
  }
  return row;
}

Row measure(const SearchContext& ctx, const std::vector<ShadowRay>& rays, const SearchOptions& so, int runs) {
  Row row;
  row.reflection = false;
  const std::vector<PointLight>& lights = ctx.scene().lights;
  time_runs(
      runs, rays.size(),
      [&](SearchKindStats* stats) {
        for (const ShadowRay& sr : rays) stats->add(shadow_search(ctx, sr.p, lights[sr.light].position, so));
      },
      &row);
  SearchOptions plain = so;
  plain.hierarchy = false;
  for (const ShadowRay& sr : rays) {
    const ShadowResult r = shadow_search(ctx, sr.p, lights[sr.light].position, so);
    row.same += same_answer(r, shadow_search(ctx, sr.p, lights[sr.light].position, plain));
    row.agree += glm::length(r.transmittance - sr.exact) < 1e-6;
  }
  return row;
}

void print_header() {
  std::printf(
      "%-36s %5s %-8s %-10s %4s %6s %6s %6s %6s %7s %6s %7s %6s %7s %6s %9s %9s %9s %6s %9s %9s %9s %9s %6s %6s "
      "%6s %5s %5s\n",
      "scene", "N", "mode", "kind", "hier", "rays", "hit%", "agree%", "same%", "texels", "nodes", "visits", "max",
      "frags", "cands", "ns/ray", "min", "max", "x/2N", "EP mean", "EP p99", "EP max", "1/(2N^2)", ">bnd%", "m:none",
      "m:thr", "m:0A", "m:cap");
}

void print_row(const std::string& scene, int n, SearchMode mode, const std::string& hier, const Row& r,
               double previous_ns) {
  const double rays = static_cast<double>(r.stats.rays);
  const double hits = static_cast<double>(r.parallax.count());
  char ratio[16] = "-";
  if (previous_ns > 0) std::snprintf(ratio, sizeof ratio, "%.2f", r.ns_median / previous_ns);
  char errors[128] = "        -         -         -         -      -";
  if (r.reflection) {
    std::snprintf(errors, sizeof errors, "%9.2e %9.2e %9.2e %9.2e %6.1f", r.parallax.mean(),
                  r.parallax.percentile(0.99), r.parallax.max(), 1.0 / (2.0 * n * n),
                  hits > 0 ? 100.0 * static_cast<double>(r.over_bound) / hits : 0.0);
  }
  std::printf(
      "%-36s %5d %-8s %-10s %4s %6llu %6.1f %6.1f %6.1f %7.1f %6.1f %7.1f %6llu %7.1f %6.1f %9.0f %9.0f %9.0f %6s "
      "%s %6llu %6llu %5llu %5llu\n",
      scene.c_str(), n, search_mode_name(mode), r.reflection ? "reflection" : "shadow", hier.c_str(),
      static_cast<unsigned long long>(r.stats.rays), 100.0 * static_cast<double>(r.stats.hits) / rays,
      100.0 * static_cast<double>(r.agree) / rays, 100.0 * static_cast<double>(r.same) / rays, r.stats.mean_texels(),
      r.stats.mean_nodes(), r.stats.mean_texels() + r.stats.mean_nodes(),
      static_cast<unsigned long long>(r.stats.max_texels), static_cast<double>(r.stats.fragments) / rays,
      static_cast<double>(r.stats.candidates) / rays, r.ns_median, r.ns_min, r.ns_max, ratio, errors,
      static_cast<unsigned long long>(r.stats.misses - r.stats.threshold_rejections - r.stats.zero_area -
                                      r.stats.aborted),
      static_cast<unsigned long long>(r.stats.threshold_rejections), static_cast<unsigned long long>(r.stats.zero_area),
      static_cast<unsigned long long>(r.stats.aborted));
  std::fflush(stdout);
}

int run(const Options& o) {
  // The command line's names (checked by BenchCommandLine) as the search's enums.
  std::vector<SearchMode> modes;
  for (const std::string& name : o.modes) {
    SearchMode m;
    if (!parse_search_mode(name, &m)) throw InputError("--modes: unknown mode " + name);
    modes.push_back(m);
  }
  const SearchLayers layers = o.layers == "all" ? SearchLayers::all : SearchLayers::nearest;
  std::printf(
      "# bench_search: one thread; ns/ray median of %d runs (min, max); x/2N = ns/ray ratio to the previous "
      "N (2.00 = linear in N); agree = same object as the exact tracer or both miss (shadows: same "
      "transmittance); same = answer bit for bit the plain walk's; visits = texels + pyramid nodes stepped "
      "over; EP = Error_Parallax of hits (thesis 9.3); layers %s, merge %s\n",
      o.runs, o.layers.c_str(), o.merge.c_str());
  print_header();
  for (const std::string& path : o.scenes) {
    const SceneData scene = load_scene(path);
    const RayTracer tracer(scene);
    std::vector<ReflectionRay> reflections;
    std::vector<ShadowRay> shadows;
    for (const std::string& kind : o.kinds) {
      if (kind == "reflection") reflections = reflection_rays(scene, tracer, o.rays, o.seed);
      if (kind == "shadow") shadows = shadow_rays(scene, tracer, o.rays, o.seed);
    }
    if (reflections.empty() && shadows.empty()) {
      std::printf("%-36s no ray of the kinds asked\n", path.c_str());
      continue;
    }
    // Previous ns/ray per (mode, kind, hierarchy) row, for the ratio column.
    std::vector<double> previous(modes.size() * 2 * o.hierarchy.size(), 0.0);
    for (const int n : o.sizes) {
      const Clock::time_point start = Clock::now();
      ABufferOptions ao;
      ao.merge = o.merge == "on";
      const CubeABuffer cube = build_cube_abuffer(scene, scene.camera.position, n, ao);
      const double build_ms = ms_since(start);
      const SearchContext ctx(scene, cube);
      for (size_t m = 0; m < modes.size(); ++m) {
        for (size_t kind = 0; kind < 2; ++kind) {
          if (kind == 0 ? reflections.empty() : shadows.empty()) continue;
          for (size_t h = 0; h < o.hierarchy.size(); ++h) {
            SearchOptions so;
            so.mode = modes[m];
            so.layers = layers;
            so.hierarchy = o.hierarchy[h] == "on";
            const Row row = kind == 0 ? measure(ctx, reflections, so, o.runs) : measure(ctx, shadows, so, o.runs);
            double& prev = previous[(m * 2 + kind) * o.hierarchy.size() + h];
            print_row(path, n, modes[m], o.hierarchy[h], row, prev);
            prev = row.ns_median;
          }
        }
      }
      std::printf(
          "# %s N=%d: cube A-buffer built in %.0f ms, %zu zero-area triangles; block bounds %.1f KiB, "
          "pyramid above them %.1f KiB (+%.1f%%)\n",
          path.c_str(), n, build_ms, ctx.zero_area_triangles().size(),
          static_cast<double>(ctx.block_bounds_bytes()) / 1024.0, static_cast<double>(ctx.pyramid_bytes()) / 1024.0,
          100.0 * static_cast<double>(ctx.pyramid_bytes()) / static_cast<double>(ctx.block_bounds_bytes()));
    }
  }
  return 0;
}

}  // namespace
}  // namespace abcube

int main(int argc, char** argv) {
  return abcube::bench_main<abcube::Options>(argc, argv, "bench_search",
                                             "Reflection and shadow searches in the cube A-buffer: cost per ray and "
                                             "error against N, with and without the hierarchical skip",
                                             abcube::add_options, abcube::run);
}
