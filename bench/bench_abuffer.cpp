// CPU A-buffer benchmark: the six-face cube A-buffer build (count, fill, merge) at several
// resolutions around the scene's camera, median of R runs with min and max, fragments,
// fragments per second, bytes per fragment, and the peak resident memory of a process that
// did only that build (each scene and size runs in a forked child, so peaks do not mix).
//
//   bench_abuffer SCENE.json... [--sizes 256,512,1024,2048] [--runs 3] [--threads 0]
//                 [--camera]   (also the camera view's A-buffer at the scene's image size)
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "raster/abuffer.hpp"
#include "base/error.hpp"
#include "base/memory.hpp"
#include "scene/scene_load.hpp"

namespace abcube {
namespace {

struct Options {
  std::vector<std::string> scenes;
  std::vector<int> sizes{256, 512, 1024, 2048};
  int runs = 3;
  int threads = 0;
  bool camera = false;
};

struct Result {
  double median_ms = 0, min_ms = 0, max_ms = 0, count_ms = 0, fill_ms = 0;
  uint64_t fragments = 0, raw_fragments = 0, max_list = 0, bytes = 0, peak_rss = 0, clipped = 0;
  int threads = 0;
  char error[256] = {0};
};

// The command line: every option with its default and unit in --help.
void add_options(BenchCommandLine& line, Options& o) {
  line.files("scenes", o.scenes, "scene files (SCENE.json...)");
  line.numbers("--sizes", o.sizes, "cube resolutions N, texels per face edge (comma-separated)", 1, 65536);
  line.number("--runs", o.runs, "runs per configuration (median, min and max reported)", 1, 1000000);
  line.number("--threads", o.threads, "worker threads (0 = every core)", 0, 4096);
  line.flag("--camera", o.camera, "also the camera view's A-buffer at the scene's image size (pixels)");
}

// One configuration, in this process: `size` 0 means the camera view.
Result measure(const SceneData& scene, int size, const Options& o) {
  Result r;
  ABufferOptions ao;
  ao.threads = o.threads;
  std::vector<double> ms, count_ms, fill_ms;
  ABufferStats st;
  for (int run = 0; run < o.runs; ++run) {
    if (size > 0) {
      const CubeABuffer cube = build_cube_abuffer(scene, scene.camera.position, size, ao, &st);
    } else {
      const ABuffer view = build_camera_abuffer(scene, ao, &st);
    }
    ms.push_back(st.total_ms);
    count_ms.push_back(st.count_ms);
    fill_ms.push_back(st.fill_ms);
  }
  std::sort(ms.begin(), ms.end());
  std::sort(count_ms.begin(), count_ms.end());
  std::sort(fill_ms.begin(), fill_ms.end());
  r.median_ms = ms[ms.size() / 2];
  r.min_ms = ms.front();
  r.max_ms = ms.back();
  r.count_ms = count_ms[count_ms.size() / 2];
  r.fill_ms = fill_ms[fill_ms.size() / 2];
  r.fragments = st.fragments;
  r.raw_fragments = st.raw_fragments;
  r.max_list = st.max_list_length;
  r.bytes = st.bytes_total;
  r.clipped = st.triangles_clipped;
  r.threads = st.threads;
  r.peak_rss = peak_rss_bytes();
  return r;
}

// Runs measure() in a child process so that its peak memory is its own.
Result measure_in_child(const std::string& path, int size, const Options& o) {
  int fd[2];
  if (pipe(fd) != 0) throw RuntimeFailure("pipe failed");
  const pid_t pid = fork();
  if (pid == 0) {
    close(fd[0]);
    Result r;
    try {
      r = measure(load_scene(path), size, o);
    } catch (const std::exception& e) {
      std::snprintf(r.error, sizeof r.error, "%s", e.what());
    }
    const ssize_t written = write(fd[1], &r, sizeof r);
    _exit(written == static_cast<ssize_t>(sizeof r) ? 0 : 1);
  }
  close(fd[1]);
  Result r;
  const ssize_t got = read(fd[0], &r, sizeof r);
  close(fd[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (got != static_cast<ssize_t>(sizeof r)) std::snprintf(r.error, sizeof r.error, "child died (status %d)", status);
  return r;
}

void print(const std::string& path, int size, const Result& r) {
  const std::string what = size > 0 ? "cube " + std::to_string(size) : std::string("camera");
  if (r.error[0]) {
    std::printf("%-34s %-10s error: %s\n", path.c_str(), what.c_str(), r.error);
    return;
  }
  const double mib = 1.0 / (1024.0 * 1024.0);
  std::printf("%-34s %-10s %11llu %11llu %8.2f %9.1f %9.1f %9.1f %8.1f %8.1f %7llu %4zu %9.1f %9.1f %3d\n",
              path.c_str(), what.c_str(), static_cast<unsigned long long>(r.fragments),
              static_cast<unsigned long long>(r.raw_fragments),
              static_cast<double>(r.fragments) / (r.median_ms * 1e-3) * 1e-6, r.median_ms, r.min_ms, r.max_ms,
              r.count_ms, r.fill_ms, static_cast<unsigned long long>(r.max_list), sizeof(Fragment),
              static_cast<double>(r.bytes) * mib, static_cast<double>(r.peak_rss) * mib, r.threads);
  std::fflush(stdout);
}

int run(const Options& o) {
  std::printf(
      "# bench_abuffer: median of %d runs (min, max); Mfrag/s = stored fragments / median; "
      "peak RSS of a process doing only that build\n",
      o.runs);
  std::printf("%-34s %-10s %11s %11s %8s %9s %9s %9s %8s %8s %7s %4s %9s %9s %3s\n", "scene", "raster", "fragments",
              "raw", "Mfrag/s", "ms", "min", "max", "count", "fill", "maxlist", "B/fr", "MiB", "peakMiB", "thr");
  for (const std::string& path : o.scenes) {
    if (o.camera) print(path, 0, measure_in_child(path, 0, o));
    for (int n : o.sizes) print(path, n, measure_in_child(path, n, o));
  }
  return 0;
}

}  // namespace
}  // namespace abcube

int main(int argc, char** argv) {
  return abcube::bench_main<abcube::Options>(
      argc, argv, "bench_abuffer",
      "CPU cube A-buffer build: median ms, fragments, Mfrag/s and peak memory per scene and N", abcube::add_options,
      abcube::run);
}
