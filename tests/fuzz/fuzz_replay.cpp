// A main for the fuzz harnesses in the ordinary build (no libFuzzer): runs
// LLVMFuzzerTestOneInput once on each file named, or on each file of each folder named
// (sorted), and prints how many ran. The ctest tests fuzz.replay.* run it on the seeds
// and on every input that once crashed (tests/fuzz/regressions/), so that a fixed crash
// stays fixed. A failed check aborts (fuzz_checks.hpp); no input at all is an error too.
// Like libFuzzer, which reports any one allocation over 2 GiB, the replay runs in a bounded
// address space, so that an input that once made a loader allocate what its header claims
// fails here too (std::bad_alloc is not an InputError): REPLAY_ADDRESS_SPACE, and per core
// REPLAY_SPACE_PER_CORE for what each of the load's threads reserves (its stack, a malloc
// arena), so that a machine with many cores does not fail for its cores. Not under a
// sanitizer, whose shadow memory needs the address space.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sys/resource.h>
#include <string>
#include <thread>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define ABCUBE_REPLAY_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define ABCUBE_REPLAY_SANITIZED 1
#endif
#endif

namespace {
constexpr rlim_t REPLAY_ADDRESS_SPACE = rlim_t{3} << 30;
constexpr rlim_t REPLAY_SPACE_PER_CORE = rlim_t{256} << 20;
}  // namespace

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
#ifndef ABCUBE_REPLAY_SANITIZED
  const rlim_t space = REPLAY_ADDRESS_SPACE + REPLAY_SPACE_PER_CORE * std::max(1u, std::thread::hardware_concurrency());
  const rlimit cap{space, space};
  if (setrlimit(RLIMIT_AS, &cap) != 0) std::perror("fuzz_replay: setrlimit");
#endif
  std::vector<fs::path> files;
  for (int i = 1; i < argc; ++i) {
    const fs::path p(argv[i]);
    if (fs::is_directory(p)) {
      for (const auto& e : fs::recursive_directory_iterator(p)) {
        if (e.is_regular_file()) files.push_back(e.path());
      }
    } else if (fs::is_regular_file(p)) {
      files.push_back(p);
    } else {
      std::fprintf(stderr, "fuzz_replay: %s: no such file or folder\n", argv[i]);
      return 2;
    }
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    std::fprintf(stderr, "fuzz_replay: no input files\n");
    return 2;
  }
  for (const fs::path& f : files) {
    std::ifstream in(f, std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::fprintf(stderr, "%s\n", f.string().c_str());
    LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
  }
  std::printf("fuzz_replay: %zu inputs, every check passed\n", files.size());
  return 0;
}
