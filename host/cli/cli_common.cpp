#include "cli/cli_common.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "base/error.hpp"

namespace abcube {

Args::Args(const std::vector<std::string>& words, const std::vector<std::string>& with_value,
           const std::vector<std::string>& flags) {
  auto contains = [](const std::vector<std::string>& v, const std::string& s) {
    return std::find(v.begin(), v.end(), s) != v.end();
  };
  for (size_t i = 0; i < words.size(); ++i) {
    std::string w = words[i];
    if (w.size() > 1 && w[0] == '-' && !(w.size() > 1 && (std::isdigit(static_cast<unsigned char>(w[1])) || w[1] == '.'))) {
      std::string value;
      bool inline_value = false;
      const size_t eq = w.find('=');
      if (eq != std::string::npos && w.rfind("--", 0) == 0) {
        value = w.substr(eq + 1);
        w = w.substr(0, eq);
        inline_value = true;
      }
      if (contains(flags, w) && !inline_value) {
        values_[w] = "1";
      } else if (contains(with_value, w)) {
        if (!inline_value) {
          if (i + 1 >= words.size()) throw InputError(w + ": needs a value");
          value = words[++i];
        }
        values_[w] = value;
      } else {
        throw InputError(w + ": unknown option");
      }
    } else {
      positional_.push_back(w);
    }
  }
}

std::string Args::get(const std::string& name, const std::string& fallback) const {
  auto it = values_.find(name);
  return it == values_.end() ? fallback : it->second;
}

int Args::get_int(const std::string& name, int fallback, int lo, int hi) const {
  if (!has(name)) return fallback;
  const std::string s = get(name);
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0' || errno != 0 || v < lo || v > hi) {
    throw InputError(name + ": must be an integer in [" + std::to_string(lo) + ", " +
                     std::to_string(hi) + "], got '" + s + "'");
  }
  return static_cast<int>(v);
}

double Args::get_double(const std::string& name, double fallback, double lo, double hi) const {
  if (!has(name)) return fallback;
  const std::string s = get(name);
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || !std::isfinite(v) || v < lo || v > hi) {
    throw InputError(name + ": must be a number in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                     "], got '" + s + "'");
  }
  return v;
}

void Args::expect_positional(size_t count, const std::string& what) const {
  if (positional_.size() < count) throw InputError("missing " + what);
  if (positional_.size() > count) throw InputError("unexpected argument '" + positional_[count] + "'");
}

bool stderr_is_terminal() { return isatty(STDERR_FILENO) == 1; }

}  // namespace abcube
