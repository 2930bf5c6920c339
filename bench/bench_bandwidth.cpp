// The machine's memory bandwidth, measured the way STREAM does (McCalpin): copy
// (a[i] = b[i]) and triad (a[i] = b[i] + s c[i]) over arrays far larger than the caches,
// split over T threads, best of K repetitions. Bytes counted as STREAM counts them (copy
// 16 per element, triad 24), so the figures compare with published STREAM results.
// The A-buffer's fragments per second are read against it (docs/performance.md).
//
//   bench_bandwidth [--mib 256] [--threads 2] [--reps 5]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <thread>
#include <vector>

#include "bench_common.hpp"

namespace abcube {
namespace {

struct Options {
  int mib = 256;  // per array
  int threads = 2;
  int reps = 5;
};

void add_options(BenchCommandLine& line, Options& o) {
  line.number("--mib", o.mib, "MiB per array (three arrays)", 8, 8192);
  line.number("--threads", o.threads, "threads", 1, 256);
  line.number("--reps", o.reps, "repetitions, best taken", 1, 1000);
}

template <class Kernel>
double best_seconds(int threads, int reps, size_t n, Kernel&& kernel) {
  double best = 1e30;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) {
      const size_t lo = n * static_cast<size_t>(t) / static_cast<size_t>(threads);
      const size_t hi = n * static_cast<size_t>(t + 1) / static_cast<size_t>(threads);
      pool.emplace_back([&kernel, lo, hi] { kernel(lo, hi); });
    }
    for (std::thread& th : pool) th.join();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

int run(const Options& o) {
  const size_t n = static_cast<size_t>(o.mib) * (size_t{1} << 20) / sizeof(double);
  std::vector<double> a(n), b(n), c(n);
  // First touch by the threads that use them (pages land where they run).
  best_seconds(o.threads, 1, n, [&](size_t lo, size_t hi) {
    for (size_t i = lo; i < hi; ++i) a[i] = 0.0, b[i] = 1.0, c[i] = 2.0;
  });
  const double copy = best_seconds(o.threads, o.reps, n, [&](size_t lo, size_t hi) {
    for (size_t i = lo; i < hi; ++i) a[i] = b[i];
  });
  const double triad = best_seconds(o.threads, o.reps, n, [&](size_t lo, size_t hi) {
    for (size_t i = lo; i < hi; ++i) a[i] = b[i] + 3.0 * c[i];
  });
  double check = 0;
  for (size_t i = 0; i < n; i += 4096) check += a[i];
  std::printf("arrays %d MiB x 3, %d threads, best of %d (checksum %.0f)\n", o.mib, o.threads, o.reps, check);
  std::printf("copy  %.2f GB/s\n", 16.0 * static_cast<double>(n) / copy / 1e9);
  std::printf("triad %.2f GB/s\n", 24.0 * static_cast<double>(n) / triad / 1e9);
  return 0;
}

}  // namespace
}  // namespace abcube

int main(int argc, char** argv) {
  return abcube::bench_main<abcube::Options>(argc, argv, "bench_bandwidth", "Memory bandwidth, STREAM copy and triad",
                                             abcube::add_options, abcube::run);
}
