// Shared by the benchmark programs: errors become one line and the cli.md exit codes.
#pragma once
#include <cstdio>
#include <exception>

#include "error.hpp"

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

}  // namespace abcube
