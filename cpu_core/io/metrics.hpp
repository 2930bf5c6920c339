// Error measures, usable by every method (thesis ch. 9). Image error: two images are
// compared AS DISPLAYED, each RGB channel clamped to [0, 1] and sRGB-encoded (as an 8-bit
// output file gets it) before differencing, so 1/255 is one code value of the written PNG;
// rmse, psnr (peak 1, +infinity for identical images), max_abs, and the shares of pixels over
// 1/255 and 2/255. Ray error (thesis 9.2 eq. 5, 9.3 eq. 7): Error_CP of the lookup direction
// and Error_Parallax of the found point, 0 when exact, 1 when opposite.
// docs/design/metrics.md has the definitions.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "io/image.hpp"

namespace abcube {

// ImageError and image_error(a, b): <abcube/image.hpp>. Throws InputError when the
// sizes differ (naming both).

// The error over some pixels only, as an estimate of the whole image's: the mean squared
// difference of the marked pixels (displayed values, averaged over the three channels, as
// image_error's PSNR counts it), the standard error of that mean as an estimate of the
// image's (simple random sampling without replacement), and the PSNRs of the estimate and
// of its one-sided 95% upper bound. `only`: width x height, row-major, non-zero = counted.
struct SampledError {
  uint64_t pixels = 0;
  double mse = 0, mse_standard_error = 0;
  double psnr = 0;      // of mse
  double psnr_low = 0;  // of mse + 1.645 standard errors: the image reaches it 95% of the time
};
SampledError sampled_error(const Image& a, const Image& b, const std::vector<uint8_t>& only);

// 10 log10(1 / mse): PSNR with a peak of 1 (infinite for 0).
double psnr_of_mse(double mse);

// Share of pixels whose largest displayed channel |d| exceeds `threshold` (idiff's
// -fail; the same 1e-6 slack as share_over_1/2). Throws InputError when sizes differ.
double share_over(const Image& a, const Image& b, double threshold);

// Per-pixel largest channel |d| (as displayed, see above) on a colour ramp, ready to
// write: black 0, dark blue 1/255, blue 2/255, cyan 4/255, green 8/255, yellow 32/255,
// red 128/255 and above, linear between stops (the stops are the displayed colours:
// the image holds their linear values, so an 8-bit file shows exactly these).
Image error_heatmap(const Image& a, const Image& b);

// `heat` (an error_heatmap) with its legend drawn in beneath: the ramp as a bar with its
// stops (0, 1, 2, 4, 8, 32, 128/255) written under it; the same width, a strip taller.
Image with_heatmap_legend(const Image& heat);

// The displayed colour ramp above for a difference d in [0, 1] (sRGB-encoded RGB).
glm::dvec3 heatmap_ramp(double d);

// thesis 9.2, eq. 5: (1 - [[lookup_dir]] . [[sigma]]) / 2; sigma relative to the centre.
// Both vectors must be non-zero (an always-on check: a zero vector is a caller's bug).
double error_cp(const glm::dvec3& lookup_dir, const glm::dvec3& sigma);

// thesis 9.3, eq. 7: (1 - [[found_point - W]] . [[R]]) / 2. found_point must differ from W
// and R be non-zero (checked likewise; a search that returns its own start point W should
// count that ray as a miss instead).
double error_parallax(const glm::dvec3& found_point, const glm::dvec3& w, const glm::dvec3& r);

// Accumulates one error measure over many rays: found values and misses (rays for which
// the method found nothing while the exact tracer did).
class ErrorStats {
 public:
  void add(double value) { values_.push_back(value); }
  void add_miss() { ++misses_; }
  void merge(const ErrorStats& other);

  uint64_t count() const { return values_.size(); }  // found values
  uint64_t miss_count() const { return misses_; }
  uint64_t total() const { return count() + misses_; }
  double mean() const;  // over found values; 0 when there are none
  double max() const;   // 0 when there are none
  // Nearest-rank percentile of the found values (base/statistics.hpp percentile), q in
  // [0, 1]; 0 when there are none.
  double percentile(double q) const;
  double miss_share() const;  // misses / total; 0 when empty
  // Share of the found values <= bound (e.g. thesis 9.3.4's 1/(2 N^2)); 0 when none.
  double share_within(double bound) const;

 private:
  std::vector<double> values_;
  uint64_t misses_ = 0;
};

}  // namespace abcube
