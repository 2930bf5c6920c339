// Overhead benchmark: what the library costs per render beyond the render's own passes.
// A batch of renders of a tiny scene (8x8 pixels) through ONE Renderer, per method: the
// wall time of render() minus the sum of the passes its stats time (every timings_ms entry
// but "total" and "load" -- the scene's load, done once before -- plus the tracer's nested
// raytrace.timings_ms), median and p90 against the goal "under 5 ms". For comparison, the
// same scene rendered by separate `abcube render` processes: median wall time per process.
//
//   bench_overhead [--renders 1000] [--methods raytrace,gpu] [--gl auto] [--size 8]
//                  [--processes 20] [--abcube build/abcube]
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <abcube/renderer.hpp>

#include "bench_common.hpp"
#include "tiny_scene.hpp"

#ifndef ABCUBE_PROGRAM
#define ABCUBE_PROGRAM "abcube"
#endif

namespace abcube {
namespace {

struct Options {
  int renders = 1000;
  std::vector<std::string> methods{"raytrace", "gpu"};
  std::string gl = "auto";
  int size = 8;
  int processes = 20;
  int threads = 0;
  std::string program = ABCUBE_PROGRAM;
};

// The command line: every option with its default and unit in --help.
void add_options(BenchCommandLine& line, Options& o) {
  line.number("--renders", o.renders, "renders per method through one Renderer", 1, 100000000);
  line.choices("--methods", o.methods, "methods measured (comma-separated)",
               {"abuffer", "zbuffer", "envmap", "raytrace", "gpu"});
  line.choice("--gl", o.gl, "the Renderer's and the processes' GL path (gpu)",
              {"auto", "egl", "egl-device", "egl-surfaceless", "osmesa", "none"});
  line.number("--size", o.size, "image width and height, pixels", 1, 4096);
  line.number("--processes", o.processes, "`abcube render` processes per method (0 = none)", 0, 100000);
  line.number("--threads", o.threads, "worker threads per render (0 = every core)", 0, 4096);
  line.text("--abcube", o.program, "the abcube program the processes run");
}

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// Nearest-rank percentile of `v` (q in [0, 1]).
double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t rank = static_cast<size_t>(std::ceil(q * static_cast<double>(v.size())));
  return v[std::min(v.size() - 1, rank > 0 ? rank - 1 : 0)];
}

// The milliseconds of the passes a render's stats time: timings_ms but total and load,
// and each section's own timings_ms (the tracer's bvh_build and trace).
double pass_ms(const std::string& stats_json) {
  const nlohmann::json stats = nlohmann::json::parse(stats_json);
  double sum = 0;
  for (const auto& [key, value] : stats.at("timings_ms").items()) {
    if (key != "total" && key != "load" && value.is_number()) sum += value.get<double>();
  }
  for (const auto& [key, section] : stats.items()) {
    if (key == "timings_ms" || !section.is_object() || !section.contains("timings_ms")) continue;
    for (const auto& [pass, value] : section["timings_ms"].items()) {
      if (value.is_number()) sum += value.get<double>();
    }
  }
  return sum;
}

// Renders through one Renderer: per render, wall - passes and wall - stats total.
void measure_library(const Options& o, const Scene& scene, Renderer& renderer, const std::string& method) {
  RenderOptions ro;
  ro.method = method;
  ro.threads = o.threads;
  std::vector<double> overhead, outside, wall;
  for (int i = 0; i < o.renders; ++i) {
    const Clock::time_point t0 = Clock::now();
    const RenderResult r = renderer.render(scene, ro);
    const double ms = ms_since(t0);
    wall.push_back(ms);
    overhead.push_back(ms - pass_ms(r.stats.json));
    outside.push_back(ms - r.stats.total_ms);
  }
  const double median = percentile(overhead, 0.5), p90 = percentile(overhead, 0.9);
  std::printf(
      "%-8s library: %d renders, wall per render median %.3f ms; overhead (wall - passes) median %.3f ms, "
      "p90 %.3f ms, max %.3f ms; outside render()'s own total: median %.3f ms; goal under 5 ms: %s\n",
      method.c_str(), o.renders, percentile(wall, 0.5), median, p90, percentile(overhead, 1.0),
      percentile(outside, 0.5), p90 < 5.0 ? "met" : "NOT met");
  std::fflush(stdout);
}

// Runs `args` as a process with its output thrown away; its exit status (-1: not run).
int run_process(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  std::fflush(stdout);  // or the child's exit writes our buffered lines again
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    std::FILE* null = std::freopen("/dev/null", "w", stdout);
    null = std::freopen("/dev/null", "w", stderr);
    (void)null;
    execv(argv[0], argv.data());
    _exit(127);
  }
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// The same scene rendered by separate `abcube render` processes: median ms per process.
void measure_processes(const Options& o, const std::string& scene_path, const std::string& out,
                       const std::string& method) {
  std::vector<double> ms;
  for (int i = 0; i < o.processes; ++i) {
    const Clock::time_point t0 = Clock::now();
    const int status = run_process({o.program, "render", scene_path, "-o", out, "--method", method, "--gl", o.gl,
                                    "--threads", std::to_string(o.threads)});
    if (status != 0) {
      std::printf("%-8s process: `%s render` exited %d; no figure\n", method.c_str(), o.program.c_str(), status);
      return;
    }
    ms.push_back(ms_since(t0));
  }
  std::printf("%-8s process: %d `abcube render` processes, median %.1f ms per process (min %.1f, max %.1f)\n",
              method.c_str(), o.processes, percentile(ms, 0.5), percentile(ms, 0.0), percentile(ms, 1.0));
  std::fflush(stdout);
}

int run(const Options& o) {
  const std::string json = tiny_scene_json(o.size, o.size, 32);
  const Scene scene = Scene::from_json(json, "tiny");
  Renderer renderer(RendererOptions{o.gl, -1, o.threads});
  std::printf(
      "# bench_overhead: %dx%d tiny scene (%zu triangles), %d renders per method through one Renderer, "
      "threads %d (0 = every core)\n",
      o.size, o.size, scene.triangle_count(), o.renders, o.threads);
  for (const std::string& method : o.methods) measure_library(o, scene, renderer, method);
  if (!renderer.gl_path().empty()) {
    std::printf("GL path %s (%s)\n", renderer.gl_path().c_str(), renderer.gl_renderer().c_str());
  }
  if (o.processes == 0) return 0;
  char dir_template[] = "/tmp/bench_overhead.XXXXXX";
  const char* dir = mkdtemp(dir_template);
  if (!dir) throw RuntimeFailure("cannot make a temporary folder under /tmp");
  const std::string scene_path = std::string(dir) + "/tiny.json", out = std::string(dir) + "/out.png";
  std::ofstream(scene_path) << json;
  for (const std::string& method : o.methods) measure_processes(o, scene_path, out, method);
  std::remove(out.c_str());
  std::remove(scene_path.c_str());
  rmdir(dir);
  return 0;
}

}  // namespace
}  // namespace abcube

int main(int argc, char** argv) {
  return abcube::bench_main<abcube::Options>(
      argc, argv, "bench_overhead",
      "Per-render overhead of the library (wall - passes) against `abcube render` processes", abcube::add_options,
      abcube::run);
}
