// A plain parallel loop: items handed to std::threads dynamically, the calling thread
// working too, the first exception rethrown after every thread has stopped. A render's
// time limit (RenderTimeout) and a request to stop (Interrupted) are checked before every
// item: see ScopedDeadline.
#pragma once
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstddef>
#include <cstdio>
#include <exception>
#include <string>
#include <thread>
#include <vector>

#include <abcube/error.hpp>

namespace abcube {

// requested > 0, else the hardware's count; never more than `items`, never below 1.
inline int thread_count(int requested, size_t items) {
  const int hw = static_cast<int>(std::thread::hardware_concurrency());
  const int n = requested > 0 ? requested : std::max(hw, 1);
  return static_cast<int>(std::clamp<size_t>(static_cast<size_t>(n), 1, std::max<size_t>(items, 1)));
}

// A request to stop every render of the process (request_stop, renderer.hpp: a signal
// handler may make it, so it is a lock-free atomic with no dynamic initialisation). 0: none;
// else the number given, usually the signal. Checked wherever a deadline is.
inline std::atomic<int>& stop_request() {
  static std::atomic<int> request{0};
  return request;
}

// Throws Interrupted when a stop was requested.
inline void check_stop_request() {
  if (const int s = stop_request().load(std::memory_order_relaxed)) {
    throw Interrupted(s == SIGINT    ? "interrupted (SIGINT)"
                      : s == SIGTERM ? "terminated (SIGTERM)"
                                     : "stopped (signal " + std::to_string(s) + ")",
                      s);
  }
}

// A render's time limit. The thread that starts a render installs one for the render's
// length (ScopedDeadline); every parallel_for started under it, on that thread or on its
// workers, checks it before each item and throws RenderTimeout past it (and Interrupted
// when a stop was requested, limit or none). The one piece of per-thread state in the
// library, scoped to one render call.
struct Deadline {
  std::chrono::steady_clock::time_point at;
  double seconds = 0;  // the limit as given, for the message
  bool passed() const { return std::chrono::steady_clock::now() > at; }
  void check() const {
    if (passed()) throw RenderTimeout("timed out after " + format_seconds(seconds) + " s");
  }
  // "2", "0.5", "1e-06": the limit as a person wrote it.
  static std::string format_seconds(double s) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", s);
    return text;
  }
};

inline const Deadline*& current_deadline() {
  thread_local const Deadline* deadline = nullptr;
  return deadline;
}

// Installs `d` (may be null) on this thread until the end of the scope.
class ScopedDeadline {
 public:
  explicit ScopedDeadline(const Deadline* d) : previous_(current_deadline()) { current_deadline() = d; }
  ~ScopedDeadline() { current_deadline() = previous_; }
  ScopedDeadline(const ScopedDeadline&) = delete;
  ScopedDeadline& operator=(const ScopedDeadline&) = delete;

 private:
  const Deadline* previous_;
};

// Throws Interrupted when a stop was requested, RenderTimeout when this thread's render is
// over its limit.
inline void check_deadline() {
  check_stop_request();
  if (const Deadline* d = current_deadline()) d->check();
}

// Calls fn(item, worker) for item in [0, count), worker in [0, threads).
template <class Fn>
void parallel_for(size_t count, int threads, Fn&& fn) {
  std::atomic<size_t> next{0};
  std::vector<std::exception_ptr> errors(static_cast<size_t>(threads));
  const Deadline* deadline = current_deadline();
  auto work = [&](int worker) {
    const ScopedDeadline scope(deadline);  // the workers inherit the caller's limit
    try {
      for (size_t i = next++; i < count; i = next++) {
        check_stop_request();
        if (deadline) deadline->check();
        fn(i, worker);
      }
    } catch (...) {
      errors[static_cast<size_t>(worker)] = std::current_exception();
      next = count;  // stop the others early
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work, t);
  work(0);
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

// Calls fn(i) for i in [0, count), handed out `run` items at a time (the deadline and a
// stop request checked between runs), on up to `threads` threads (0: every core). For
// loops over many cheap items, each writing its own place.
template <class Fn>
void parallel_for_runs(size_t count, size_t run, int threads, Fn&& fn) {
  const size_t runs = (count + run - 1) / run;
  parallel_for(runs, thread_count(threads, runs), [&](size_t r, int) {
    const size_t end = std::min(count, (r + 1) * run);
    for (size_t i = r * run; i < end; ++i) fn(i);
  });
}

}  // namespace abcube
