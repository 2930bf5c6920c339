// GL passes benchmark: the six-face distance prepass and the camera-view raster at several
// cube resolutions, median of R runs, with the renderer string, and the prepass's error
// against the exact tracer (relative distance at texel centres), so no speed is quoted
// without its error. Beside it, the CPU cube A-buffer build of the same faces (every
// fragment of every surface) and its ratio to the GPU prepass, and the same A-buffer built by
// GL compute shaders (gl_abuffer.hpp) with the share of its lists identical to the CPU's.
// Then the searches' cube walks of the scene's rays (gl_cube_walks.hpp scene_walk_rays) on the
// GPU and by CubeWalk on one CPU thread, with the share of walks identical; and the searches'
// candidates in the cube A-buffer (gl_cube_scan.hpp scene_search_rays) on the GPU and by
// scan_candidates on one CPU thread, with the share of rays whose candidates are identical.
// Last, the camera's resolve with local Phong on every core: pack_under_mask alone, THE
// RESOLVE PLAN made on the GPU (gl_resolve_plan.hpp), the resolve running its steps, and the
// share of pixels whose colours are the same bits.
//
//   bench_gl_passes SCENE.json [--sizes 256,512,1024] [--runs 5] [--gl auto|egl|osmesa]
//                   [--error-samples 20000] [--walk-triangles 4096] [--resolve-size W,H]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "base/statistics.hpp"
#include "base/timer.hpp"
#include "raster/abuffer.hpp"
#include "raster/abuffer_compare.hpp"
#include "raster/cube_map.hpp"
#include "base/error.hpp"
#include "gl/gl_abuffer.hpp"
#include "gl/gl_context.hpp"
#include "gl/gl_cube_scan.hpp"
#include "gl/gl_cube_walks.hpp"
#include "gl/gl_passes.hpp"
#include "gl/gl_resolve_plan.hpp"
#include "reference/raytrace.hpp"
#include "scene/scene_load.hpp"
#include "shading/fragment_texture.hpp"
#include "shading/resolve.hpp"

namespace abcube {
namespace {

struct Options {
  std::string scene;
  std::vector<int> sizes{256, 512, 1024};
  int runs = 5;
  std::string gl = "auto";
  int error_samples = 20000;
  int walk_triangles = 4096;
  std::vector<int> resolve_size;  // the resolve's camera, width and height (empty: the scene's)
};

// The command line: every option with its default and unit in --help.
void add_options(BenchCommandLine& line, Options& o) {
  line.file("scene", o.scene, "scene file (SCENE.json)");
  line.numbers("--sizes", o.sizes, "cube resolutions N, texels per face edge (comma-separated)", 1, 65536);
  line.number("--runs", o.runs, "runs per N (median, min and max reported)", 1, 1000);
  line.choice("--gl", o.gl, "GL path", {"auto", "egl", "egl-device", "egl-surfaceless", "osmesa", "none"});
  line.number("--error-samples", o.error_samples, "texel-centre rays checked against the exact tracer", 0, 100000000);
  line.numbers("--resolve-size", o.resolve_size, "the resolve's camera: WIDTH,HEIGHT (default the scene's)", 1, 16384);
  line.number("--walk-triangles", o.walk_triangles, "triangles whose search rays are walked and scanned (0 = neither)",
              0, 100000000);
}

struct Spread {
  double median, lo, hi;
};

Spread spread(std::vector<double> v) {
  const double median = percentile(v, 0.5);
  return {median, *std::min_element(v.begin(), v.end()), *std::max_element(v.begin(), v.end())};
}

struct PrepassError {
  double median_rel = 0, p99_rel = 0, max_rel = 0, same_object = 0;
  size_t texels = 0;
};

// Exact first hit along random texel-centre directions against what the prepass stored.
PrepassError prepass_error(const SceneData& scene, const RayTracer& rt, const CubeImage& dist, const CubeIds& ids,
                           int samples) {
  const int n = dist.n;
  std::mt19937 rng(1234);
  std::uniform_int_distribution<int> pick(0, n - 1), pick_face(0, 5);
  std::vector<double> rel;
  size_t same = 0;
  for (int k = 0; k < samples; ++k) {
    const int face = pick_face(rng), i = pick(rng), j = pick(rng);
    const glm::dvec3 d = glm::normalize(texel_center_direction(face, i, j, n));
    Hit hit;
    const float g = dist.faces[face].at(i, j)[0];
    if (!rt.intersect(scene.camera.position, d, &hit) || !std::isfinite(g)) continue;
    rel.push_back(std::abs(g - hit.t) / hit.t);
    same += ids.faces[face][static_cast<size_t>(j) * n + i] == hit.object_id;
  }
  PrepassError e;
  e.texels = rel.size();
  if (rel.empty()) return e;
  e.median_rel = percentile(rel, 0.5);
  e.p99_rel = percentile(rel, 0.99);
  e.max_rel = percentile(rel, 1.0);
  e.same_object = static_cast<double>(same) / static_cast<double>(rel.size());
  return e;
}

// The searches' cube walks of the scene's rays at each N: GPU against one CPU thread.
void print_walks(const SceneData& scene, const Options& o) {
  const std::vector<WalkRay> rays =
      scene_walk_rays(scene, scene.camera.position, static_cast<size_t>(o.walk_triangles));
  const GlCubeWalks gpu;
  std::printf(
      "\n%zu search rays (shadow segments and reflections from %d triangles at most)\n\n"
      "| N | texels walked | GPU walks ms | CPU walks ms (1 thread) | GPU Mtexels/s | CPU Mtexels/s | walks "
      "identical |\n|---|---|---|---|---|---|---|\n",
      rays.size(), o.walk_triangles);
  for (int n : o.sizes) {
    if (!gpu_walks_at(n)) {
      std::printf("| %d | not walked: the cap is above the GPU's %u texels | | | | | |\n", n, GPU_WALK_MAX_TEXELS);
      continue;
    }
    std::vector<double> gpu_ms, cpu_ms;
    std::vector<RayWalk> on_gpu, on_cpu;
    for (int r = 0; r < o.runs; ++r) {
      Clock::time_point t0 = Clock::now();
      on_gpu = gpu.walk(rays, n);
      gpu_ms.push_back(ms_since(t0));
      t0 = Clock::now();
      on_cpu = cpu_cube_walks(rays, n);
      cpu_ms.push_back(ms_since(t0));
    }
    const WalkComparison c = compare_walks(on_cpu, on_gpu);
    const Spread g = spread(gpu_ms), cp = spread(cpu_ms);
    const double mtexels = static_cast<double>(c.texels) * 1e-3;
    std::printf("| %d | %llu | %.1f [%.1f, %.1f] | %.1f [%.1f, %.1f] | %.1f | %.1f | %zu of %zu |\n", n,
                static_cast<unsigned long long>(c.texels), g.median, g.lo, g.hi, cp.median, cp.lo, cp.hi,
                mtexels / g.median, mtexels / cp.median, c.identical, c.rays);
    std::fflush(stdout);
  }
}

// The searches' candidates in the CPU's cube A-buffer at each N: GPU against one CPU thread.
// The GPU's time is the scan's (walks, z-interval tests, reading the candidates back); the
// lists' upload is its own column.
void print_candidates(const SceneData& scene, const Options& o) {
  std::printf(
      "\n| N | search rays | candidates | texels walked | GPU upload ms | GPU scan ms | CPU scan ms (1 thread) | "
      "rays identical | answers from the GPU's candidates ms (1 thread) | CPU searches ms (1 thread) | answers the "
      "same | GPU scan with stop hints ms | texels walked with them |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int n : o.sizes) {
    if (!gpu_walks_at(n)) {
      std::printf("| %d | not scanned: the walk's cap is above the GPU's %u texels | | | | | | | | | |\n", n,
                  GPU_WALK_MAX_TEXELS);
      continue;
    }
    const CubeABuffer cube = build_cube_abuffer(scene, scene.camera.position, n);
    const SearchContext ctx(scene, cube);
    std::vector<int> lights;
    const std::vector<SearchRay> rays = scene_search_rays(ctx, static_cast<size_t>(o.walk_triangles), {}, &lights);
    std::vector<ScanStop> stops;  // STOP HINTS as the deferred searches give them
    for (const int l : lights) stops.push_back(l >= 0 ? ScanStop::shadow : ScanStop::crossing);
    std::vector<double> upload_ms, gpu_ms, cpu_ms, answer_ms, search_ms, hinted_ms;
    uint64_t hinted_texels = 0;
    std::vector<CandidateScan> on_gpu, on_cpu;
    size_t answers = 0, same = 0;
    for (int r = 0; r < o.runs; ++r) {
      Clock::time_point t0 = Clock::now();
      const GlCandidateScan gpu(ctx);
      upload_ms.push_back(ms_since(t0));
      t0 = Clock::now();
      on_gpu = gpu.scan(rays);
      gpu_ms.push_back(ms_since(t0));
      t0 = Clock::now();
      const std::vector<CandidateScan> hinted = gpu.scan(rays, {}, {}, stops);
      hinted_ms.push_back(ms_since(t0));
      hinted_texels = 0;
      for (const CandidateScan& s : hinted) hinted_texels += s.texels;
      t0 = Clock::now();
      on_cpu.clear();
      for (const SearchRay& q : rays) on_cpu.push_back(scan_candidates(ctx, q));
      cpu_ms.push_back(ms_since(t0));
      // The searches that are not segments: from the GPU's candidates, and walked on the CPU.
      std::vector<SearchResult> found, walked;
      t0 = Clock::now();
      for (size_t k = 0; k < rays.size(); ++k) {
        if (std::isinf(rays[k].l_max)) found.push_back(search_from_candidates(ctx, rays[k], {}, on_gpu[k]));
      }
      answer_ms.push_back(ms_since(t0));
      t0 = Clock::now();
      for (const SearchRay& q : rays) {
        if (std::isinf(q.l_max)) walked.push_back(search_along(ctx, q));
      }
      search_ms.push_back(ms_since(t0));
      answers = found.size(), same = 0;
      for (size_t k = 0; k < found.size(); ++k) same += same_found(walked[k], found[k]) ? 1 : 0;
    }
    const CandidateComparison c = compare_candidate_scans(on_cpu, on_gpu);
    uint64_t texels = 0;
    for (const CandidateScan& s : on_cpu) texels += s.texels;
    const Spread u = spread(upload_ms), g = spread(gpu_ms), cp = spread(cpu_ms), a = spread(answer_ms),
                 w = spread(search_ms), h = spread(hinted_ms);
    std::printf(
        "| %d | %zu | %llu | %llu | %.1f [%.1f, %.1f] | %.1f [%.1f, %.1f] | %.1f [%.1f, %.1f] | %zu of %zu | %.1f "
        "[%.1f, %.1f] | %.1f [%.1f, %.1f] | %zu of %zu | %.1f [%.1f, %.1f] | %llu |\n",
        n, rays.size(), static_cast<unsigned long long>(c.candidates), static_cast<unsigned long long>(texels),
        u.median, u.lo, u.hi, g.median, g.lo, g.hi, cp.median, cp.lo, cp.hi, c.identical, c.rays, a.median, a.lo, a.hi,
        w.median, w.lo, w.hi, same, answers, h.median, h.lo, h.hi, static_cast<unsigned long long>(hinted_texels));
    std::fflush(stdout);
  }
}

// The camera's resolve, pack alone against the GPU's plan and its steps, at the scene's size.
void print_resolve(SceneData scene, GlScene& gl, const Options& o) {
  if (o.resolve_size.size() == 2) scene.camera.width = o.resolve_size[0], scene.camera.height = o.resolve_size[1];
  if (!o.resolve_size.empty() && o.resolve_size.size() != 2) throw InputError("--resolve-size: WIDTH,HEIGHT");
  const ABuffer camera = build_camera_abuffer(scene);
  const PixelShader shade = local_phong_shader(scene, camera, false);
  ResolveOptions ro;
  std::vector<double> pack, plan, steps;
  Image by_pack, by_steps;
  ResolvePlanStats s;
  for (int r = 0; r < o.runs; ++r) {
    Clock::time_point t0 = Clock::now();
    by_pack = resolve_image(camera, *scene.triangles, shade, scene.background, ro);
    pack.push_back(ms_since(t0));
    t0 = Clock::now();
    const ResolvePlan p = gl.resolve_planner().plan(camera, scene, {}, &s);
    plan.push_back(ms_since(t0));
    ResolveOptions with = ro;
    with.plan = &p;
    t0 = Clock::now();
    by_steps = resolve_image(camera, *scene.triangles, shade, scene.background, with);
    steps.push_back(ms_since(t0));
  }
  size_t same = 0;
  const size_t pixels = camera.view.pixel_count();
  for (size_t q = 0; q < pixels; ++q) {
    same += std::equal(by_pack.data.begin() + 3 * q, by_pack.data.begin() + 3 * q + 3, by_steps.data.begin() + 3 * q);
  }
  const Spread a = spread(pack), b = spread(plan), c = spread(steps);
  std::printf(
      "\n| camera | fragments | resolve, pack alone ms | GPU plan ms | resolve by its steps ms | steps | pixels "
      "planned "
      "| pixels the same bits |\n|---|---|---|---|---|---|---|---|\n"
      "| %dx%d | %zu | %.1f [%.1f, %.1f] | %.1f [%.1f, %.1f] | %.1f [%.1f, %.1f] | %llu | %llu of %zu | %zu of %zu |\n",
      camera.width(), camera.height(), camera.fragments.size(), a.median, a.lo, a.hi, b.median, b.lo, b.hi, c.median,
      c.lo, c.hi, static_cast<unsigned long long>(s.steps), static_cast<unsigned long long>(s.planned), pixels, same,
      pixels);
  std::fflush(stdout);
}

int run(const Options& o) {
  const SceneData scene = load_scene(o.scene);
  GlChoice choice = GlChoice::automatic;
  if (!parse_gl_choice(o.gl, &choice)) throw InputError("--gl: unknown path " + o.gl);

  std::string log;
  auto ctx = open_gl_context(choice, -1, &log);
  if (!ctx) throw RuntimeFailure("no GL context: " + log);
  const RayTracer rt(scene);
  GlScene gl(scene);
  std::printf("scene: %s (%zu triangles)\nrenderer: %s\nruns: %d (median [min, max] ms)\n\n", o.scene.c_str(),
              scene.triangles->triangle_count(), describe_gl(ctx.get()).c_str(), o.runs);
  std::printf(
      "| N | prepass 6 faces ms | readback ms | camera %dx%d raster ms | prepass rel. distance error "
      "vs exact: median / p99 / max | same object | texels checked | CPU cube A-buffer ms | fragments | "
      "CPU/GPU | GPU cube A-buffer ms | its lists identical to the CPU's |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|\n",
      scene.camera.width, scene.camera.height);
  for (int n : o.sizes) {
    std::vector<double> prepass, readback, camera;
    CubeImage dist;
    CubeIds ids;
    for (int r = 0; r < o.runs; ++r) {
      const GpuTimings before = gl.timings();
      gl.cube_distance(scene.camera.position, n, &dist, &ids);
      prepass.push_back(gl.timings().cube_distance_ms - before.cube_distance_ms);
      readback.push_back(gl.timings().readback_ms - before.readback_ms);
      const double cam0 = gl.timings().camera_ms;
      gl.camera_color(scene.camera);
      camera.push_back(gl.timings().camera_ms - cam0);
    }
    std::vector<double> cpu;
    ABufferStats as;
    ABufferOptions options;
    options.near_distance = gl.near_distance();
    CubeABuffer cube;
    for (int r = 0; r < o.runs; ++r) {
      const Clock::time_point t0 = Clock::now();
      cube = build_cube_abuffer(scene, scene.camera.position, n, options, &as);
      cpu.push_back(ms_since(t0));
    }
    std::vector<double> gpu_abuffer;
    ListComparison lists;
    for (int r = 0; r < o.runs; ++r) {
      const Clock::time_point t0 = Clock::now();
      const CubeABuffer on_gpu = build_cube_abuffer_gl(scene, scene.camera.position, n, options);
      gpu_abuffer.push_back(ms_since(t0));
      if (r == 0) lists = compare_lists(cube, on_gpu);
    }
    const Spread p = spread(prepass), rb = spread(readback), c = spread(camera), a = spread(cpu),
                 g = spread(gpu_abuffer);
    const PrepassError e = prepass_error(scene, rt, dist, ids, o.error_samples);
    std::printf(
        "| %d | %.1f [%.1f, %.1f] | %.1f [%.1f, %.1f] | %.1f [%.1f, %.1f] | %.1e / %.1e / %.1e | %.4f | %zu "
        "| %.1f [%.1f, %.1f] | %llu | %.1f | %.1f [%.1f, %.1f] | %llu of %llu |\n",
        n, p.median, p.lo, p.hi, rb.median, rb.lo, rb.hi, c.median, c.lo, c.hi, e.median_rel, e.p99_rel, e.max_rel,
        e.same_object, e.texels, a.median, a.lo, a.hi, static_cast<unsigned long long>(as.fragments),
        a.median / p.median, g.median, g.lo, g.hi, static_cast<unsigned long long>(lists.lists_identical),
        static_cast<unsigned long long>(lists.lists));
    std::fflush(stdout);
  }
  if (o.walk_triangles > 0) {
    print_walks(scene, o);
    print_candidates(scene, o);
  }
  print_resolve(scene, gl, o);
  return 0;
}

}  // namespace
}  // namespace abcube

int main(int argc, char** argv) {
  return abcube::bench_main<abcube::Options>(
      argc, argv, "bench_gl_passes",
      "GL passes: the six-face distance prepass and the camera raster against N, with their error", abcube::add_options,
      abcube::run);
}
