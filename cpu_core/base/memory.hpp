// What the machine can hold: used to refuse work whose estimate exceeds it.
#pragma once
#include <cstddef>
#include <cstdint>

namespace abcube {

// MemAvailable from /proc/meminfo in bytes (or total RAM if that line is missing).
uint64_t available_memory_bytes();

// Peak resident set size of this process so far, in bytes (getrusage).
uint64_t peak_rss_bytes();

}  // namespace abcube
