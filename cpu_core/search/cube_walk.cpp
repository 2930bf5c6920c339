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
    : w_(w), d_(d), n_(n), l_max_(l_max), cap_(max_texels ? max_texels : default_cap(n)) {
  ABCUBE_CHECK(n >= 1, "n = " + std::to_string(n));
  ABCUBE_CHECK(std::fabs(glm::length(d) - 1.0) < 1e-6,
               "direction must be unit, |d| = " + std::to_string(glm::length(d)));
  ABCUBE_CHECK(std::isfinite(w.x) && std::isfinite(w.y) && std::isfinite(w.z), "non-finite origin");
  if (!(l_max > 0.0)) {
    done_ = true;
    return;
  }
  // The ball |X| < r around the centre, skipped (rule 4, docs/design/cube-walk.md).
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

double CubeWalk::crossing(int axis, int boundary) const { return std::max(l_, raw_crossing(axis, boundary)); }

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

bool CubeWalk::on_face() {
  if (done_) return false;
  if (!face_active_) {
    if (!start_face()) {
      done_ = true;
      return false;
    }
    face_active_ = true;
  }
  return true;
}

bool CubeWalk::next(WalkTexel* texel) {
  for (;;) {
    if (!on_face()) return false;
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

bool CubeWalk::pending(WalkTexel* texel) {
  if (!on_face()) return false;
  texel->face = face_, texel->i = ij_[0], texel->j = ij_[1];
  texel->l0 = l_;
  texel->l1 = std::min({next_l_[0], next_l_[1], face_end_});
  texel->after_gap = gap_pending_;
  return true;
}

// The boundaries one axis may cross inside a square (SQUARE EXIT, rule 5 of
// docs/design/cube-walk.md): from its head on, along its step, those of 1 .. n-1 up to the
// square's edge whose plane the ray reaches (den of the step's sign: den is monotone along
// the boundaries, so they are a prefix).
struct CubeWalk::AxisRun {
  int first = 0;        // the head: the next boundary the axis crosses
  int count = 0;        // boundaries first, first + step, ... the walk may cross in the square
  bool exits = false;   // the last of them is the square's edge: crossing it leaves the square
  double exit_l = INF;  // where it is crossed, max(l, r(last)), when it exits
};

// False when the run's crossings cannot be proven to increase along the walk (rule 5).
bool CubeWalk::axis_run(int axis, int lo, int hi, AxisRun* run) const {
  const int s = step_[axis];
  *run = AxisRun{};
  if (s == 0) return true;  // this index never changes on the face
  const int head = s > 0 ? ij_[axis] + 1 : ij_[axis];
  const int edge = s > 0 ? hi : lo;
  const bool interior_edge = edge >= 1 && edge <= n_ - 1;
  const int last = interior_edge ? edge : (s > 0 ? n_ - 1 : 1);
  const int m = s > 0 ? last - head + 1 : head - last + 1;
  run->first = head;
  const auto reached = [&](int k) { return denominator(axis, head + s * k) * step_[axis] > 0.0; };  // as raw_crossing
  if (m <= 0 || !reached(0)) return true;  // nothing left to cross on this axis
  int count = m;
  if (!reached(m - 1)) {  // the reachable prefix ends inside: its first unreached boundary
    int yes = 0, no = m - 1;
    while (no - yes > 1) {
      const int mid = yes + (no - yes) / 2;
      (reached(mid) ? yes : no) = mid;
    }
    count = no;
  }
  run->count = count;
  run->exits = interior_edge && count == m;
  if (run->exits) run->exit_l = std::max(l_, raw_crossing(axis, head + s * (count - 1)));
  if (count < 2) return true;
  // Do the computed crossings increase along the walk? The exact gap between consecutive
  // ones, 2 n |rate| / (den den'), against twice the roundings' bound on each (rule 5).
  constexpr double EPS = std::numeric_limits<double>::epsilon() / 2;  // unit roundoff
  const int b_last = head + s * (count - 1);
  const double d0 = std::fabs(denominator(axis, head)), d1 = std::fabs(denominator(axis, b_last));
  const double pn = n_ * (std::fabs(axis_w_[axis]) + std::fabs(forward_w_));  // >= |n A.W| + |u F.W|
  const double pd = n_ * (std::fabs(axis_d_[axis]) + std::fabs(forward_d_));
  const double den_min = std::min(d0, d1), den_max = std::max(d0, d1) + 4.0 * EPS * pd;
  if (!(den_min > 64.0 * EPS * pd)) return false;
  const double r_max = std::max(std::fabs(raw_crossing(axis, head)), std::fabs(raw_crossing(axis, b_last)));
  const double error = 8.0 * EPS * ((pn + r_max * pd) / den_min + r_max);
  const double ad_fw = axis_d_[axis] * forward_w_, aw_fd = axis_w_[axis] * forward_d_;
  const double rate = (ad_fw - aw_fd) * s - 4.0 * EPS * (std::fabs(ad_fw) + std::fabs(aw_fd));
  const double gap = 2.0 * n_ * rate / (den_max * den_max) * (1.0 - 8.0 * EPS);
  return rate > 0.0 && gap > 4.0 * error;
}

// How many of the run's boundaries have their crossing at or before l (a prefix: they
// increase): guessed from the point at l, then settled with the walk's own division.
int CubeWalk::crossed_before(int axis, const AxisRun& run, double l) const {
  if (run.count == 0) return 0;
  const int s = step_[axis];
  const double coord = 0.5 * ((axis_w_[axis] + l * axis_d_[axis]) / (forward_w_ + l * forward_d_) + 1.0) * n_;
  const double guess = s > 0 ? std::floor(coord) - run.first + 1 : run.first - std::ceil(coord) + 1;
  int k = std::isfinite(guess) ? static_cast<int>(std::clamp(guess, 0.0, static_cast<double>(run.count))) : 0;
  while (k < run.count && raw_crossing(axis, run.first + s * k) <= l) ++k;
  while (k > 0 && raw_crossing(axis, run.first + s * (k - 1)) > l) --k;
  return k;
}

bool CubeWalk::square_exit(int i0, int j0, int size, SquareExit* exit) const {
  if (done_ || !face_active_ || !can_jump()) return false;
  const int origin[2] = {i0, j0};
  AxisRun run[2];
  for (int axis = 0; axis < 2; ++axis) {
    if (!axis_run(axis, origin[axis], std::min(origin[axis] + size, n_), &run[axis])) return false;
  }
  const double l = std::min(run[0].exit_l, run[1].exit_l);
  if (!(l < face_end_)) {  // the face segment ends first, inside the square
    exit->face_ends = true;
    exit->l_end = face_end_;
    return true;
  }
  exit->face_ends = false;
  exit->l_end = l;
  int ij[2];
  for (int axis = 0; axis < 2; ++axis) {
    const bool leaves = run[axis].exits && run[axis].exit_l == l;  // both at once: a corner
    ij[axis] = ij_[axis] + step_[axis] * (leaves ? run[axis].count : crossed_before(axis, run[axis], l));
  }
  exit->i = ij[0], exit->j = ij[1];
  return true;
}

double CubeWalk::square_end(int i0, int j0, int size) const {
  const int origin[2] = {i0, j0};
  double l = face_end_;
  for (int axis = 0; axis < 2; ++axis) {
    const int s = step_[axis];
    const int edge = s > 0 ? std::min(origin[axis] + size, n_) : origin[axis];
    const int head = s > 0 ? ij_[axis] + 1 : ij_[axis];
    // As axis_run: the edge is crossed if it is interior and its plane and the head's are reached.
    if (s == 0 || edge < 1 || edge > n_ - 1 || !(denominator(axis, head) * step_[axis] > 0.0)) continue;
    l = std::min(l, std::max(l_, raw_crossing(axis, edge)));
  }
  return l;
}

void CubeWalk::jump(const SquareExit& exit) {
  // The square's texels of positive length take the after-gap mark, as next() would.
  if (exit.face_ends || exit.l_end > l_) gap_pending_ = false;
  if (exit.face_ends) {
    face_active_ = false;
    return;
  }
  ij_[0] = exit.i, ij_[1] = exit.j;
  l_ = exit.l_end;
  next_crossing(0);
  next_crossing(1);
}

glm::dvec2 ray_distance_range(const glm::dvec3& w, const glm::dvec3& d, double l0, double l1) {
  const double lc = std::clamp(-glm::dot(w, d), l0, l1);
  const double dmin = glm::length(w + lc * d);
  const double dmax = std::isinf(l1) ? INF : std::max(glm::length(w + l0 * d), glm::length(w + l1 * d));
  return {dmin, dmax};
}

}  // namespace abcube
