// What this process holds now: resident memory and open file descriptors (Linux /proc).
// Header only, for bench_soak and the API tests' memory and descriptor bounds.
#pragma once
#include <dirent.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>

namespace abcube {

// VmRSS of /proc/self/status in bytes ("VmRSS:   1234 kB"); 0 where /proc is missing.
inline uint64_t resident_bytes() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmRSS:", 0) == 0) return std::strtoull(line.c_str() + 6, nullptr, 10) * 1024;
  }
  return 0;
}

// VmHWM of /proc/self/status in bytes: the peak resident set since the process started or
// since reset_peak_resident(); 0 where /proc is missing.
inline uint64_t peak_resident_bytes() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmHWM:", 0) == 0) return std::strtoull(line.c_str() + 6, nullptr, 10) * 1024;
  }
  return 0;
}

// Resets VmHWM to the present resident set (Linux 4.0: "5" to /proc/self/clear_refs);
// false where that is not possible.
inline bool reset_peak_resident() {
  std::ofstream out("/proc/self/clear_refs");
  out << "5";
  out.flush();
  return static_cast<bool>(out);
}

// Entries of /proc/self/fd, less the one the listing itself holds open; -1 without /proc.
inline int open_descriptors() {
  DIR* dir = opendir("/proc/self/fd");
  if (!dir) return -1;
  int count = 0;
  while (const dirent* entry = readdir(dir)) count += entry->d_name[0] != '.';
  closedir(dir);
  return count - 1;
}

}  // namespace abcube
