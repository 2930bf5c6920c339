// The cube walk on the GPU (host/gl/gl_cube_walks.hpp) against CubeWalk on the CPU
// (search/cube_walk.hpp): the same texels in the same order with the same intervals, bit for
// bit, on random rays and on the rays the walk's rules are about: along seams and through
// corners, from the centre and through it, skipping a ball, ending short, capped.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/error.hpp"
#include "gl/gl_cube_walks.hpp"
#include "gl_test_support.hpp"

namespace abcube {
namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

glm::dvec3 unit(glm::dvec3 v) { return glm::normalize(v); }

// Random rays of every kind the walk meets, from `seed`.
std::vector<WalkRay> random_rays(unsigned seed, size_t count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), unit_interval(0.0, 1.0);
  const auto random_unit = [&] {
    for (;;) {
      const glm::dvec3 v(u(rng), u(rng), u(rng));
      const double len = glm::length(v);
      if (len > 1e-3 && len <= 1.0) return v / len;
    }
  };
  std::vector<WalkRay> rays;
  for (size_t k = 0; k < count; ++k) {
    WalkRay r;
    r.d = random_unit();
    switch (k % 5) {
      case 0: r.w = 3.0 * glm::dvec3(u(rng), u(rng), u(rng)); break;   // anywhere
      case 1: r.w = 0.01 * glm::dvec3(u(rng), u(rng), u(rng)); break;  // near the centre
      case 2: r.w = -2.0 * r.d + 1e-4 * random_unit(); break;          // past the centre
      case 3:
        r.w = 2.0 * random_unit();
        r.l_max = 4.0 * unit_interval(rng);
        break;  // a shadow segment
      default:
        r.w = 2.0 * random_unit();
        r.skip_radius = 0.5 * unit_interval(rng);
        break;  // a skipped ball
    }
    rays.push_back(r);
  }
  return rays;
}

// The rays the walk's tie rules are about: exact seams, corners and axes, from the centre.
std::vector<WalkRay> rule_rays() {
  std::vector<WalkRay> rays;
  const std::vector<glm::dvec3> origins{{0, 0, 0}, {1, 1, 0}, {1, 1, 1}, {-1, 0.5, 0}, {0, 0, 2}, {0.25, -0.25, 0.25}};
  const std::vector<glm::dvec3> directions{{1, 0, 0},  {0, -1, 0}, {0, 0, 1},   {1, 1, 0},  {1, 1, 1},
                                           {-1, 1, 1}, {1, -1, 0}, {0.5, 1, 0}, {0, -1, -1}};
  for (const glm::dvec3& w : origins) {
    for (const glm::dvec3& d : directions) {
      rays.push_back({w, unit(d), INF, 0.0});
      rays.push_back({w, unit(d), 1.5, 0.0});
      rays.push_back({w, unit(-d), INF, 0.25});
    }
  }
  return rays;
}

void expect_same_walks(const std::vector<WalkRay>& rays, int n, uint32_t cap, const std::string& what) {
  const GlCubeWalks gpu;
  const WalkComparison c = compare_walks(cpu_cube_walks(rays, n, cap), gpu.walk(rays, n, cap));
  EXPECT_EQ(c.identical, c.rays) << what << " n = " << n << ": " << c.example;
  EXPECT_GT(c.texels, rays.size()) << what;
}

TEST(CubeWalkGl, RandomRaysWalkTheCpusTexels) {
  test::test_context();
  for (int n : {1, 2, 7, 64, 255}) {
    for (unsigned seed : {1u, 2u}) expect_same_walks(random_rays(seed, 3000), n, 0, "seed " + std::to_string(seed));
  }
}

TEST(CubeWalkGl, SeamsCornersAndTheCentreAsTheCpu) {
  test::test_context();
  for (int n : {1, 2, 8, 64, 128}) expect_same_walks(rule_rays(), n, 0, "rule rays");
}

TEST(CubeWalkGl, CapStopsBothAlike) {
  test::test_context();
  const std::vector<WalkRay> rays = random_rays(3, 500);
  expect_same_walks(rays, 64, 5, "cap 5");
  const std::vector<RayWalk> walks = GlCubeWalks().walk(rays, 64, 5);
  size_t aborted = 0;
  for (const RayWalk& w : walks) aborted += w.aborted ? 1 : 0;
  EXPECT_GT(aborted, 0u);
  // Walks as long as a GPU walk may be (N = 10000 at the largest cap): llvmpipe's loop limit
  // is not reached, and the cap stops both alike.
  expect_same_walks(random_rays(4, 40), 10000, GPU_WALK_MAX_TEXELS, "longest walks");
}

TEST(CubeWalkGl, RefusesWhatTheCpuRefusesAndCapsAboveTheGpusBound) {
  test::test_context();
  const GlCubeWalks gpu;
  const std::vector<WalkRay> one{{glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0), INF, 0.0}};
  EXPECT_THROW(gpu.walk(one, 0), InputError);
  EXPECT_THROW(gpu.walk(one, 64, GPU_WALK_MAX_TEXELS + 1), InputError);
  EXPECT_THROW(gpu.walk({{glm::dvec3(1, 0, 0), glm::dvec3(0, 2, 0), INF, 0.0}}, 64), InputError);
  EXPECT_THROW(gpu.walk({{glm::dvec3(NAN, 0, 0), glm::dvec3(0, 1, 0), INF, 0.0}}, 64), InputError);
  EXPECT_THROW(gpu.walk({{glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0), NAN, 0.0}}, 64), InputError);
  EXPECT_THROW(gpu.walk({{glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0), INF, NAN}}, 64), InputError);
  EXPECT_TRUE(gpu.walk({}, 64).empty());
  // The largest N whose default cap a GPU walk takes, and the next.
  EXPECT_TRUE(gpu_walks_at(996));
  EXPECT_FALSE(gpu_walks_at(997));
  EXPECT_FALSE(gpu_walks_at(0));
  EXPECT_THROW(gpu.walk(one, 997), InputError);
}

// compare_walks' classes: a bound moved by one ulp is within rounding, a zero's sign is not
// the same bits, a texel missing or a cap differs.
TEST(CubeWalkGl, ComparisonSortsAndNamesTheDifferences) {
  const std::vector<RayWalk> cpu = cpu_cube_walks(rule_rays(), 16);
  ASSERT_GT(cpu.size(), 3u);
  WalkComparison c = compare_walks(cpu, cpu);
  EXPECT_EQ(c.identical, cpu.size());
  EXPECT_TRUE(c.example.empty());
  size_t k = 0;  // a ray of a few texels
  while (k < cpu.size() && cpu[k].texels.size() < 3) ++k;
  ASSERT_LT(k, cpu.size());
  std::vector<RayWalk> moved = cpu;
  moved[k].texels[1].l1 = std::nextafter(moved[k].texels[1].l1, INF);
  c = compare_walks(cpu, moved);
  EXPECT_EQ(c.identical, cpu.size() - 1);
  EXPECT_EQ(c.within_rounding, 1u);
  EXPECT_EQ(c.differing, 0u);
  EXPECT_NE(c.example.find("ray " + std::to_string(k) + " (within rounding): "), std::string::npos) << c.example;
  EXPECT_NE(c.example.find("texel 1:"), std::string::npos) << c.example;
  std::vector<RayWalk> signed_zero = cpu;
  RayWalk& from_zero = signed_zero[0];
  ASSERT_EQ(from_zero.texels[0].l0, 0.0);
  from_zero.texels[0].l0 = -0.0;
  c = compare_walks(cpu, signed_zero);
  EXPECT_EQ(c.identical, cpu.size() - 1);
  EXPECT_EQ(c.within_rounding, 1u);
  std::vector<RayWalk> shorter = cpu;
  shorter[k].texels.pop_back();
  shorter[k].aborted = true;
  c = compare_walks(cpu, shorter);
  EXPECT_EQ(c.differing, 1u);
  EXPECT_NE(c.example.find("(aborted)"), std::string::npos) << c.example;
  std::vector<RayWalk> elsewhere = cpu;
  elsewhere[k].texels[2].i += 1;
  c = compare_walks(cpu, elsewhere);
  EXPECT_EQ(c.differing, 1u);
  EXPECT_NE(c.example.find("texel 2:"), std::string::npos) << c.example;
}

}  // namespace
}  // namespace abcube
