// Errors that carry where they came from (pbrt-v4 FileLoc style).
#pragma once
#include <stdexcept>
#include <string>

namespace abcube {

// Bad user input: a scene, a command line, an input image. The program turns it
// into one line on stderr and exit status 2. The message already names the place,
// e.g. "scene.json:12:5: ..." or "scene.json: objects[3].radius: must be > 0, got -1".
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A failure that is not the user's input (GL context lost, disk full, ...): exit 1.
struct RuntimeFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Always-on invariant check that prints its operands (pbrt-v4 CHECK).
[[noreturn]] void check_failed(const char* expr, const char* file, int line, const std::string& detail);

}  // namespace abcube

#define ABCUBE_CHECK(cond, detail)                                        \
  do {                                                                    \
    if (!(cond)) ::abcube::check_failed(#cond, __FILE__, __LINE__, (detail)); \
  } while (0)
