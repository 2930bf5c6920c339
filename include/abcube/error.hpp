// abcube's exceptions. Nothing in the library exits or aborts the process: every failure
// is one of these, and its message is one line that names where the problem is.
#pragma once
#include <stdexcept>
#include <string>

namespace abcube {

// Bad user input: a scene, an option, a command line, an input image. The message names
// the place, e.g. "scene.json:12:5: ..." or "scene.json: objects[3].radius: must be > 0,
// got -1". The CLI prints it on one line and exits 2; Python raises abcube.SceneError.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A failure that is not the user's input (no GL path works, disk full, ...): exit 1,
// RuntimeError in Python.
struct RuntimeFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A render stopped because it ran past its time limit (RenderOptions::timeout_s).
struct RenderTimeout : RuntimeFailure {
  using RuntimeFailure::RuntimeFailure;
};

// Work stopped because the process was asked to stop (request_stop in renderer.hpp: the
// CLI's SIGINT and SIGTERM handlers). `signal` is the number given to request_stop.
struct Interrupted : RuntimeFailure {
  Interrupted(const std::string& what, int signal_number) : RuntimeFailure(what), signal(signal_number) {}
  int signal;
};

// A failed internal check: a bug in abcube, never the input's fault. Thrown, not aborted,
// so that a host program or an interpreter survives it; the message names the check, its
// file and line, and its operands.
struct InternalError : std::logic_error {
  using std::logic_error::logic_error;
};

}  // namespace abcube
