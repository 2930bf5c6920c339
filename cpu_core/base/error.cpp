#include "base/error.hpp"

#include <cstdio>
#include <cstdlib>

namespace abcube {

void check_failed(const char* expr, const char* file, int line, const std::string& detail) {
  std::fprintf(stderr, "abcube: internal check failed: %s at %s:%d: %s\n", expr, file, line,
               detail.c_str());
  std::abort();
}

}  // namespace abcube
