// Wall-clock timing of passes, in milliseconds (every --stats figure uses this).
#pragma once
#include <chrono>

namespace abcube {

using Clock = std::chrono::steady_clock;

inline double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace abcube
