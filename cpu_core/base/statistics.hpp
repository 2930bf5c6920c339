// Order statistics shared by every figure the library and its benchmarks report.
#pragma once
#include <vector>

namespace abcube {

// Nearest-rank percentile (Hyndman & Fan 1996, definition 1), q in [0, 1]: the smallest
// value with at least q * n of the n values at or below it, i.e. the value of rank
// ceil(q n) (index ceil(q n) - 1, clamped to [0, n - 1]); q = 0 gives the minimum, q = 0.5
// of an even count the lower middle value. 0 when there are no values. Reorders `values`
// (std::nth_element).
double percentile(std::vector<double>& values, double q);

}  // namespace abcube
