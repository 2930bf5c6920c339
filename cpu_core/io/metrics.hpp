// Error measures, usable by every method (design.md "Error measures"; thesis ch. 9).
//
// Image error. Two images are compared AS DISPLAYED: each RGB channel is clamped to
// [0, 1] and sRGB-encoded (image_io.hpp srgb_encode, the encoding an 8-bit output file
// gets) before differencing, so a difference of 1/255 is one code value of the written
// PNG, and errors in the darks weigh as much as the eye sees them. Alpha and channels
// beyond the third are ignored; a one-channel image counts as grey. Over all pixels and
// the three channels:
//   rmse     sqrt(mean of d^2)
//   psnr     20 log10(1 / rmse)  (peak 1); +infinity for identical images (callers print
//            "inf" or a large number)
//   max_abs  largest |d|
//   share_over_1, share_over_2: share of PIXELS whose largest channel |d| exceeds 1/255,
//            2/255 (plus 1e-6, so that exact 8-bit round trips do not count).
//
// Ray error (thesis 9.2 eq. 5 and 9.3 eq. 7), with [[A]] = A/|A|:
//   Error_CP       = (1 - [[P']] . [[Sigma]]) / 2   P' the lookup direction, Sigma the true
//                                                    point, both relative to the cube centre
//   Error_Parallax = (1 - [[X' - W]] . [[R]]) / 2   X' the point the method found, W the ray
//                                                    origin, R the ray direction
// Both are 0 when exact, 1/2 at a right angle, 1 when opposite.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "io/image.hpp"

namespace abcube {

// ImageError and image_error(a, b): <abcube/image.hpp>. Throws InputError when the
// sizes differ (naming both).

// Share of pixels whose largest displayed channel |d| exceeds `threshold` (idiff's
// -fail; the same 1e-6 slack as share_over_1/2). Throws InputError when sizes differ.
double share_over(const Image& a, const Image& b, double threshold);

// Per-pixel largest channel |d| (as displayed, see above) on a colour ramp, ready to
// write: black 0, dark blue 1/255, blue 2/255, cyan 4/255, green 8/255, yellow 32/255,
// red 128/255 and above, linear between stops (the stops are the displayed colours:
// the image holds their linear values, so an 8-bit file shows exactly these).
Image error_heatmap(const Image& a, const Image& b);

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
  double mean() const;                 // over found values; 0 when there are none
  double max() const;                  // 0 when there are none
  // Nearest-rank percentile of the found values (base/statistics.hpp percentile), q in
  // [0, 1]; 0 when there are none.
  double percentile(double q) const;
  double miss_share() const;           // misses / total; 0 when empty
  // Share of the found values <= bound (e.g. thesis 9.3.4's 1/(2 N^2)); 0 when none.
  double share_within(double bound) const;

 private:
  std::vector<double> values_;
  uint64_t misses_ = 0;
};

}  // namespace abcube
