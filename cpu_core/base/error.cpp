#include "base/error.hpp"

namespace abcube {

void check_failed(const char* expr, const char* file, int line, const std::string& detail) {
  throw InternalError(std::string("internal check failed: ") + expr + " at " + file + ":" + std::to_string(line) +
                      ": " + detail);
}

}  // namespace abcube
