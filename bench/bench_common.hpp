// Shared by the benchmark programs: the command line (bench_cli.hpp) and errors as one line
// with the cli.md exit codes.
#pragma once
#include <cstdio>
#include <exception>

#include "bench_cli.hpp"

#include <abcube/error.hpp>

namespace abcube {

// Runs fn(); bad input -> "name: message", exit 2; any other failure -> exit 1.
template <class Fn>
int guarded_main(const char* name, Fn&& fn) {
  try {
    return fn();
  } catch (const InputError& e) {
    std::fprintf(stderr, "%s: %s\n", name, e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", name, e.what());
    return 1;
  }
}

// A benchmark program's whole main: its options registered by add_options(line, options)
// on a command line described by `description`, parsed, then run(options) under
// guarded_main.
template <class Options, class AddOptions, class Run>
int bench_main(int argc, char** argv, const char* name, const char* description, AddOptions&& add_options, Run&& run) {
  Options options;
  BenchCommandLine line{description};
  add_options(line, options);
  if (const int status = line.parse(argc, argv, name); status >= 0) return status;
  return guarded_main(name, [&] { return run(options); });
}

}  // namespace abcube
