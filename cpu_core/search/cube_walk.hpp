// The texel walk: the texels of an n x n cube map (cube_map.hpp) that a ray's projection
// crosses, in order of increasing ray parameter (thesis 7.4.1, 7.5, 8.3). Every texel
// boundary is a plane through the centre C, so the ray X(l) = W + l D crosses it at one exact
// l: faces in order of the upper envelope of F_k . X(l) (rule 1), a 2D DDA on each face
// (rule 2), TIE RULES at corners and on boundaries (rule 3), THE CENTRE skipped (rule 4), and
// the SQUARE EXIT of the searches' HIERARCHICAL SKIP (rule 5). Each reported texel has the
// exact interval [l0, l1] the ray spends in its frustum; consecutive intervals meet except
// across a gap. docs/design/cube-walk.md has the whole argument, rule by rule.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <glm/glm.hpp>

#include "raster/cube_map.hpp"

namespace abcube {

// Below this closest approach, relative to |W|, a ray counts as passing through the centre.
constexpr double CENTRE_PASS_REL = 1e-9;

struct WalkTexel {
  int face = 0, i = 0, j = 0;  // cube_map.hpp: face, column (s), row (t)
  double l0 = 0, l1 = 0;       // the ray's parameter interval in the texel's frustum
  bool after_gap = false;      // first texel after a skipped ball around the centre
};

class CubeWalk {
 public:
  // w: ray origin relative to the cube centre; d: unit direction; n: face resolution;
  // l_max: end of the ray (+inf for a ray, |L - P| for a shadow segment);
  // skip_radius: ball around the centre to skip (rule 4); max_texels: 0 = 16 n + 64.
  CubeWalk(const glm::dvec3& w, const glm::dvec3& d, int n, double l_max = std::numeric_limits<double>::infinity(),
           double skip_radius = 0.0, uint32_t max_texels = 0);

  // The next texel in order of increasing l; false when the walk is over (or aborted).
  bool next(WalkTexel* texel);

  // The DDA's direction on the current face per axis (0: s / column i, 1: t / row j): +1,
  // -1 or 0; a face's texels are visited with i and j moving that way only.
  int step(int axis) const { return step_[axis]; }
  // Skips the rest of the current face segment: the next texel is on the next face (the
  // caller knows that nothing it looks for lies on the rest of this face).
  void leave_face() { face_active_ = false; }

  // HIERARCHICAL SKIP (search_scan.hpp). The pending texel: the one next() reports next
  // (face, i, j and l0 = the walk's current l; l1 as far as known), starting the next face
  // segment if need be (as next() would); false when the walk is over.
  bool pending(WalkTexel* texel);
  // Where the walk leaves the square of texels [i0, i0 + size) x [j0, j0 + size) (clipped to
  // the face) that holds the pending texel, exactly as next() would leave it: the walk's l
  // there and its next texel, or the end of the face segment inside the square. False when
  // exactness cannot be guaranteed (SQUARE EXIT, rule 5): the caller then walks on.
  struct SquareExit {
    double l_end = 0;        // the texels of the square the walk passes lie in [l, l_end]
    bool face_ends = false;  // the face segment ends inside the square (l_end = its end)
    int i = 0, j = 0;        // else: the first texel after the square, entered at l_end
  };
  bool square_exit(int i0, int j0, int size, SquareExit* exit) const;
  // square_exit's l_end when it succeeds, without the proof (a cheap test first).
  double square_end(int i0, int j0, int size) const;
  // Goes on from `exit` (of square_exit at the current pending texel): the walk's state is
  // then the one next() reaches after the square's texels.
  void jump(const SquareExit& exit);
  // Whether square_exit may be used: the cap cannot stop the plain walk (rule 3), so
  // leaving texels out cannot change where it stops.
  bool can_jump() const { return cap_ >= default_cap(n_); }

  // The texels a walk reports at most when max_texels is 0: 16 n + 64.
  static uint32_t default_cap(int n) { return 16u * static_cast<uint32_t>(n > 1 ? n : 1) + 64u; }

  bool aborted() const { return aborted_; }
  uint32_t texels() const { return texels_; }  // reported so far
  // The skipped parameter interval (gap_begin < gap_end) or an empty one.
  double gap_begin() const { return gap_begin_; }
  double gap_end() const { return gap_end_; }

 private:
  bool start_face();                              // the next face segment of the current run; false at the end
  bool on_face();                                 // a face segment started (the current or the next); false at the end
  void start_texel_on_face();                     // entry texel and first crossings of the face segment
  double crossing(int axis, int boundary) const;  // l where the ray crosses a boundary plane
  // The same, not clamped to l_ (INF: never). Inline, as denominator(): a walk asks for a few
  // of them a texel, and the hierarchy's square exits for more.
  double raw_crossing(int axis, int boundary) const {
    // Plane n (A . X) - (2k - n) (F . X) = 0 through the centre: s or t = k / n on this face.
    const double u = 2.0 * boundary - n_;
    const double num = n_ * axis_w_[axis] - u * forward_w_;
    const double den = denominator(axis, boundary);
    if (!(den * step_[axis] > 0.0)) return std::numeric_limits<double>::infinity();  // moving away (or along)
    return -num / den;
  }
  // Of raw_crossing: its sign says if the ray gets there.
  double denominator(int axis, int boundary) const { return n_ * axis_d_[axis] - (2.0 * boundary - n_) * forward_d_; }
  struct AxisRun;
  bool axis_run(int axis, int lo, int hi, AxisRun* run) const;
  int crossed_before(int axis, const AxisRun& run, double l) const;
  void next_crossing(int axis);

  glm::dvec3 w_, d_;
  int n_;
  double l_max_;
  uint32_t cap_;
  // Runs: [0, gap_begin] and [gap_end, l_max] (either may be empty).
  double run_begin_[2] = {0, 0}, run_end_[2] = {0, 0};
  int run_count_ = 0, run_ = -1;
  double gap_begin_ = 0, gap_end_ = 0;
  bool gap_pending_ = false;
  // The current face segment [face_begin_, face_end_] and the envelope's next line.
  int face_ = -1, next_face_ = -1;
  double face_begin_ = 0, face_end_ = 0;
  bool face_active_ = false;
  // The DDA on the current face. A crossing's plane is N (A . X) - u (F . X) = 0, so its
  // parameter needs only A . W, A . D (A the s or t axis) and F . W, F . D, fixed per face.
  double axis_w_[2] = {0, 0}, axis_d_[2] = {0, 0}, forward_w_ = 0, forward_d_ = 0;
  int ij_[2] = {0, 0};    // column i, row j
  int step_[2] = {0, 0};  // +1, -1 or 0 per axis
  double next_l_[2] = {0, 0};
  double l_ = 0;
  uint32_t texels_ = 0, iterations_ = 0;
  bool aborted_ = false, done_ = false;
};

// The width of one texel of an n x n map at point x (relative to the centre): 2 |x|_inf / n,
// the exact width of a texel in the plane through x perpendicular to its face's axis
// (|x|_inf = F . x). At a face centre it is 2 |x| / n (the thesis 9.3.4 texel, the largest);
// at a face corner 2 |x| / (sqrt(3) n). Tolerances and offsets in texel units use it.
// Inline: the mesh refinement asks for it once a triangle it tests.
inline double texel_size_at(const glm::dvec3& x, int n) {
  const double m = std::max({std::fabs(x.x), std::fabs(x.y), std::fabs(x.z)});
  return 2.0 * m / n;
}

// [min, max] of |W + l D| over l in [l0, l1] (D unit; l1 may be +inf).
glm::dvec2 ray_distance_range(const glm::dvec3& w, const glm::dvec3& d, double l0, double l1);

}  // namespace abcube
