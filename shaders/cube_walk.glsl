// The texel walk of cpu_core/search/cube_walk.hpp (CubeWalk's plain walk: rules 1 to 4 of
// docs/design/cube-walk.md) on the GPU: the texels of an n x n cube map that the ray
// X(l) = W + l D crosses, in order of increasing l, each with its exact interval [l0, l1].
// Every expression is the CPU's, operation for operation in double precision
// (double_math.glsl), so that a GL whose doubles round as IEEE 754 says walks the CPU's texels
// with the CPU's intervals bit for bit. One walk an invocation: its state is global.

// A texel of a walk as cube_walks.comp writes it and cube_scan.comp reads it: (face, i, j,
// after_gap) and [l0, l1].
struct WalkTexelOut {
  ivec4 texel;
  dvec2 interval;
};

// The cube's face bases (cube_map.hpp cube_face_basis), set from the C++ definition.
uniform dvec3 face_forward[6];
uniform dvec3 face_s_axis[6];
uniform dvec3 face_t_axis[6];
// CubeWalk's CENTRE_PASS_REL.
uniform double centre_pass_rel;
// The cube's n (texels a face side), for every pass that includes the walk.
uniform int face_resolution;

dvec3 walk_w, walk_d;
int walk_n;
double walk_l_max;
uint walk_cap;
double walk_run_begin[2], walk_run_end[2];
int walk_run_count, walk_run;
double walk_gap_begin, walk_gap_end;
bool walk_gap_pending;
int walk_face, walk_next_face;
double walk_face_begin, walk_face_end;
bool walk_face_active;
double walk_axis_w[2], walk_axis_d[2], walk_forward_w, walk_forward_d;
int walk_ij[2], walk_step[2];
double walk_next_l[2];
double walk_l;
uint walk_texels, walk_iterations;
bool walk_aborted, walk_done;

// The face envelope's line k at l: F_k . X(l) = c_k + l s_k.
double envelope_c(int k) { return (k & 1) == 0 ? walk_w[k >> 1] : -walk_w[k >> 1]; }
double envelope_s(int k) { return (k & 1) == 0 ? walk_d[k >> 1] : -walk_d[k >> 1]; }
double envelope_value(int k, double l) {
  precise double v = envelope_c(k) + l * envelope_s(k);
  return v;
}

// The face of X(l): the largest line; ties to the larger slope, then the lower index.
int envelope_face(double l) {
  int best = 0;
  for (int k = 1; k < 6; ++k) {
    double vk = envelope_value(k, l), vb = envelope_value(best, l);
    if (vk > vb || (vk == vb && envelope_s(k) > envelope_s(best))) best = k;
  }
  return best;
}

// Where the envelope leaves face `cur` after l: the first line of larger slope to overtake it.
void envelope_next(int cur, double l, double end, out double face_end, out int next) {
  face_end = end;
  next = -1;
  for (int k = 0; k < 6; ++k) {
    if (!(envelope_s(k) > envelope_s(cur))) continue;
    precise double cross_at = (envelope_c(cur) - envelope_c(k)) / (envelope_s(k) - envelope_s(cur));
    double meet = std_max(l, cross_at);
    if (!(meet < end)) continue;
    if (next < 0 || meet < face_end || (meet == face_end && envelope_s(k) > envelope_s(next))) {
      face_end = meet;
      next = k;
    }
  }
}

// CubeWalk's constructor. The caller has checked n >= 1, |d| = 1 and a finite w.
void walk_begin(dvec3 w, dvec3 d, int n, double l_max, double skip_radius, uint cap) {
  walk_w = w;
  walk_d = d;
  walk_n = n;
  walk_l_max = l_max;
  walk_cap = cap;
  walk_run_count = 0;
  walk_run = -1;
  walk_gap_begin = 0.0lf;
  walk_gap_end = 0.0lf;
  walk_gap_pending = false;
  walk_face = -1;
  walk_next_face = -1;
  walk_face_begin = 0.0lf;
  walk_face_end = 0.0lf;
  walk_face_active = false;
  walk_l = 0.0lf;
  walk_texels = 0u;
  walk_iterations = 0u;
  walk_aborted = false;
  walk_done = false;
  if (!(l_max > 0.0lf)) {
    walk_done = true;
    return;
  }
  precise double pass = centre_pass_rel * length3(w);
  double r = std_max(skip_radius, pass);
  precise double lc = -dot3(w, d);
  double h = length3(cross3(w, d));
  double la = inf(), lb = inf();
  if (r > 0.0lf && h < r) {
    precise double half_chord = sqrt(r * r - h * h);
    precise double a = lc - half_chord, b = lc + half_chord;
    la = a;
    lb = b;
  }
  if (lb <= 0.0lf || la >= l_max) {
    walk_run_begin[0] = 0.0lf;
    walk_run_end[0] = l_max;
    walk_run_count = 1;
    return;
  }
  walk_gap_begin = std_max(la, 0.0lf);
  walk_gap_end = std_min(lb, l_max);
  if (la > 0.0lf) {
    walk_run_begin[walk_run_count] = 0.0lf;
    walk_run_end[walk_run_count] = la;
    ++walk_run_count;
  }
  if (lb < l_max) {
    walk_run_begin[walk_run_count] = lb;
    walk_run_end[walk_run_count] = l_max;
    ++walk_run_count;
  }
}

double walk_denominator(int axis, int boundary) {
  precise double den = double(walk_n) * walk_axis_d[axis] - (2.0lf * double(boundary) - double(walk_n)) * walk_forward_d;
  return den;
}

double walk_raw_crossing(int axis, int boundary) {
  precise double u = 2.0lf * double(boundary) - double(walk_n);
  precise double num = double(walk_n) * walk_axis_w[axis] - u * walk_forward_w;
  double den = walk_denominator(axis, boundary);
  if (!(den * double(walk_step[axis]) > 0.0lf)) return inf();
  precise double l = -num / den;
  return l;
}

void walk_next_crossing(int axis) {
  int k = walk_step[axis] > 0 ? walk_ij[axis] + 1 : walk_ij[axis];
  walk_next_l[axis] =
      (walk_step[axis] == 0 || k < 1 || k > walk_n - 1) ? inf() : std_max(walk_l, walk_raw_crossing(axis, k));
}

void walk_start_texel_on_face() {
  dvec3 forward = face_forward[walk_face];
  dvec3 axes[2] = dvec3[2](face_s_axis[walk_face], face_t_axis[walk_face]);
  precise dvec3 x = walk_face_begin == 0.0lf ? walk_w : walk_w + walk_face_begin * walk_d;
  if (x == dvec3(0.0lf)) x = walk_d;
  double ma = dot3(forward, x);
  double fw = dot3(forward, walk_w), fd = dot3(forward, walk_d);
  walk_forward_w = fw;
  walk_forward_d = fd;
  walk_l = walk_face_begin;
  for (int axis = 0; axis < 2; ++axis) {
    double sc = dot3(axes[axis], x);
    walk_axis_w[axis] = dot3(axes[axis], walk_w);
    walk_axis_d[axis] = dot3(axes[axis], walk_d);
    precise double coord = 0.5lf * (sc / ma + 1.0lf) * double(walk_n);
    walk_ij[axis] = clamp(int(floor(coord)), 0, walk_n - 1);
    precise double rate = walk_axis_d[axis] * fw - walk_axis_w[axis] * fd;
    walk_step[axis] = rate > 0.0lf ? 1 : (rate < 0.0lf ? -1 : 0);
  }
  walk_next_crossing(0);
  walk_next_crossing(1);
}

bool walk_start_face() {
  for (;;) {
    if (walk_next_face >= 0) {
      walk_face = walk_next_face;
      walk_face_begin = walk_face_end;
    } else {
      if (++walk_run >= walk_run_count) return false;
      walk_face_begin = walk_run_begin[walk_run];
      walk_face = envelope_face(walk_face_begin);
      walk_gap_pending = walk_face_begin > 0.0lf;
    }
    envelope_next(walk_face, walk_face_begin, walk_run_end[walk_run], walk_face_end, walk_next_face);
    if (walk_face_end > walk_face_begin) {
      walk_start_texel_on_face();
      return true;
    }
  }
  return false;
}

bool walk_on_face() {
  if (walk_done) return false;
  if (!walk_face_active) {
    if (!walk_start_face()) {
      walk_done = true;
      return false;
    }
    walk_face_active = true;
  }
  return true;
}

// One pass of CubeWalk::next's loop: 1 with the next texel (face, i, j), its interval (l0,
// l1) and whether it is the first after the skipped ball; 0 when this pass reported nothing
// (a texel of zero length); -1 when the walk is over (or aborted). A step, not a loop, so that
// the caller's loop is the only one a texel: llvmpipe counts an invocation's loop iterations,
// nested ones included, against one limit.
int walk_step_once(out ivec3 texel, out dvec2 interval, out bool after_gap) {
  texel = ivec3(0);
  interval = dvec2(0.0lf);
  after_gap = false;
  if (!walk_on_face()) return -1;
  if (++walk_iterations > walk_cap) {
    walk_aborted = true;
    walk_done = true;
    return -1;
  }
  double l_exit = std_min(std_min(walk_next_l[0], walk_next_l[1]), walk_face_end);
  ivec3 t = ivec3(walk_face, walk_ij[0], walk_ij[1]);
  double l0 = walk_l;
  if (l_exit >= walk_face_end) {
    walk_face_active = false;
  } else {
    bool step_s = walk_next_l[0] == l_exit, step_t = walk_next_l[1] == l_exit;
    walk_l = l_exit;
    if (step_s) walk_ij[0] += walk_step[0];
    if (step_t) walk_ij[1] += walk_step[1];
    if (step_s) walk_next_crossing(0);
    if (step_t) walk_next_crossing(1);
  }
  if (!(l_exit > l0)) return 0;
  after_gap = walk_gap_pending;
  walk_gap_pending = false;
  ++walk_texels;
  texel = t;
  interval = dvec2(l0, l_exit);
  return 1;
}
