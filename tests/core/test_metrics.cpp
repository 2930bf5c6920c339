// Known answers for the error measures (metrics.hpp; thesis ch. 9).
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "base/constants.hpp"
#include "base/error.hpp"
#include "io/image_io.hpp"
#include "io/metrics.hpp"
#include "reference/raytrace.hpp"

namespace abcube {
namespace {

using glm::dvec3;

// An image whose displayed (sRGB-encoded) value is `shown` everywhere.
Image displayed_flat(int w, int h, float shown) { return Image(w, h, 3, srgb_decode(shown)); }

TEST(Metrics, IdenticalImagesHaveNoErrorAndInfinitePsnr) {
  const Image a = displayed_flat(7, 5, 0.3f);
  const ImageError e = image_error(a, a);
  EXPECT_EQ(e.rmse, 0.0);
  EXPECT_TRUE(std::isinf(e.psnr) && e.psnr > 0);
  EXPECT_EQ(e.max_abs, 0.0);
  EXPECT_EQ(e.share_over_1, 0.0);
  EXPECT_EQ(e.share_over_2, 0.0);
}

TEST(Metrics, UniformDisplayedOffsetGivesKnownRmseAndPsnr) {
  // Displayed 0.5 vs 0.6 everywhere: rmse 0.1, psnr 20 dB, every pixel over 2/255.
  const ImageError e = image_error(displayed_flat(8, 4, 0.5f), displayed_flat(8, 4, 0.6f));
  EXPECT_NEAR(e.rmse, 0.1, 1e-6);
  EXPECT_NEAR(e.psnr, 20.0, 1e-4);
  EXPECT_NEAR(e.max_abs, 0.1, 1e-6);
  EXPECT_EQ(e.share_over_2, 1.0);
}

TEST(Metrics, ComparesAsDisplayedNotLinear) {
  // The same linear difference weighs more in the darks once sRGB-encoded.
  const ImageError dark = image_error(Image(2, 2, 3, 0.01f), Image(2, 2, 3, 0.02f));
  const ImageError bright = image_error(Image(2, 2, 3, 0.81f), Image(2, 2, 3, 0.82f));
  EXPECT_NEAR(dark.max_abs, srgb_encode(0.02f) - srgb_encode(0.01f), 1e-6);
  EXPECT_GT(dark.rmse, 3.0 * bright.rmse);
  // Out-of-range values are clamped like a written file clamps them.
  EXPECT_EQ(image_error(Image(1, 1, 3, 1.0f), Image(1, 1, 3, 7.0f)).rmse, 0.0);
}

// The error of some pixels as an estimate of the image's: every pixel marked gives the
// image's PSNR with no sampling error; half the pixels, the mean of theirs, and a lower
// bound below the estimate when the errors vary.
TEST(Metrics, SampledErrorEstimatesTheImagesError) {
  Image a = displayed_flat(8, 4, 0.5f);
  const Image b = displayed_flat(8, 4, 0.6f);
  for (int x = 0; x < 8; ++x) {
    for (int k = 0; k < 3; ++k) a.at(x, 0)[k] = srgb_decode(0.3f);  // row 0: 0.3 off
  }
  const ImageError whole = image_error(a, b);
  const SampledError all = sampled_error(a, b, std::vector<uint8_t>(32, 1));
  EXPECT_EQ(all.pixels, 32u);
  EXPECT_NEAR(all.psnr, whole.psnr, 1e-9);
  EXPECT_EQ(all.mse_standard_error, 0.0);
  EXPECT_NEAR(all.psnr_low, whole.psnr, 1e-9);
  std::vector<uint8_t> odd(32, 0);
  for (size_t k = 1; k < 32; k += 2) odd[k] = 1;  // half of each row
  const SampledError half = sampled_error(a, b, odd);
  EXPECT_EQ(half.pixels, 16u);
  EXPECT_NEAR(half.mse, whole.rmse * whole.rmse, 1e-12);  // every row equally sampled
  EXPECT_GT(half.mse_standard_error, 0.0);
  EXPECT_LT(half.psnr_low, half.psnr);
  std::vector<uint8_t> row1(32, 0);
  for (size_t k = 8; k < 16; ++k) row1[k] = 1;
  EXPECT_NEAR(sampled_error(a, b, row1).psnr, 20.0, 1e-4);  // the 0.1 rows only
  EXPECT_TRUE(std::isinf(psnr_of_mse(0.0)));
}

TEST(Metrics, SharesCountPixelsOverThresholds) {
  // Ten pixels; displayed differences 0, 1/255 (not over), 1.5/255, 2/255 (not over 2),
  // 3/255 in one channel only, and 5 equal pixels.
  Image a(10, 1, 3, 0.f), b(10, 1, 3, 0.f);
  const double shown[] = {0, 1, 1.5, 2, 3};
  for (int x = 0; x < 5; ++x) {
    a.at(x, 0)[1] = srgb_decode(0.5f);
    b.at(x, 0)[1] = srgb_decode(static_cast<float>(0.5 + shown[x] / 255.0));
  }
  const ImageError e = image_error(a, b);
  EXPECT_DOUBLE_EQ(e.share_over_1, 0.3);  // 1.5, 2, 3
  EXPECT_DOUBLE_EQ(e.share_over_2, 0.1);  // 3
  EXPECT_NEAR(e.max_abs, 3.0 / 255.0, 1e-6);
  // rmse over 10 pixels x 3 channels
  const double sum_sq = (1 + 2.25 + 4 + 9) / (255.0 * 255.0);
  EXPECT_NEAR(e.rmse, std::sqrt(sum_sq / 30.0), 1e-7);
}

TEST(Metrics, WorstPixelAndLinearFigures) {
  Image a(4, 3, 3, 0.5f), b(4, 3, 3, 0.5f);
  a.set_rgb(2, 1, glm::vec3(0.5f, 4.0f, 0.5f));   // HDR: displayed as 1, linear 3.5 away
  a.set_rgb(0, 2, glm::vec3(0.5f, 0.5f, 0.25f));  // a smaller displayed difference
  const ImageError e = image_error(a, b);
  EXPECT_EQ(e.worst_x, 2);
  EXPECT_EQ(e.worst_y, 1);
  EXPECT_EQ(e.worst_channel, 1);
  EXPECT_EQ(e.worst_a[1], 4.0f);
  EXPECT_EQ(e.worst_b[1], 0.5f);
  EXPECT_TRUE(e.hdr);
  EXPECT_NEAR(e.linear_max_abs, 3.5, 1e-9);
  EXPECT_NEAR(e.linear_rmse, std::sqrt((3.5 * 3.5 + 0.25 * 0.25) / 36.0), 1e-7);
  EXPECT_NEAR(e.relative_mean, (3.5 / 0.5 + 0.25 / 0.5) / 36.0, 1e-7);
  EXPECT_NEAR(e.max_abs, 1.0 - srgb_encode(0.5f), 1e-6);  // displayed values clamp at 1
  EXPECT_DOUBLE_EQ(e.share_over_8, 2.0 / 12.0);
}

TEST(Metrics, TheLegendSitsBeneathTheHeatmap) {
  Image heat(320, 10, 3, 0.f);
  heat.set_rgb(5, 5, glm::vec3(1.f));
  const Image l = with_heatmap_legend(heat);
  ASSERT_EQ(l.width, 320);
  ASSERT_GT(l.height, 10);
  EXPECT_EQ(l.rgb(5, 5), glm::vec3(1.f));  // the heat map itself unchanged
  // The bar runs from the ramp's black (left) to its red (right), its numbers in white below.
  const int bar = 10 + 4 + 3;  // the strip's gap, then the middle of the bar (scale 2)
  EXPECT_LT(srgb_encode(l.rgb(3, bar).r), 0.05);
  EXPECT_GT(srgb_encode(l.rgb(300, bar).r), 0.9);
  int white = 0;
  for (int y = 10 + 16; y < l.height; ++y) {
    for (int x = 0; x < l.width; ++x) white += l.rgb(x, y) == glm::vec3(1.f);
  }
  EXPECT_GT(white, 100);
}

TEST(Metrics, SizeMismatchIsAnInputError) {
  EXPECT_THROW(image_error(Image(4, 4), Image(4, 5)), InputError);
  EXPECT_THROW(error_heatmap(Image(3, 4), Image(4, 4)), InputError);
}

TEST(Metrics, HeatmapShowsTheRamp) {
  Image a(3, 1, 3, 0.f), b(3, 1, 3, 0.f);
  b.set_rgb(1, 0, glm::vec3(srgb_decode(static_cast<float>(8.0 / 255.0)), 0, 0));
  b.set_rgb(2, 0, glm::vec3(1.0f));
  const Image h = error_heatmap(a, b);
  ASSERT_EQ(h.width, 3);
  EXPECT_EQ(h.rgb(0, 0), glm::vec3(0.0f));             // equal: black
  EXPECT_NEAR(srgb_encode(h.rgb(1, 0).g), 1.0, 1e-4);  // 8/255: green
  EXPECT_NEAR(srgb_encode(h.rgb(1, 0).r), 0.0, 1e-4);
  EXPECT_NEAR(srgb_encode(h.rgb(2, 0).r), 1.0, 1e-6);               // full scale: red
  EXPECT_NEAR(heatmap_ramp(1.5 / 255).b, 0.35 + 0.5 * 0.65, 1e-9);  // linear between stops
}

TEST(Metrics, ErrorCpKnownAngles) {
  const dvec3 sigma(0, 0, 5);
  EXPECT_NEAR(error_cp({0, 0, 1}, sigma), 0.0, 1e-15);
  EXPECT_NEAR(error_cp({0, 0, -2}, sigma), 1.0, 1e-15);
  EXPECT_NEAR(error_cp({3, 0, 0}, sigma), 0.5, 1e-15);
  const double a = 0.01;  // small angle: (1 - cos a)/2 ~ a^2/4
  EXPECT_NEAR(error_cp({std::sin(a), 0, std::cos(a)}, sigma), (1 - std::cos(a)) / 2, 1e-15);
}

TEST(Metrics, ErrorParallaxKnownAngles) {
  const dvec3 w(1, 2, 3), r(0, 1, 0);
  EXPECT_NEAR(error_parallax(w + dvec3(0, 4, 0), w, r), 0.0, 1e-15);
  EXPECT_NEAR(error_parallax(w + dvec3(0, -4, 0), w, r), 1.0, 1e-15);
  EXPECT_NEAR(error_parallax(w + dvec3(1, 1, 0), w, r), (1 - std::cos(PI / 4)) / 2, 1e-15);
}

TEST(Metrics, BisectorLookupErrorCpIsAtMostHalf) {
  // thesis 9.2.3: for the lookup direction [[R + [[W]]]] the true point W + l R (l >= 0)
  // is never more than 90 degrees away, so Error_CP <= 1/2; looking up R alone can reach 1.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst_bisector = 0, worst_r = 0;
  for (int i = 0; i < 20000; ++i) {
    const dvec3 w(u(rng), u(rng), u(rng));
    const dvec3 r = glm::normalize(dvec3(u(rng), u(rng), u(rng)));
    const dvec3 bisector = r + glm::normalize(w);
    if (glm::length(bisector) < 1e-6) continue;
    const double l = std::exp(6.0 * u(rng));
    const dvec3 sigma = w + l * r;
    worst_bisector = std::max(worst_bisector, error_cp(bisector, sigma));
    worst_r = std::max(worst_r, error_cp(r, sigma));
  }
  EXPECT_LE(worst_bisector, 0.5 + 1e-12);
  EXPECT_GT(worst_bisector, 0.4);  // the bound is approached
  EXPECT_GT(worst_r, 0.9);
}

TEST(Metrics, ErrorStatsAccumulates) {
  ErrorStats s;
  EXPECT_EQ(s.mean(), 0.0);
  EXPECT_EQ(s.percentile(0.99), 0.0);
  EXPECT_EQ(s.miss_share(), 0.0);
  for (int i = 100; i >= 1; --i) s.add(i);  // 1..100, unsorted
  for (int i = 0; i < 20; ++i) s.add_miss();
  EXPECT_EQ(s.count(), 100u);
  EXPECT_EQ(s.miss_count(), 20u);
  EXPECT_EQ(s.total(), 120u);
  EXPECT_DOUBLE_EQ(s.mean(), 50.5);
  EXPECT_DOUBLE_EQ(s.max(), 100.0);
  EXPECT_DOUBLE_EQ(s.percentile(0.99), 99.0);  // nearest rank: ceil(0.99 * 100) = 99th
  EXPECT_DOUBLE_EQ(s.percentile(0.5), 50.0);
  EXPECT_DOUBLE_EQ(s.percentile(0.0), 1.0);
  EXPECT_DOUBLE_EQ(s.percentile(1.0), 100.0);
  EXPECT_DOUBLE_EQ(s.miss_share(), 20.0 / 120.0);
  ErrorStats t;
  t.add(1000);
  t.add_miss();
  s.merge(t);
  EXPECT_DOUBLE_EQ(s.max(), 1000.0);
  EXPECT_EQ(s.total(), 122u);
}

TEST(Metrics, ExactTracerHasZeroParallaxError) {
  // Reflect a camera ray off a mirror and find the true point Sigma with the exact tracer:
  // measured against itself, Error_Parallax is 0 to rounding (the later methods' yardstick).
  SceneData s;
  s.materials.push_back(Material{});
  auto add_tri = [&](const dvec3& a, const dvec3& b, const dvec3& c) {
    const glm::vec3 n(glm::normalize(glm::cross(b - a, c - a)));
    for (const dvec3& p : {a, b, c}) s.triangles.edit().positions.emplace_back(p);
    for (int k = 0; k < 3; ++k) s.triangles.edit().normals.push_back(n);
    s.triangles.edit().object_id.push_back(static_cast<uint32_t>(s.triangles->object_id.size()));
    s.triangles.edit().material_id.push_back(0);
  };
  add_tri({-5, -1, -5}, {-5, -1, 5}, {5, -1, 5});  // floor mirror (one triangle)
  add_tri({-5, -1, -5}, {5, -1, 5}, {5, -1, -5});
  add_tri({-5, -5, -3}, {5, -5, -3}, {0, 5, -3});  // wall
  const RayTracer tracer(s);
  Hit w;
  const dvec3 dir = glm::normalize(dvec3(0.1, -0.5, -1.0));
  ASSERT_TRUE(tracer.intersect({0, 0, 0}, dir, &w));
  const Ray r = tracer.reflected_ray(w, dir);
  Hit sigma;
  ASSERT_TRUE(tracer.intersect(r.origin, r.dir, &sigma));
  EXPECT_EQ(sigma.triangle, 2u);
  EXPECT_LT(error_parallax(sigma.point, w.point, r.dir), 1e-15);
}

}  // namespace
}  // namespace abcube
