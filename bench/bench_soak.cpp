// Soak benchmark: many small renders in one process through the library (the way a
// service or a Python worker uses it), cycling every method, to find what leaks.
//
// Phase 1: ONE Renderer renders N images of a tiny scene (the camera orbits it, a new
// Scene every few renders); every K renders a line with the resident memory (VmRSS) and
// the open file descriptors. At the end, their growth after warm-up (from render N/10 to
// the last) against the goal "under 2 MB and 0 descriptors", and renders per second.
// Phase 2: a Renderer created and destroyed per render (GL opened and closed each time:
// the EGL re-creation that fails in pyrender), with its own growth figures.
// With --timeout-every K, every K-th render of phase 1 is a larger one (8x the size, 4x the
// cube) under a time limit of --timeout-ms: it must stop with RenderTimeout, and how far
// past the limit it stopped is reported (median, p90, max); the growth figures include them.
// Every image must have the size asked, finite values and some light; exit 1 otherwise
// or when any render throws (but the timed ones, with RenderTimeout).
//
//   bench_soak [--renders 10000] [--every 500] [--gl auto] [--methods abuffer,zbuffer,...]
//              [--recreate 300] [--new-scene-every 100] [--threads 0]
//              [--timeout-every 0] [--timeout-ms 30]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <abcube/renderer.hpp>

#include "bench_common.hpp"
#include "process_usage.hpp"
#include "tiny_scene.hpp"

namespace abcube {
namespace {

struct Options {
  int renders = 10000;
  int every = 500;
  std::string gl = "auto";
  std::vector<std::string> methods{"abuffer", "zbuffer", "envmap", "raytrace", "gpu"};
  int recreate = 300;
  int new_scene_every = 100;
  int threads = 0;
  int width = 32, height = 24, cube_res = 32;
  int timeout_every = 0;
  double timeout_ms = 30;
};

// The command line: every option with its default and unit in --help.
void add_options(BenchCommandLine& line, Options& o) {
  line.number("--renders", o.renders, "renders of phase 1 (one Renderer)", 1, 100000000);
  line.number("--every", o.every, "renders between two memory and descriptor samples", 1, 100000000);
  line.choice("--gl", o.gl, "the Renderer's GL path (gpu renders)",
              {"auto", "egl", "egl-device", "egl-surfaceless", "osmesa", "none"});
  line.choices("--methods", o.methods, "methods cycled through, one per render (comma-separated)",
               {"abuffer", "zbuffer", "envmap", "raytrace", "gpu"});
  line.number("--recreate", o.recreate, "renders of phase 2 (a new Renderer each; 0 = skip it)", 0, 100000000);
  line.number("--new-scene-every", o.new_scene_every, "renders between two new Scenes (0 = one Scene)", 0, 100000000);
  line.number("--threads", o.threads, "worker threads per render (0 = every core)", 0, 4096);
  line.number("--width", o.width, "image width, pixels", 1, 4096);
  line.number("--height", o.height, "image height, pixels", 1, 4096);
  line.number("--cube-res", o.cube_res, "cube resolution N, texels per face edge", 1, 4096);
  line.number("--timeout-every", o.timeout_every,
              "every K-th render of phase 1 is 8x larger under --timeout-ms and must time out (0 = none)", 0,
              100000000);
  line.number("--timeout-ms", o.timeout_ms, "time limit of those renders, ms", 0.001, 1e9);
}

struct Sample {
  int render = 0;  // renders done when taken
  double rss_mb = 0;
  int fds = 0;
};

Sample sample_now(int render) {
  return {render, static_cast<double>(resident_bytes()) / (1024.0 * 1024.0), open_descriptors()};
}

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// What is wrong with an image, or "" when it has the size asked, finite values and light.
std::string image_problem(const Image& image, int width, int height) {
  if (image.width != width || image.height != height || image.channels < 1 ||
      image.data.size() != static_cast<size_t>(width) * height * image.channels) {
    return "image is " + std::to_string(image.width) + "x" + std::to_string(image.height) + ", asked " +
           std::to_string(width) + "x" + std::to_string(height);
  }
  double sum = 0;
  for (float v : image.data) {
    if (!std::isfinite(v)) return "image has a NaN or infinite value";
    sum += v;
  }
  return sum > 0 ? "" : "image is black";
}

// Render i's options: the method cycles, the camera orbits the scene.
RenderOptions render_options(const Options& o, int i) {
  RenderOptions r;
  r.method = o.methods[static_cast<size_t>(i) % o.methods.size()];
  r.cube_resolution = o.cube_res;
  r.threads = o.threads;
  r.stats = true;
  const double angle = 0.05 * i;
  r.camera.position = std::array<double, 3>{3.0 * std::sin(angle), 1.2, 3.0 * std::cos(angle)};
  r.camera.width = o.width;
  r.camera.height = o.height;
  return r;
}

// Counts failed renders and prints the first few.
struct Failures {
  int count = 0;
  void add(const char* phase, int i, const std::string& method, const std::string& why) {
    if (++count <= 10) std::printf("FAILED %s render %d (%s): %s\n", phase, i, method.c_str(), why.c_str());
    std::fflush(stdout);
  }
};

// One render, checked; a failure is counted, never thrown.
void render_checked(Renderer& renderer, const Scene& scene, const Options& o, int i, const char* phase,
                    Failures* failures) {
  const RenderOptions options = render_options(o, i);
  try {
    const RenderResult r = renderer.render(scene, options);
    const std::string problem = image_problem(r.image, o.width, o.height);
    if (!problem.empty()) failures->add(phase, i, options.method, problem);
  } catch (const std::exception& e) {
    failures->add(phase, i, options.method, e.what());
  }
}

void print_sample(const char* phase, const Sample& s, double renders_per_s) {
  std::printf("%-8s render %7d  RSS %8.1f MB  fds %4d  %8.1f renders/s\n", phase, s.render, s.rss_mb, s.fds,
              renders_per_s);
  std::fflush(stdout);
}

// Growth after `warm` renders, against the goal: from the first sample after it to the last
// one, and (renders of mixed sizes leave the resident set anywhere in a band: which render
// came last decides) the highest sample of the second half against that of the first. The
// goal is judged on the second figure.
bool print_growth(const char* phase, const std::vector<Sample>& samples, int warm) {
  const auto from = std::find_if(samples.begin(), samples.end(), [&](const Sample& s) { return s.render >= warm; });
  const Sample& a = from == samples.end() ? samples.back() : *from;
  const Sample& b = samples.back();
  const auto middle = from + (samples.end() - from) / 2;
  auto highest = [](auto first, auto last) {
    double m = 0;
    for (auto it = first; it != last; ++it) m = std::max(m, it->rss_mb);
    return m;
  };
  const double band = middle == samples.end() ? 0.0 : highest(middle, samples.end()) - highest(from, middle);
  const int fds = b.fds - a.fds;
  const bool met = band < 2.0 && fds <= 0;
  std::printf(
      "%s growth after warm-up (render %d -> %d): %+.2f MB last against first, %+.2f MB highest of the second "
      "half against the first, %+d descriptors; goal under 2 MB and 0 descriptors: %s\n",
      phase, a.render, b.render, b.rss_mb - a.rss_mb, band, fds, met ? "met" : "NOT met");
  return met;
}

// The first render that counts as past warm-up: 10% of the run, on a sample.
int warm_up(int renders, int every) { return std::max(every, renders / 10 / every * every); }

// The timed renders of phase 1: how far past the limit each stopped, and the ones that did not.
struct TimedRenders {
  std::map<std::string, std::vector<double>> overshoot_ms;  // by method
  int finished = 0;
};

// Render i, 8x larger under o.timeout_ms: a RenderTimeout is the expected outcome.
void render_timed(Renderer& renderer, const Scene& scene, const Options& o, int i, TimedRenders* timed,
                  Failures* failures) {
  RenderOptions options = render_options(o, i);
  options.method = o.methods[static_cast<size_t>(i / o.timeout_every) % o.methods.size()];  // every method in turn
  options.camera.width = 8 * o.width;
  options.camera.height = 8 * o.height;
  options.cube_resolution = 4 * o.cube_res;
  options.timeout_s = o.timeout_ms / 1000.0;
  const Clock::time_point t0 = Clock::now();
  try {
    renderer.render(scene, options);
    ++timed->finished;
  } catch (const RenderTimeout&) {
    timed->overshoot_ms[options.method].push_back(seconds_since(t0) * 1000.0 - o.timeout_ms);
  } catch (const std::exception& e) {
    failures->add("phase1", i, options.method + " (timed)", e.what());
  }
}

void print_timed(const TimedRenders& t, const Options& o) {
  std::printf("timed renders (8x size, limit %.1f ms): %d finished in time; stopped by RenderTimeout:\n", o.timeout_ms,
              t.finished);
  for (auto [method, v] : t.overshoot_ms) {
    std::sort(v.begin(), v.end());
    auto at = [&](double q) {
      return v[std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())))];
    };
    std::printf("  %-9s %4zu, past the limit by %.2f ms median, %.2f p90, %.2f max\n", method.c_str(), v.size(),
                at(0.5), at(0.9), v.back());
  }
}

// Phase 1: one Renderer for every render.
void soak_one_renderer(const Options& o, Failures* failures) {
  const RendererOptions ro{o.gl, -1, o.threads};
  Renderer renderer(ro);
  const std::string json = tiny_scene_json(o.width, o.height, o.cube_res);
  Scene scene = Scene::from_json(json, "tiny");
  std::vector<Sample> samples{sample_now(0)};
  TimedRenders timed;
  print_sample("phase1", samples.back(), 0);
  const Clock::time_point start = Clock::now();
  Clock::time_point last = start;
  for (int i = 0; i < o.renders; ++i) {
    if (o.new_scene_every > 0 && i > 0 && i % o.new_scene_every == 0) scene = Scene::from_json(json, "tiny");
    if (o.timeout_every > 0 && i % o.timeout_every == o.timeout_every - 1) {
      render_timed(renderer, scene, o, i, &timed, failures);
    } else {
      render_checked(renderer, scene, o, i, "phase1", failures);
    }
    if ((i + 1) % o.every == 0 || i + 1 == o.renders) {
      const int done_since = (i + 1) - samples.back().render;
      samples.push_back(sample_now(i + 1));
      print_sample("phase1", samples.back(), done_since / seconds_since(last));
      last = Clock::now();
    }
  }
  const double seconds = seconds_since(start);
  std::printf("phase1: %d renders in %.1f s: %.1f renders/s (methods cycled; GL path %s, %s)\n", o.renders, seconds,
              o.renders / seconds, renderer.gl_path().c_str(), renderer.gl_renderer().c_str());
  if (o.timeout_every > 0) print_timed(timed, o);
  print_growth("phase1", samples, warm_up(o.renders, o.every));
}

// Phase 2: a new Renderer per render, GL opened and closed each time it renders gpu.
void soak_new_renderers(const Options& o, Failures* failures) {
  const RendererOptions ro{o.gl, -1, o.threads};
  const Scene scene = Scene::from_json(tiny_scene_json(o.width, o.height, o.cube_res), "tiny");
  const int every = std::max(1, std::min(o.every, o.recreate / 6));
  std::vector<Sample> samples{sample_now(0)};
  print_sample("phase2", samples.back(), 0);
  const Clock::time_point start = Clock::now();
  Clock::time_point last = start;
  for (int i = 0; i < o.recreate; ++i) {
    try {
      Renderer renderer(ro);
      render_checked(renderer, scene, o, i, "phase2", failures);
    } catch (const std::exception& e) {
      failures->add("phase2", i, "Renderer", e.what());
    }
    if ((i + 1) % every == 0 || i + 1 == o.recreate) {
      const int done_since = (i + 1) - samples.back().render;
      samples.push_back(sample_now(i + 1));
      print_sample("phase2", samples.back(), done_since / seconds_since(last));
      last = Clock::now();
    }
  }
  const double seconds = seconds_since(start);
  std::printf("phase2: %d Renderers created, rendered once and destroyed in %.1f s: %.1f renders/s\n", o.recreate,
              seconds, o.recreate / seconds);
  print_growth("phase2", samples, warm_up(o.recreate, every));
}

int run(const Options& o) {
  std::printf("# bench_soak: %dx%d images, cube N = %d, methods %zu cycled, threads %d (0 = every core), gl %s\n",
              o.width, o.height, o.cube_res, o.methods.size(), o.threads, o.gl.c_str());
  Failures failures;
  soak_one_renderer(o, &failures);
  if (o.recreate > 0) soak_new_renderers(o, &failures);
  std::printf("failed renders: %d\n", failures.count);
  return failures.count == 0 ? 0 : 1;
}

}  // namespace
}  // namespace abcube

int main(int argc, char** argv) {
  return abcube::bench_main<abcube::Options>(
      argc, argv, "bench_soak", "Soak: many small renders in one process; resident memory, descriptors and renders/s",
      abcube::add_options, abcube::run);
}
