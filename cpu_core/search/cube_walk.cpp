#include "search/cube_walk.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "base/error.hpp"

namespace abcube {

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

// The six lines F_k . X(l) = c_k + l s_k of the face envelope (F_k = +-axis, cube_map.hpp order).
struct FaceLines {
  double c[CUBE_FACES], s[CUBE_FACES];
  FaceLines(const glm::dvec3& w, const glm::dvec3& d) {
    for (int a = 0; a < 3; ++a) {
      c[2 * a] = w[a], c[2 * a + 1] = -w[a];
      s[2 * a] = d[a], s[2 * a + 1] = -d[a];
    }
  }
  double value(int k, double l) const { return c[k] + l * s[k]; }
};

// The face of X(l): the largest line; ties go to the larger slope (the face the ray is
// entering), then to the lower index (cube_map.hpp's x-before-y-before-z rule).
int envelope_face(const FaceLines& f, double l) {
  int best = 0;
  for (int k = 1; k < CUBE_FACES; ++k) {
    const double vk = f.value(k, l), vb = f.value(best, l);
    if (vk > vb || (vk == vb && f.s[k] > f.s[best])) best = k;
  }
  return best;
}

// Where the envelope leaves face `cur` after l: the first line of larger slope to overtake
// it (ties: the larger slope), or none before `end`. The envelope is convex, so only lines
// of larger slope can take over and each face comes at most once.
void envelope_next(const FaceLines& f, int cur, double l, double end, double* face_end, int* next) {
  *face_end = end;
  *next = -1;
  for (int k = 0; k < CUBE_FACES; ++k) {
    if (!(f.s[k] > f.s[cur])) continue;
    const double meet = std::max(l, (f.c[cur] - f.c[k]) / (f.s[k] - f.s[cur]));
    if (!(meet < end)) continue;
    if (*next < 0 || meet < *face_end || (meet == *face_end && f.s[k] > f.s[*next])) {
      *face_end = meet;
      *next = k;
    }
  }
}

}  // namespace

CubeWalk::CubeWalk(const glm::dvec3& w, const glm::dvec3& d, int n, double l_max, double skip_radius,
                   uint32_t max_texels)
    : w_(w), d_(d), n_(n), l_max_(l_max),
      cap_(max_texels ? max_texels : 16u * static_cast<uint32_t>(std::max(n, 1)) + 64u) {
  ABCUBE_CHECK(n >= 1, "n = " + std::to_string(n));
  ABCUBE_CHECK(std::fabs(glm::length(d) - 1.0) < 1e-6,
               "direction must be unit, |d| = " + std::to_string(glm::length(d)));
  ABCUBE_CHECK(std::isfinite(w.x) && std::isfinite(w.y) && std::isfinite(w.z), "non-finite origin");
  if (!(l_max > 0.0)) {
    done_ = true;
    return;
  }
  // The ball |X| < r around the centre, skipped (header, rule 4).
  const double r = std::max(skip_radius, CENTRE_PASS_REL * glm::length(w));
  const double lc = -glm::dot(w, d);
  const double h = glm::length(glm::cross(w, d));
  double la = INF, lb = INF;
  if (r > 0.0 && h < r) {
    const double half = std::sqrt(r * r - h * h);
    la = lc - half;
    lb = lc + half;
  }
  if (lb <= 0.0 || la >= l_max) {  // no ball, or behind the origin, or beyond the end
    run_begin_[0] = 0.0, run_end_[0] = l_max;
    run_count_ = 1;
    return;
  }
  gap_begin_ = std::max(la, 0.0);
  gap_end_ = std::min(lb, l_max);
  if (la > 0.0) {
    run_begin_[run_count_] = 0.0, run_end_[run_count_] = la;
    ++run_count_;
  }
  if (lb < l_max) {
    run_begin_[run_count_] = lb, run_end_[run_count_] = l_max;
    ++run_count_;
  }
}

double CubeWalk::crossing(int axis, int boundary) const {
  // Plane n (A . X) - (2k - n) (F . X) = 0 through the centre: s or t = k / n on this face.
  const double u = 2.0 * boundary - n_;
  const double num = n_ * axis_w_[axis] - u * forward_w_;
  const double den = n_ * axis_d_[axis] - u * forward_d_;
  if (!(den * step_[axis] > 0.0)) return INF;  // moving away from (or along) this plane
  return std::max(l_, -num / den);
}

void CubeWalk::next_crossing(int axis) {
  const int k = step_[axis] > 0 ? ij_[axis] + 1 : ij_[axis];
  next_l_[axis] = (step_[axis] == 0 || k < 1 || k > n_ - 1) ? INF : crossing(axis, k);
}

void CubeWalk::start_texel_on_face() {
  const CubeFaceBasis& b = cube_face_basis(face_);
  glm::dvec3 x = face_begin_ == 0.0 ? w_ : w_ + face_begin_ * d_;
  if (x == glm::dvec3(0.0)) x = d_;  // the ray starts at the centre: its direction is d
  const double ma = glm::dot(b.forward, x);
  const double sc[2] = {glm::dot(b.s_axis, x), glm::dot(b.t_axis, x)};
  const double fw = glm::dot(b.forward, w_), fd = glm::dot(b.forward, d_);
  const glm::dvec3* axes[2] = {&b.s_axis, &b.t_axis};
  forward_w_ = fw;
  forward_d_ = fd;
  l_ = face_begin_;
  for (int axis = 0; axis < 2; ++axis) {
    axis_w_[axis] = glm::dot(*axes[axis], w_);
    axis_d_[axis] = glm::dot(*axes[axis], d_);
    const double coord = 0.5 * (sc[axis] / ma + 1.0) * n_;
    ij_[axis] = std::clamp(static_cast<int>(std::floor(coord)), 0, n_ - 1);
    // d(sc/ma)/dl has the constant sign of (A . D)(F . W) - (A . W)(F . D) on the face.
    const double rate = axis_d_[axis] * fw - axis_w_[axis] * fd;
    step_[axis] = rate > 0.0 ? 1 : (rate < 0.0 ? -1 : 0);
  }
  next_crossing(0);
  next_crossing(1);
}

bool CubeWalk::start_face() {
  const FaceLines lines(w_, d_);
  for (;;) {
    if (next_face_ >= 0) {  // the envelope goes on within this run
      face_ = next_face_;
      face_begin_ = face_end_;
    } else {
      if (++run_ >= run_count_) return false;
      face_begin_ = run_begin_[run_];
      face_ = envelope_face(lines, face_begin_);
      gap_pending_ = face_begin_ > 0.0;
    }
    envelope_next(lines, face_, face_begin_, run_end_[run_], &face_end_, &next_face_);
    if (face_end_ > face_begin_) {
      start_texel_on_face();
      return true;
    }
  }
}

bool CubeWalk::next(WalkTexel* texel) {
  for (;;) {
    if (done_) return false;
    if (!face_active_) {
      if (!start_face()) {
        done_ = true;
        return false;
      }
      face_active_ = true;
    }
    if (++iterations_ > cap_) {
      aborted_ = done_ = true;
      return false;
    }
    const double l_exit = std::min({next_l_[0], next_l_[1], face_end_});
    WalkTexel t;
    t.face = face_, t.i = ij_[0], t.j = ij_[1], t.l0 = l_, t.l1 = l_exit;
    if (l_exit >= face_end_) {
      face_active_ = false;  // the face is left by the envelope, not by a texel boundary
    } else {
      const bool step_s = next_l_[0] == l_exit, step_t = next_l_[1] == l_exit;  // both: a corner
      l_ = l_exit;
      if (step_s) ij_[0] += step_[0];
      if (step_t) ij_[1] += step_[1];
      if (step_s) next_crossing(0);
      if (step_t) next_crossing(1);
    }
    if (t.l1 > t.l0) {
      t.after_gap = gap_pending_;
      gap_pending_ = false;
      ++texels_;
      *texel = t;
      return true;
    }
  }
}

double texel_size_at(const glm::dvec3& x, int n) {
  const double m = std::max({std::fabs(x.x), std::fabs(x.y), std::fabs(x.z)});
  return 2.0 * m / n;
}

glm::dvec2 ray_distance_range(const glm::dvec3& w, const glm::dvec3& d, double l0, double l1) {
  const double lc = std::clamp(-glm::dot(w, d), l0, l1);
  const double dmin = glm::length(w + lc * d);
  const double dmax = std::isinf(l1) ? INF : std::max(glm::length(w + l0 * d), glm::length(w + l1 * d));
  return {dmin, dmax};
}

}  // namespace abcube
