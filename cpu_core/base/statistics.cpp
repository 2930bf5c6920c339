#include "base/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace abcube {

double percentile(std::vector<double>& values, double q) {
  if (values.empty()) return 0.0;
  const double n = static_cast<double>(values.size());
  const size_t rank = static_cast<size_t>(std::max(1.0, std::ceil(std::clamp(q, 0.0, 1.0) * n)));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(rank - 1), values.end());
  return values[rank - 1];
}

}  // namespace abcube
