// What the fuzz harnesses check beyond "no crash" (docs/robustness.md): a scene that
// loads satisfies its invariants, and a refused input is refused with one short line that
// says where. A broken rule prints what broke on stderr and aborts, which libFuzzer reports
// as a crash (and keeps the input) and the replay test (fuzz_replay.cpp) as a failure.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

#include "scene/scene_data.hpp"

// ABCUBE_FUZZ_VERBOSE=1 in the environment: each input's outcome (what loaded, or the
// message) on stderr, to see what the seeds reach.

namespace abcube::fuzz {

// The longest error message a harness accepts: a message quotes input (80 characters, a
// path 1024) a few times at most.
constexpr size_t MAX_MESSAGE_BYTES = 4096;

// Prints "fuzz check failed: WHAT" and aborts.
[[noreturn]] void broken(const std::string& what);

// Every number finite, every index in range (triangle -> object, material; object ->
// its triangle range), every object holding triangles or named by a warning, the camera
// finite with a positive size, the lights and materials finite; THE RADIANCE BOUND under
// MAX_RADIANCE, and a small scene's pixels finite (traced at 4 x 3).
void check_scene(const SceneData& scene);

// An error message: one line, at most MAX_MESSAGE_BYTES, starting with `place` (the file
// name the input was given as, then ':').
void check_message(const std::string& message, const std::string& place);

// Runs `load`; an InputError must pass check_message(place), any other exception is
// broken(). Returns whether `load` returned.
bool expect_input_error_or_success(const std::function<void()>& load, const std::string& place);

// A private folder for the harness's files (under /dev/shm when it exists), made on the
// first call and removed when the process exits.
const std::string& scratch_dir();

// Writes `bytes` to `path` (replacing it); broken() when it cannot.
void write_file(const std::string& path, const uint8_t* bytes, size_t size);

}  // namespace abcube::fuzz
