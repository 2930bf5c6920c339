// Errors that carry where they came from (pbrt-v4 FileLoc style).
#pragma once
#include <string>

#include <abcube/error.hpp>  // InputError, RuntimeFailure, InternalError

namespace abcube {

// Always-on invariant check that names its operands (pbrt-v4 CHECK); throws InternalError.
[[noreturn]] void check_failed(const char* expr, const char* file, int line, const std::string& detail);

}  // namespace abcube

#define ABCUBE_CHECK(cond, detail)                                        \
  do {                                                                    \
    if (!(cond)) ::abcube::check_failed(#cond, __FILE__, __LINE__, (detail)); \
  } while (0)
