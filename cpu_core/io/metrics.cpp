#include "io/metrics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "base/error.hpp"
#include "base/statistics.hpp"
#include "io/image_io.hpp"

namespace abcube {

namespace {

// Allowance so that two 8-bit values one code apart are not "over 1/255".
constexpr double SHARE_SLACK = 1e-6;

glm::dvec3 displayed(const Image& img, int x, int y) {
  const glm::vec3 c = img.rgb(x, y);
  return glm::dvec3(srgb_encode(c.r), srgb_encode(c.g), srgb_encode(c.b));
}

void check_same_size(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height) {
    throw InputError("images differ in size: " + std::to_string(a.width) + "x" + std::to_string(a.height) + " vs " +
                     std::to_string(b.width) + "x" + std::to_string(b.height));
  }
  if (a.channels < 1 || b.channels < 1) throw InputError("images must have at least one channel");
}

}  // namespace

double psnr_of_mse(double mse) {
  return mse > 0.0 ? 10.0 * std::log10(1.0 / mse) : std::numeric_limits<double>::infinity();
}

SampledError sampled_error(const Image& a, const Image& b, const std::vector<uint8_t>& only) {
  check_same_size(a, b);
  const size_t pixels = static_cast<size_t>(a.width) * static_cast<size_t>(a.height);
  ABCUBE_CHECK(only.size() == pixels, "sampled_error: the mask is not width x height");
  double sum = 0, sum_sq = 0;
  SampledError s;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      if (!only[static_cast<size_t>(y) * static_cast<size_t>(a.width) + static_cast<size_t>(x)]) continue;
      const glm::dvec3 d = displayed(a, x, y) - displayed(b, x, y);
      const double e = glm::dot(d, d) / 3.0;
      sum += e;
      sum_sq += e * e;
      ++s.pixels;
    }
  }
  if (s.pixels == 0) return s;
  const double k = static_cast<double>(s.pixels), n = static_cast<double>(pixels);
  s.mse = sum / k;
  // The sample variance of the per-pixel errors, and the finite-population correction:
  // every pixel counted leaves no sampling error.
  const double variance = k > 1 ? std::max(0.0, (sum_sq - k * s.mse * s.mse) / (k - 1)) : s.mse * s.mse;
  s.mse_standard_error = std::sqrt(variance / k * std::max(0.0, 1.0 - k / n));
  s.psnr = psnr_of_mse(s.mse);
  s.psnr_low = psnr_of_mse(s.mse + 1.645 * s.mse_standard_error);
  return s;
}

ImageError image_error(const Image& a, const Image& b) {
  check_same_size(a, b);
  ImageError e;
  const size_t pixels = static_cast<size_t>(a.width) * static_cast<size_t>(a.height);
  if (pixels == 0) {
    e.psnr = std::numeric_limits<double>::infinity();
    return e;
  }
  double sum_sq = 0, linear_sq = 0, relative = 0;
  size_t over1 = 0, over2 = 0, over8 = 0;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      const glm::dvec3 d = glm::abs(displayed(a, x, y) - displayed(b, x, y));
      sum_sq += glm::dot(d, d);
      const double m = std::max(d.x, std::max(d.y, d.z));
      if (m > e.max_abs) {
        e.max_abs = m;
        e.worst_x = x;
        e.worst_y = y;
        e.worst_channel = d.x == m ? 0 : d.y == m ? 1 : 2;
      }
      if (m > 1.0 / 255.0 + SHARE_SLACK) ++over1;
      if (m > 2.0 / 255.0 + SHARE_SLACK) ++over2;
      if (m > 8.0 / 255.0 + SHARE_SLACK) ++over8;
      const glm::dvec3 la(a.rgb(x, y)), lb(b.rgb(x, y));
      const glm::dvec3 ld = glm::abs(la - lb);
      linear_sq += glm::dot(ld, ld);
      e.linear_max_abs = std::max(e.linear_max_abs, std::max(ld.x, std::max(ld.y, ld.z)));
      for (int k = 0; k < 3; ++k) relative += ld[k] / std::max(std::abs(lb[k]), 1.0 / 255.0);
      e.hdr = e.hdr || std::max(la.x, std::max(la.y, la.z)) > 1.0 || std::max(lb.x, std::max(lb.y, lb.z)) > 1.0;
    }
  }
  const double n = static_cast<double>(pixels);
  e.rmse = std::sqrt(sum_sq / (3.0 * n));
  e.psnr = psnr_of_mse(e.rmse * e.rmse);
  e.share_over_1 = static_cast<double>(over1) / n;
  e.share_over_2 = static_cast<double>(over2) / n;
  e.share_over_8 = static_cast<double>(over8) / n;
  e.linear_rmse = std::sqrt(linear_sq / (3.0 * n));
  e.relative_mean = relative / (3.0 * n);
  const glm::vec3 wa = a.rgb(e.worst_x, e.worst_y), wb = b.rgb(e.worst_x, e.worst_y);
  for (int k = 0; k < 3; ++k) {
    e.worst_a[k] = wa[k];
    e.worst_b[k] = wb[k];
  }
  return e;
}

double share_over(const Image& a, const Image& b, double threshold) {
  check_same_size(a, b);
  const size_t pixels = static_cast<size_t>(a.width) * static_cast<size_t>(a.height);
  if (pixels == 0) return 0.0;
  size_t over = 0;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      const glm::dvec3 d = glm::abs(displayed(a, x, y) - displayed(b, x, y));
      over += std::max(d.x, std::max(d.y, d.z)) > threshold + SHARE_SLACK;
    }
  }
  return static_cast<double>(over) / static_cast<double>(pixels);
}

glm::dvec3 heatmap_ramp(double d) {
  struct Stop {
    double at;
    glm::dvec3 rgb;
  };
  static const std::array<Stop, 7> STOPS = {{
      {0.0, {0, 0, 0}},
      {1.0 / 255, {0, 0, 0.35}},
      {2.0 / 255, {0, 0, 1}},
      {4.0 / 255, {0, 1, 1}},
      {8.0 / 255, {0, 1, 0}},
      {32.0 / 255, {1, 1, 0}},
      {128.0 / 255, {1, 0, 0}},
  }};
  if (!(d > 0.0)) return STOPS[0].rgb;
  for (size_t i = 1; i < STOPS.size(); ++i) {
    if (d <= STOPS[i].at) {
      const double f = (d - STOPS[i - 1].at) / (STOPS[i].at - STOPS[i - 1].at);
      return glm::mix(STOPS[i - 1].rgb, STOPS[i].rgb, f);
    }
  }
  return STOPS.back().rgb;
}

Image error_heatmap(const Image& a, const Image& b) {
  check_same_size(a, b);
  Image out(a.width, a.height, 3);
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      const glm::dvec3 d = glm::abs(displayed(a, x, y) - displayed(b, x, y));
      const glm::dvec3 shown = heatmap_ramp(std::max(d.x, std::max(d.y, d.z)));
      out.set_rgb(x, y,
                  glm::vec3(srgb_decode(static_cast<float>(shown.r)), srgb_decode(static_cast<float>(shown.g)),
                            srgb_decode(static_cast<float>(shown.b))));
    }
  }
  return out;
}

double error_cp(const glm::dvec3& lookup_dir, const glm::dvec3& sigma) {
  const double lp = glm::length(lookup_dir), ls = glm::length(sigma);
  ABCUBE_CHECK(lp > 0.0 && ls > 0.0, "error_cp needs non-zero vectors, got |lookup_dir| = " + std::to_string(lp) +
                                         ", |sigma| = " + std::to_string(ls));
  // thesis 9.2, eq. 5: Error_CP = (1 - P' . [[Sigma]]) / 2
  return std::clamp((1.0 - glm::dot(lookup_dir / lp, sigma / ls)) * 0.5, 0.0, 1.0);
}

double error_parallax(const glm::dvec3& found_point, const glm::dvec3& w, const glm::dvec3& r) {
  const glm::dvec3 x = found_point - w;
  const double lx = glm::length(x), lr = glm::length(r);
  ABCUBE_CHECK(lx > 0.0 && lr > 0.0, "error_parallax needs found_point != W and R != 0, got |X' - W| = " +
                                         std::to_string(lx) + ", |R| = " + std::to_string(lr));
  // thesis 9.3, eq. 7: Error_Parallax = (1 - [[X' - W]] . R) / 2
  return std::clamp((1.0 - glm::dot(x / lx, r / lr)) * 0.5, 0.0, 1.0);
}

void ErrorStats::merge(const ErrorStats& other) {
  values_.insert(values_.end(), other.values_.begin(), other.values_.end());
  misses_ += other.misses_;
}

double ErrorStats::mean() const {
  if (values_.empty()) return 0.0;
  double s = 0;
  for (double v : values_) s += v;
  return s / static_cast<double>(values_.size());
}

double ErrorStats::max() const { return values_.empty() ? 0.0 : *std::max_element(values_.begin(), values_.end()); }

double ErrorStats::percentile(double q) const {
  std::vector<double> v(values_);
  return abcube::percentile(v, q);
}

double ErrorStats::share_within(double bound) const {
  if (values_.empty()) return 0.0;
  size_t within = 0;
  for (double v : values_) within += v <= bound;
  return static_cast<double>(within) / static_cast<double>(values_.size());
}

double ErrorStats::miss_share() const {
  const uint64_t n = total();
  return n == 0 ? 0.0 : static_cast<double>(misses_) / static_cast<double>(n);
}

namespace {

// A 3 x 5 pixel font for the legend's numbers: each glyph's rows, top first, 3 bits each
// (the high bit the left column).
int glyph_row(char c, int row) {
  static const char* const DIGITS = "0123456789/";
  static const int GLYPHS[11][5] = {{7, 5, 5, 5, 7}, {2, 6, 2, 2, 7}, {7, 1, 7, 4, 7}, {7, 1, 7, 1, 7},
                                    {5, 5, 7, 1, 1}, {7, 4, 7, 1, 7}, {7, 4, 7, 5, 7}, {7, 1, 2, 2, 2},
                                    {7, 5, 7, 5, 7}, {7, 5, 7, 1, 7}, {1, 1, 2, 4, 4}};
  for (int i = 0; i < 11; ++i) {
    if (DIGITS[i] == c) return GLYPHS[i][row];
  }
  return 0;
}

void draw_text(Image& img, int x0, int y0, const std::string& text, int scale, const glm::vec3& colour) {
  for (size_t i = 0; i < text.size(); ++i) {
    for (int row = 0; row < 5; ++row) {
      const int bits = glyph_row(text[i], row);
      for (int col = 0; col < 3; ++col) {
        if (!(bits & (4 >> col))) continue;
        for (int dy = 0; dy < scale; ++dy) {
          for (int dx = 0; dx < scale; ++dx) {
            const int x = x0 + (static_cast<int>(i) * 4 + col) * scale + dx, y = y0 + row * scale + dy;
            if (x >= 0 && y >= 0 && x < img.width && y < img.height) img.set_rgb(x, y, colour);
          }
        }
      }
    }
  }
}

}  // namespace

Image with_heatmap_legend(const Image& heat) {
  // The ramp's stops, in 1/255 of a displayed value, evenly spaced along the bar.
  static const int STOPS[] = {0, 1, 2, 4, 8, 32, 128};
  constexpr int SEGMENTS = 6;
  const int scale = heat.width >= 320 ? 2 : 1;
  const int bar = 6 * scale, gap = 2 * scale, text = 5 * scale;
  const int strip = gap + bar + gap + text + gap;
  Image out(heat.width, heat.height + strip, 3, 0.f);
  std::copy(heat.data.begin(), heat.data.end(), out.data.begin());
  // Room for the first label's left half and for the last label, "128/255", after its stop.
  const int margin = 4 * scale + 1;
  const int span = std::max(1, heat.width - 2 * margin - 22 * scale);
  const auto linear = [](const glm::dvec3& shown) {
    return glm::vec3(srgb_decode(static_cast<float>(shown.r)), srgb_decode(static_cast<float>(shown.g)),
                     srgb_decode(static_cast<float>(shown.b)));
  };
  for (int x = 0; x < heat.width; ++x) {
    const double t = std::clamp(static_cast<double>(x - margin) / span, 0.0, 1.0) * SEGMENTS;
    const int i = std::min(static_cast<int>(t), SEGMENTS - 1);
    const double d = (STOPS[i] + (t - i) * (STOPS[i + 1] - STOPS[i])) / 255.0;
    for (int y = 0; y < bar; ++y) out.set_rgb(x, heat.height + gap + y, linear(heatmap_ramp(d)));
  }
  if (heat.width >= 60) {  // narrower, the numbers would overlap: the bar alone
    const glm::vec3 white(1.f);
    for (int i = 0; i <= SEGMENTS; ++i) {
      const std::string label = std::to_string(STOPS[i]) + (i == SEGMENTS ? "/255" : "");
      const int digits = static_cast<int>(std::to_string(STOPS[i]).size());
      const int x = margin + span * i / SEGMENTS - digits * 2 * scale;  // the number centred on its stop
      draw_text(out, std::max(0, x), heat.height + gap + bar + gap, label, scale, white);
    }
  }
  return out;
}

}  // namespace abcube
