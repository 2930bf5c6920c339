// The texel walk (cube_walk.hpp) against a dense sampling of the arc, on random rays and on
// the degenerate ones: seams, cube edges and corners, texel corners, D . [[W]] = +-1, rays
// passing near the centre, a ray from the centre, finite segments.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <vector>

#include "base/constants.hpp"
#include "raster/cube_map.hpp"
#include "search/cube_walk.hpp"

namespace abcube {
namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

struct WalkCase {
  glm::dvec3 w, d;
  double l_max = INF;
  double skip = 0.0;
};

std::string describe(const WalkCase& r, int n) {
  std::ostringstream s;
  s.precision(17);
  s << "n=" << n << " W=(" << r.w.x << "," << r.w.y << "," << r.w.z << ") D=(" << r.d.x << "," << r.d.y << "," << r.d.z
    << ") l_max=" << r.l_max << " skip=" << r.skip;
  return s.str();
}

std::vector<WalkTexel> walk_all(const WalkCase& r, int n, bool* aborted = nullptr) {
  CubeWalk walk(r.w, r.d, n, r.l_max, r.skip);
  std::vector<WalkTexel> out;
  WalkTexel t;
  while (walk.next(&t)) out.push_back(t);
  if (aborted) *aborted = walk.aborted();
  return out;
}

// Does texel (face, i, j) contain direction x, allowing `slop` in face coordinates?
bool contains(const WalkTexel& t, const glm::dvec3& x, int n, double slop) {
  const CubeFaceBasis& b = cube_face_basis(t.face);
  const double ma = glm::dot(b.forward, x);
  if (!(ma > 0)) return false;
  const double s = 0.5 * (glm::dot(b.s_axis, x) / ma + 1.0), tt = 0.5 * (glm::dot(b.t_axis, x) / ma + 1.0);
  return s >= static_cast<double>(t.i) / n - slop && s <= static_cast<double>(t.i + 1) / n + slop &&
         tt >= static_cast<double>(t.j) / n - slop && tt <= static_cast<double>(t.j + 1) / n + slop;
}

// Distance, in face coordinates, from direction x to the nearest texel boundary of its face.
double boundary_distance(const glm::dvec3& x, int n) {
  const CubeCoord c = direction_to_cube(x);
  double m = INF;
  for (const double v : {c.s, c.t}) {
    const double f = v * n;
    m = std::min(m, std::fabs(f - std::round(f)) / n);
  }
  return m;
}

// The four corners of a texel on the unit-max-norm cube.
std::array<glm::dvec3, 4> corners(const WalkTexel& t, int n) {
  const double s0 = static_cast<double>(t.i) / n, s1 = static_cast<double>(t.i + 1) / n;
  const double t0 = static_cast<double>(t.j) / n, t1 = static_cast<double>(t.j + 1) / n;
  return {cube_to_direction(t.face, s0, t0), cube_to_direction(t.face, s1, t0), cube_to_direction(t.face, s0, t1),
          cube_to_direction(t.face, s1, t1)};
}

bool touching(const WalkTexel& a, const WalkTexel& b, int n) {
  for (const glm::dvec3& p : corners(a, n)) {
    for (const glm::dvec3& q : corners(b, n)) {
      if (glm::length(p - q) < 1e-12) return true;
    }
  }
  return false;
}

// Samples of the ray uniform in the angle of the arc seen from the centre: with Q the
// closest point of the line to the centre (|Q| = h), X(l) = Q + (l - l_c) D and
// tan(phi) = (l - l_c) / h, so phi uniform sweeps the arc uniformly.
std::vector<double> arc_samples(const WalkCase& r, int count) {
  const double lc = -glm::dot(r.w, r.d);
  const double h = glm::length(glm::cross(r.w, r.d));
  std::vector<double> ls;
  if (h == 0.0) return ls;
  const double phi0 = std::atan2(-lc, h);
  const double phi1 = std::isinf(r.l_max) ? 0.5 * PI : std::atan2(r.l_max - lc, h);
  for (int k = 0; k < count; ++k) {
    const double phi = phi0 + (phi1 - phi0) * (k + 0.5) / count;
    ls.push_back(lc + h * std::tan(phi));
  }
  return ls;
}

// Every structural and sampling property of one walk.
void check_walk(const WalkCase& r, int n, int samples = 4000) {
  SCOPED_TRACE(describe(r, n));
  bool aborted = true;
  const std::vector<WalkTexel> walk = walk_all(r, n, &aborted);
  ASSERT_FALSE(aborted);
  ASSERT_FALSE(walk.empty());
  const CubeWalk probe(r.w, r.d, n, r.l_max, r.skip);
  const double gap_b = probe.gap_begin(), gap_e = probe.gap_end();
  // Intervals: positive, contiguous, from 0 (or the gap's end) to l_max.
  EXPECT_EQ(walk.front().l0, walk.front().after_gap ? gap_e : 0.0);
  EXPECT_EQ(walk.back().l1, r.l_max);
  int gaps = 0;
  for (size_t k = 0; k < walk.size(); ++k) {
    EXPECT_LT(walk[k].l0, walk[k].l1) << k;
    if (k == 0) continue;
    if (walk[k].after_gap) {
      ++gaps;
      EXPECT_EQ(walk[k - 1].l1, gap_b);
      EXPECT_EQ(walk[k].l0, gap_e);
    } else {
      EXPECT_EQ(walk[k].l0, walk[k - 1].l1) << k;
      EXPECT_TRUE(touching(walk[k - 1], walk[k], n)) << "texels " << k - 1 << " and " << k << " do not touch";
    }
  }
  EXPECT_LE(gaps, 1);
  // Dense sampling: each sample's direction lies in the walk texel whose interval holds it,
  // and the texels of unambiguous samples are a subsequence of the walk, in order.
  size_t cursor = 0, walk_pos = 0;
  int bad = 0;
  for (const double l : arc_samples(r, samples)) {
    if (l < 0 || l > r.l_max || (l > gap_b && l < gap_e)) continue;
    const glm::dvec3 x = r.w + l * r.d;
    const double slop = 4e-15 * glm::length(r.w) / glm::length(x) + 1e-12;
    while (cursor + 1 < walk.size() && walk[cursor].l1 < l) ++cursor;
    if (!contains(walk[cursor], x, n, slop) && ++bad <= 5) {
      ADD_FAILURE() << "sample l=" << l << " not in walk texel " << cursor << " (face " << walk[cursor].face << ", "
                    << walk[cursor].i << ", " << walk[cursor].j << ")";
    }
    if (boundary_distance(x, n) <= slop) continue;
    const CubeTexel s = direction_to_texel(x, n);
    while (walk_pos < walk.size() &&
           !(walk[walk_pos].face == s.face && walk[walk_pos].i == s.i && walk[walk_pos].j == s.j)) {
      ++walk_pos;
    }
    if (walk_pos == walk.size() && ++bad <= 5) {
      ADD_FAILURE() << "sampled texel (" << s.face << "," << s.i << "," << s.j << ") at l=" << l
                    << " missing from the walk or out of order";
      walk_pos = 0;
    }
  }
  // An unbounded ray ends in the texel of D.
  if (std::isinf(r.l_max)) {
    EXPECT_TRUE(contains(walk.back(), r.d, n, 1e-12));
  }
}

glm::dvec3 random_unit(std::mt19937& rng) {
  std::normal_distribution<double> g;
  for (;;) {
    const glm::dvec3 v(g(rng), g(rng), g(rng));
    if (glm::length(v) > 1e-3) return glm::normalize(v);
  }
}

TEST(CubeWalk, RandomRaysMatchDenseSampling) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-3, 3);
  for (const int n : {1, 2, 3, 7, 16, 64, 128}) {
    for (int k = 0; k < 60; ++k) {
      WalkCase r{glm::dvec3(u(rng), u(rng), u(rng)), random_unit(rng)};
      if (k % 3 == 1) r.l_max = std::fabs(u(rng)) + 0.1;  // a shadow segment
      check_walk(r, n);
    }
  }
}

TEST(CubeWalk, CostIsLinearInN) {
  // A walk crosses at most about 2n texels per face and never repeats a face.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-3, 3);
  for (const int n : {8, 64, 512}) {
    size_t most = 0;
    for (int k = 0; k < 200; ++k)
      most = std::max(most, walk_all({glm::dvec3(u(rng), u(rng), u(rng)), random_unit(rng)}, n).size());
    EXPECT_LE(most, static_cast<size_t>(8 * n + 8)) << n;
    EXPECT_GE(most, static_cast<size_t>(n)) << n;  // some arc of 200 crosses a whole face
  }
}

TEST(CubeWalk, RaysAlongSeamsEdgesAndCorners) {
  for (const int n : {4, 16, 33}) {
    // The whole ray in the plane x = z (the seam of +X and +Z) and in x = -y.
    check_walk({glm::dvec3(2, 0.3, 2), glm::normalize(glm::dvec3(0.2, 1, 0.2))}, n);
    check_walk({glm::dvec3(2, -2, 0.5), glm::normalize(glm::dvec3(-1, 1, -0.3))}, n);
    check_walk({glm::dvec3(-1.5, 0.7, 1.5), glm::normalize(glm::dvec3(1, 0.1, -1))}, n);
    // Arcs through a cube corner (1,1,1) and (-1,1,-1): X(2) is exactly that direction.
    check_walk({glm::dvec3(3, 3, 1), glm::dvec3(0, 0, 1)}, n);
    check_walk({glm::dvec3(-3, 1, -3), glm::dvec3(0, 1, 0)}, n);
    check_walk(
        {glm::dvec3(3, 3, 3) - 2.0 * glm::normalize(glm::dvec3(0.6, 0.8, 0)), glm::normalize(glm::dvec3(0.6, 0.8, 0))},
        n);
    // Starting exactly on a seam, on a corner, and heading into another face.
    check_walk({glm::dvec3(1, 1, 0.2), glm::normalize(glm::dvec3(-1, 0.5, 0.3))}, n);
    check_walk({glm::dvec3(1, 1, 1), glm::normalize(glm::dvec3(0.3, -1, 0.2))}, n);
    // Along a texel boundary (s = 1/4 on +Z), and the face's centre lines.
    check_walk({glm::dvec3(-0.5, 0.3, 1), glm::normalize(glm::dvec3(0, -1, 0.5))}, n);
    check_walk({glm::dvec3(0, 0.3, 1), glm::dvec3(0, -1, 0)}, n);
  }
}

TEST(CubeWalk, DiagonalThroughTexelCornersStepsBothIndices) {
  // On +Z (s = (x/z+1)/2, t = (-y/z+1)/2) the ray y = -x, z = 1 has s = t: it goes through
  // every texel corner (k/n, k/n) exactly; the crossings tie and the walk steps diagonally.
  const int n = 8;
  const glm::dvec3 d = glm::normalize(glm::dvec3(1, -1, 0));
  const WalkCase r{glm::dvec3(-0.875, 0.875, 1), d, 1.75 * std::sqrt(2.0)};
  check_walk(r, n);
  const std::vector<WalkTexel> walk = walk_all(r, n);
  ASSERT_EQ(walk.size(), 8u);  // texels (k, k), k = 0..7: s = t runs from 1/16 to 15/16
  for (size_t k = 0; k < walk.size(); ++k) {
    EXPECT_EQ(walk[k].face, POS_Z);
    EXPECT_EQ(walk[k].i, static_cast<int>(k));
    EXPECT_EQ(walk[k].j, static_cast<int>(k));
  }
}

TEST(CubeWalk, DirectionAlongW_IsOneTexel) {
  // R . [[W]] = +1: the arc is one texel, for any l.
  for (const int n : {4, 64, 1024}) {
    const glm::dvec3 w(1.3, -0.4, 2.2);
    const std::vector<WalkTexel> walk = walk_all({w, glm::normalize(w)}, n);
    ASSERT_EQ(walk.size(), 1u);
    const CubeTexel e = direction_to_texel(w, n);
    EXPECT_EQ(walk[0].face, e.face);
    EXPECT_EQ(walk[0].i, e.i);
    EXPECT_EQ(walk[0].j, e.j);
    EXPECT_EQ(walk[0].l0, 0.0);
    EXPECT_EQ(walk[0].l1, INF);
  }
}

TEST(CubeWalk, RayThroughTheCentreJumpsToTheAntipode) {
  // R . [[W]] = -1: the direction is [[W]] until the ray reaches the centre, then R.
  for (const int n : {4, 64, 1024}) {
    const glm::dvec3 w(1.3, -0.4, 2.2);
    const glm::dvec3 d = -glm::normalize(w);
    const std::vector<WalkTexel> walk = walk_all({w, d}, n);
    ASSERT_EQ(walk.size(), 2u);
    const CubeTexel a = direction_to_texel(w, n), b = direction_to_texel(d, n);
    EXPECT_EQ(walk[0].face, a.face);
    EXPECT_EQ(walk[0].i, a.i);
    EXPECT_EQ(walk[0].j, a.j);
    EXPECT_EQ(walk[1].face, b.face);
    EXPECT_EQ(walk[1].i, b.i);
    EXPECT_EQ(walk[1].j, b.j);
    EXPECT_TRUE(walk[1].after_gap);
    const double lc = glm::length(w), r = CENTRE_PASS_REL * lc;
    EXPECT_NEAR(walk[0].l1, lc - r, 1e-15 * lc);
    EXPECT_NEAR(walk[1].l0, lc + r, 1e-15 * lc);
  }
}

TEST(CubeWalk, RaysNearTheCentre) {
  // Closest approach h relative to |W|: resolved down to the CENTRE_PASS_REL floor, below
  // it the ray counts as through the centre (a gap of 2 * 1e-9 |W| around l_c).
  std::mt19937 rng(3);
  for (const double h : {1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 0.0}) {
    for (int k = 0; k < 6; ++k) {
      const glm::dvec3 d = random_unit(rng);
      glm::dvec3 side = glm::normalize(glm::cross(d, random_unit(rng)));
      const glm::dvec3 w = -2.5 * d + h * 2.5 * side;
      for (const int n : {5, 64}) {
        check_walk({w, d}, n, 20000);
        const CubeWalk probe(w, d, n);
        EXPECT_EQ(probe.gap_end() > probe.gap_begin(), h < CENTRE_PASS_REL) << h;
      }
    }
  }
}

TEST(CubeWalk, SkipRadiusLeavesOutTheBall) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  int gaps = 0;
  for (int k = 0; k < 100; ++k) {
    const glm::dvec3 d = random_unit(rng);
    const WalkCase r{-1.5 * d + glm::dvec3(u(rng), u(rng), u(rng)), d, INF, 0.1};
    check_walk(r, 32);
    for (const WalkTexel& t : walk_all(r, 32)) {
      // No texel interval enters the ball |X| < 0.1 (beyond rounding).
      EXPECT_GE(ray_distance_range(r.w, r.d, t.l0, t.l1).x, 0.1 * (1 - 1e-12));
      gaps += t.after_gap;
    }
  }
  EXPECT_GT(gaps, 10);
}

TEST(CubeWalk, StartAtTheCentreAndEmptySegment) {
  const glm::dvec3 d = glm::normalize(glm::dvec3(0.2, -1, 0.4));
  const std::vector<WalkTexel> walk = walk_all({glm::dvec3(0.0), d}, 16);
  ASSERT_EQ(walk.size(), 1u);
  const CubeTexel e = direction_to_texel(d, 16);
  EXPECT_EQ(walk[0].face, e.face);
  EXPECT_EQ(walk[0].i, e.i);
  EXPECT_EQ(walk[0].j, e.j);
  EXPECT_TRUE(walk_all({glm::dvec3(1, 2, 3), d, 0.0}, 16).empty());
}

TEST(CubeWalk, CapAbortsAndSaysSo) {
  CubeWalk walk(glm::dvec3(2, -1, 3), glm::normalize(glm::dvec3(-1, 0.5, -0.2)), 256, INF, 0.0, 10);
  WalkTexel t;
  int count = 0;
  while (walk.next(&t)) ++count;
  EXPECT_TRUE(walk.aborted());
  EXPECT_LE(count, 10);
}

TEST(CubeWalk, TexelSizeAndDistanceRange) {
  EXPECT_DOUBLE_EQ(texel_size_at(glm::dvec3(0, 0, 5), 100), 0.1);
  EXPECT_DOUBLE_EQ(texel_size_at(glm::dvec3(1, -3, 2), 10), 0.6);
  const glm::dvec3 w(0, 1, -2), d(0, 0, 1);
  const glm::dvec2 r = ray_distance_range(w, d, 0.0, 4.0);
  EXPECT_DOUBLE_EQ(r.x, 1.0);
  EXPECT_DOUBLE_EQ(r.y, std::sqrt(5.0));
  EXPECT_EQ(ray_distance_range(w, d, 3.0, INF).y, INF);
  EXPECT_DOUBLE_EQ(ray_distance_range(w, d, 3.0, INF).x, std::sqrt(2.0));
}

}  // namespace
}  // namespace abcube
