// A plain parallel loop: items handed to std::threads dynamically, the calling thread
// working too, the first exception rethrown after every thread has stopped.
#pragma once
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace abcube {

// requested > 0, else the hardware's count; never more than `items`, never below 1.
inline int thread_count(int requested, size_t items) {
  const int hw = static_cast<int>(std::thread::hardware_concurrency());
  const int n = requested > 0 ? requested : std::max(hw, 1);
  return static_cast<int>(std::clamp<size_t>(static_cast<size_t>(n), 1, std::max<size_t>(items, 1)));
}

// Calls fn(item, worker) for item in [0, count), worker in [0, threads).
template <class Fn>
void parallel_for(size_t count, int threads, Fn&& fn) {
  std::atomic<size_t> next{0};
  std::vector<std::exception_ptr> errors(static_cast<size_t>(threads));
  auto work = [&](int worker) {
    try {
      for (size_t i = next++; i < count; i = next++) fn(i, worker);
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

}  // namespace abcube
