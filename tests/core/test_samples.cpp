// THE SAMPLE LADDER (base/samples.hpp): each property its comment states, checked on the
// table itself.
#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "base/samples.hpp"

namespace abcube {
namespace {

struct Cell {
  int col, row;
};

Cell cell(int i) { return {SAMPLE_LADDER[i] % MASK_COLUMNS, SAMPLE_LADDER[i] / MASK_COLUMNS}; }

TEST(Samples, LadderIsEverySampleOnce) {
  std::set<int> seen(std::begin(SAMPLE_LADDER), std::end(SAMPLE_LADDER));
  EXPECT_EQ(seen.size(), static_cast<size_t>(MASK_SAMPLES));
  EXPECT_EQ(*seen.begin(), 0);
  EXPECT_EQ(*seen.rbegin(), MASK_SAMPLES - 1);
}

TEST(Samples, LadderComesInPairsSymmetricAboutTheCentre) {
  for (int i = 0; i < MASK_SAMPLES; i += 2) {
    const Cell a = cell(i), b = cell(i + 1);
    EXPECT_EQ(a.col + b.col, MASK_COLUMNS - 1) << i;
    EXPECT_EQ(a.row + b.row, MASK_ROWS - 1) << i;
  }
  for (int s = 2; s <= MASK_SAMPLES; s *= 2) {  // so each rung's mean position is the centre
    double x = 0, y = 0;
    for (int i = 0; i < s; ++i) {
      x += sample_dx(SAMPLE_LADDER[i]);
      y += sample_dy(SAMPLE_LADDER[i]);
    }
    EXPECT_DOUBLE_EQ(x / s, 0.5) << s;
    EXPECT_DOUBLE_EQ(y / s, 0.5) << s;
  }
}

// Rung 2^m: one sample in each cell of every split into 2^a columns by 2^b rows, a + b = m.
TEST(Samples, EveryRungIsStratified) {
  for (int m = 1; m <= 5; ++m) {
    const int s = 1 << m;
    int splits = 0;
    for (int a = 0; a <= 3; ++a) {
      const int b = m - a;
      if (b < 0 || b > 2) continue;
      ++splits;
      std::map<std::pair<int, int>, int> count;
      for (int i = 0; i < s; ++i) ++count[{cell(i).col >> (3 - a), cell(i).row >> (2 - b)}];
      EXPECT_EQ(count.size(), static_cast<size_t>(s)) << "rung " << s << ", " << (1 << a) << " x " << (1 << b);
      for (const auto& [where, n] : count) EXPECT_EQ(n, 1) << "rung " << s;
    }
    EXPECT_GE(splits, 1);
  }
}

// The ladder's rungs against the 32 samples on random straight edges through the pixel: each
// rung's mean squared coverage difference is under the naive choice's (the first S samples in
// raster order), and falls as the rung grows.
TEST(Samples, RungsCoverEdgesAsTheFullMaskDoes) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int lines = 20000;
  std::vector<double> ladder(6, 0.0), raster(6, 0.0);
  for (int n = 0; n < lines; ++n) {
    const double angle = u(rng) * 3.14159265358979323846, px = u(rng), py = u(rng);
    const double nx = std::cos(angle), ny = std::sin(angle), c = nx * px + ny * py;
    auto inside = [&](int k) { return sample_dx(k) * nx + sample_dy(k) * ny < c ? 1.0 : 0.0; };
    double full = 0;
    for (int k = 0; k < MASK_SAMPLES; ++k) full += inside(k);
    full /= MASK_SAMPLES;
    for (int r = 1; r < 5; ++r) {
      const int s = 1 << r;
      double a = 0, b = 0;
      for (int i = 0; i < s; ++i) {
        a += inside(SAMPLE_LADDER[i]);
        b += inside(i);
      }
      ladder[r] += (a / s - full) * (a / s - full);
      raster[r] += (b / s - full) * (b / s - full);
    }
  }
  for (int r = 1; r < 5; ++r) {
    EXPECT_LT(ladder[r], raster[r]) << (1 << r);
    if (r > 1) EXPECT_LT(ladder[r], ladder[r - 1]) << (1 << r);
  }
}

TEST(Samples, RungsAreThePowersOfTwoToThirtyTwo) {
  for (int s = 0; s <= 64; ++s) {
    EXPECT_EQ(is_sample_rung(s), s == 1 || s == 2 || s == 4 || s == 8 || s == 16 || s == 32) << s;
  }
}

}  // namespace
}  // namespace abcube
