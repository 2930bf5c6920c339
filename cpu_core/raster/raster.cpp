#include "raster/raster.hpp"

#include <algorithm>
#include <cmath>

#include "raster/cube_map.hpp"

namespace abcube {

namespace {

// Edge-on threshold: the plane passes within this share of the farthest vertex's distance.
constexpr double EDGE_ON_REL = 1e-9;

RasterView make_view(const glm::dvec3& centre, const glm::dvec3& row_x, const glm::dvec3& row_y,
                     const glm::dvec3& row_w, const glm::dmat3& to_direction, int width, int height,
                     double near_distance) {
  RasterView v;
  v.centre = centre;
  v.row_x = row_x;
  v.row_y = row_y;
  v.row_w = row_w;
  v.to_direction = to_direction;
  v.width = width;
  v.height = height;
  v.near_distance = near_distance;
  return v;
}

bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// D3D top-left rule in pixel coordinates with y down (docs/design/raster.md, "TIE RULE").
bool owns_ties(const glm::dvec3& abc) { return abc.x > 0.0 || (abc.x == 0.0 && abc.y > 0.0); }

glm::dvec3 raster_edge(const glm::dmat3& to_direction, const glm::dvec3& plane) {
  return {glm::dot(to_direction[0], plane), glm::dot(to_direction[1], plane), glm::dot(to_direction[2], plane)};
}

// Sutherland-Hodgman against one plane through the centre: keeps dot(plane, v) >= offset.
int clip_polygon(const glm::dvec3* in, int count, const glm::dvec3& plane, double offset, glm::dvec3* out) {
  int m = 0;
  for (int i = 0; i < count; ++i) {
    const glm::dvec3& a = in[i];
    const glm::dvec3& b = in[(i + 1) % count];
    const double fa = glm::dot(plane, a) - offset, fb = glm::dot(plane, b) - offset;
    if (fa >= 0.0) out[m++] = a;
    if ((fa >= 0.0) != (fb >= 0.0)) out[m++] = a + (fa / (fa - fb)) * (b - a);
  }
  return m;
}

// Pixel bounds of the near-clipped polygon, one pixel of margin, clamped to the view (the
// whole view if a projection overflows: the edge functions decide coverage anyway).
bool pixel_bounds(const RasterView& view, TriangleSetup* s) {
  double xmin = HUGE_VAL, xmax = -HUGE_VAL, ymin = HUGE_VAL, ymax = -HUGE_VAL;
  for (int k = 0; k < s->polygon_size; ++k) {
    const glm::dvec2 p = view.project(s->polygon[static_cast<size_t>(k)]);
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      xmin = ymin = -HUGE_VAL;
      xmax = ymax = HUGE_VAL;
      break;
    }
    xmin = std::min(xmin, p.x);
    xmax = std::max(xmax, p.x);
    ymin = std::min(ymin, p.y);
    ymax = std::max(ymax, p.y);
  }
  const auto clamp_to = [](double v, int hi) { return static_cast<int>(std::clamp(v, 0.0, double(hi))); };
  s->x0 = clamp_to(std::floor(xmin) - 1.0, view.width);
  s->x1 = clamp_to(std::floor(xmax) + 2.0, view.width);
  s->y0 = clamp_to(std::floor(ymin) - 1.0, view.height);
  s->y1 = clamp_to(std::floor(ymax) + 2.0, view.height);
  return s->x0 < s->x1 && s->y0 < s->y1;
}

// The pixel holding the foot of the perpendicular from the centre, when the triangle
// (in front of the near plane) contains it.
void locate_foot(const RasterView& view, TriangleSetup* s) {
  const glm::dvec3& n = s->plane_normal;
  const glm::dvec3 foot = n * (s->plane_offset / glm::dot(n, n));
  s->foot_x = s->foot_y = -1;
  for (int k = 0; k < s->edge_count; ++k) {
    if (glm::dot(s->edge_3d[static_cast<size_t>(k)], foot) < 0.0) return;
  }
  if (glm::dot(view.row_w, foot) < view.near_distance) return;
  const glm::dvec2 p = view.project(foot);
  if (!(p.x >= 0.0 && p.x < view.width && p.y >= 0.0 && p.y < view.height)) return;
  s->foot_x = static_cast<int>(p.x);
  s->foot_y = static_cast<int>(p.y);
}

// Edge functions: the three triangle edges, plus the near line when the plane cuts it.
void setup_edges(const RasterView& view, TriangleSetup* s) {
  const double orientation = s->plane_offset > 0.0 ? 1.0 : -1.0;  // sign of det(r0, r1, r2)
  for (size_t k = 0; k < 3; ++k) {
    s->edge_3d[k] = orientation * glm::cross(s->r[k], s->r[(k + 1) % 3]);
  }
  // Near line: w(P) >= near along d  <=>  dot(|h| row_w - near * sign(h) * n, d) >= 0.
  s->edge_3d[3] = std::fabs(s->plane_offset) * view.row_w - (view.near_distance * orientation) * s->plane_normal;
  for (size_t k = 0; k < 4; ++k) {
    s->edge[k] = raster_edge(view.to_direction, s->edge_3d[k]);
    s->owns_ties[k] = k == 3 || owns_ties(s->edge[k]);
  }
}

}  // namespace

RasterView cube_face_view(int face, const glm::dvec3& centre, int n, double near_distance) {
  const CubeFaceBasis& b = cube_face_basis(face);
  const double half = 0.5 * n;
  // x = N s = half (sc/ma + 1), y = N t; direction(x, y) = cube_to_direction(face, x/N, y/N).
  const glm::dmat3 to_direction(b.s_axis / half, b.t_axis / half, b.forward - b.s_axis - b.t_axis);
  return make_view(centre, half * (b.s_axis + b.forward), half * (b.t_axis + b.forward), b.forward, to_direction, n, n,
                   near_distance);
}

RasterView camera_view(const CameraFrame& f, double near_distance) {
  const double ty = f.tan_half_fov_y, tx = f.tan_half_fov_y * f.aspect;
  const double hw = 0.5 * f.width, hh = 0.5 * f.height;
  // x = hw (dot(right, r) / (w tx) + 1), y = hh (1 - dot(up, r) / (w ty)), as CameraFrame::direction.
  const glm::dmat3 to_direction(f.right * (tx / hw), f.up * (-ty / hh), f.forward - tx * f.right + ty * f.up);
  return make_view(f.eye, (hw / tx) * f.right + hw * f.forward, (-hh / ty) * f.up + hh * f.forward, f.forward,
                   to_direction, f.width, f.height, near_distance);
}

namespace {

// The corners relative to `centre` into r, their plane (normal, offset, distance) into s, and
// whether the triangle is degenerate or edge-on: setup_triangle's first part, view-free.
SetupResult shape(const glm::dvec3& centre, const TriangleSoup& soup, uint32_t index, TriangleSetup* s) {
  const size_t base = 3 * static_cast<size_t>(index);
  double farthest = 0.0;
  for (size_t k = 0; k < 3; ++k) {
    s->r[k] = glm::dvec3(soup.positions[base + k]) - centre;
    if (!finite(s->r[k])) return SetupResult::degenerate;
    farthest = std::max(farthest, glm::length(s->r[k]));
  }
  s->plane_normal = glm::cross(s->r[1] - s->r[0], s->r[2] - s->r[0]);
  const double area2 = glm::length(s->plane_normal);
  if (!(area2 > 0.0) || !std::isfinite(area2)) return SetupResult::degenerate;
  s->plane_offset = glm::dot(s->plane_normal, s->r[0]);  // = det(r0, r1, r2)
  s->plane_distance = std::fabs(s->plane_offset) / area2;
  if (!(s->plane_distance > EDGE_ON_REL * farthest)) return SetupResult::edge_on;
  return SetupResult::visible;
}

}  // namespace

SetupResult triangle_shape(const glm::dvec3& centre, const TriangleSoup& soup, uint32_t index) {
  TriangleSetup s;
  return shape(centre, soup, index, &s);
}

uint8_t cube_faces_of(const glm::dvec3& centre, const TriangleSoup& soup, uint32_t index) {
  constexpr uint8_t ALL = (1u << CUBE_FACES) - 1;
  uint8_t faces = ALL;
  for (size_t k = 0; k < 3 && faces != 0; ++k) {
    const glm::dvec3 r = glm::dvec3(soup.positions[3 * static_cast<size_t>(index) + k]) - centre;
    uint8_t in = 0;
    for (int f = 0; f < CUBE_FACES; ++f) {
      const CubeFaceBasis& b = cube_face_basis(f);
      const double ahead = glm::dot(r, b.forward);
      if (ahead >= std::fabs(glm::dot(r, b.s_axis)) && ahead >= std::fabs(glm::dot(r, b.t_axis))) {
        in = static_cast<uint8_t>(in | (1u << f));
      }
    }
    faces &= in;
  }
  return faces != 0 ? faces : ALL;
}

SetupResult setup_triangle(const RasterView& view, const TriangleSoup& soup, uint32_t index, TriangleSetup* s) {
  s->triangle = index;
  const size_t base = 3 * static_cast<size_t>(index);
  const SetupResult shaped = shape(view.centre, soup, index, s);
  if (shaped != SetupResult::visible) return shaped;
  for (size_t k = 0; k < 3; ++k) s->normal[k] = glm::dvec3(soup.normals[base + k]);

  // The part in front of the near plane (thesis: "clipping" before the raster).
  std::array<double, 3> w{};
  bool all_in = true, any_in = false;
  for (size_t k = 0; k < 3; ++k) {
    w[k] = glm::dot(view.row_w, s->r[k]);
    all_in = all_in && w[k] >= view.near_distance;
    any_in = any_in || w[k] >= view.near_distance;
  }
  if (!any_in) return SetupResult::culled;
  s->edge_count = all_in ? 3 : 4;
  s->polygon_size = clip_polygon(s->r.data(), 3, view.row_w, view.near_distance, s->polygon.data());
  if (s->polygon_size < 3) return SetupResult::culled;
  setup_edges(view, s);
  if (!pixel_bounds(view, s)) return SetupResult::culled;
  locate_foot(view, s);
  return SetupResult::visible;
}

void row_span(const TriangleSetup& s, int y, int* x_begin, int* x_end) {
  double lo = s.x0, hi = s.x1;
  const double y_top = y + sample_dy(0), y_bottom = y + sample_dy(MASK_SAMPLES - 1);
  for (int k = 0; k < s.edge_count; ++k) {
    const glm::dvec3& e = s.edge[static_cast<size_t>(k)];
    const double v_top = e.y * y_top + e.z, v_bottom = e.y * y_bottom + e.z;
    if (e.x == 0.0) {
      if (std::fmax(v_top, v_bottom) < 0.0) lo = hi;  // no sample row on the inside
      continue;
    }
    // Some sample row of the pixel row is inside for x beyond -v/a (v linear in y).
    const double b0 = -v_top / e.x, b1 = -v_bottom / e.x;
    if (e.x > 0.0) {
      const double bound = std::fmin(b0, b1);
      lo = std::fmax(lo, bound - 1e-7 * (1.0 + std::fabs(bound)));
    } else {
      const double bound = std::fmax(b0, b1);
      hi = std::fmin(hi, bound + 1e-7 * (1.0 + std::fabs(bound)));
    }
  }
  *x_begin = static_cast<int>(std::clamp(std::floor(lo), double(s.x0), double(s.x1)));
  *x_end = static_cast<int>(std::clamp(std::floor(hi) + 1.0, double(s.x0), double(s.x1)));
}

CoverageMask pixel_mask(const TriangleSetup& s, int x, int y) {
  // Trivial accept / reject from the extreme samples (E is linear), with a margin far
  // above rounding so the answer equals the per-sample test's.
  const double x_lo = x + sample_dx(0), x_hi = x + sample_dx(MASK_COLUMNS - 1);
  const double y_lo = y + sample_dy(0), y_hi = y + sample_dy(MASK_SAMPLES - 1);
  bool all_inside = true;
  for (int k = 0; k < s.edge_count; ++k) {
    const glm::dvec3& e = s.edge[static_cast<size_t>(k)];
    const double tol =
        RASTER_TRIVIAL_REL * (std::fabs(e.x) * (x_hi + 1.0) + std::fabs(e.y) * (y_hi + 1.0) + std::fabs(e.z));
    const double e_max = e.x * (e.x > 0 ? x_hi : x_lo) + e.y * (e.y > 0 ? y_hi : y_lo) + e.z;
    if (e_max < -tol) return 0;
    const double e_min = e.x * (e.x > 0 ? x_lo : x_hi) + e.y * (e.y > 0 ? y_lo : y_hi) + e.z;
    all_inside = all_inside && e_min > tol;
  }
  if (all_inside) return FULL_MASK;

  // Per sample: E = a x + (b y + c) > 0, or == 0 under the tie rule; the same operations
  // for every triangle, so the two sides of a shared edge see exactly opposite values
  // (docs/design/raster.md, "Watertight").
  CoverageMask mask = FULL_MASK;
  for (int k = 0; k < s.edge_count && mask != 0; ++k) {
    const glm::dvec3& e = s.edge[static_cast<size_t>(k)];
    double ax[MASK_COLUMNS];
    for (int col = 0; col < MASK_COLUMNS; ++col) ax[col] = e.x * (x + sample_dx(col));
    const bool ties = s.owns_ties[static_cast<size_t>(k)];
    CoverageMask inside = 0;
    for (int row = 0; row < MASK_ROWS; ++row) {
      const double base = e.y * (y + sample_dy(sample_index(0, row))) + e.z;
      unsigned bits = 0;
      if (ties) {
        for (int col = 0; col < MASK_COLUMNS; ++col) bits |= static_cast<unsigned>(ax[col] + base >= 0.0) << col;
      } else {
        for (int col = 0; col < MASK_COLUMNS; ++col) bits |= static_cast<unsigned>(ax[col] + base > 0.0) << col;
      }
      inside |= static_cast<CoverageMask>(bits) << (row * MASK_COLUMNS);
    }
    mask &= inside;
  }
  return mask;
}

glm::dvec2 mask_centroid(CoverageMask mask) {
  if (mask == 0 || mask == FULL_MASK) return {0.5, 0.5};
  // Per row (one byte of the mask): its sample count and the sum of its column indices.
  int count = 0, column_sum = 0, row_sum = 0;
  for (int row = 0; row < MASK_ROWS; ++row) {
    const unsigned bits = (mask >> (row * MASK_COLUMNS)) & 0xffu;
    const int c = __builtin_popcount(bits);
    int cols = 0;
    for (unsigned b = bits; b != 0; b &= b - 1) cols += __builtin_ctz(b);
    count += c;
    column_sum += cols;
    row_sum += c * row;
  }
  // Sample (col, row) sits at ((col + 0.5)/8, (row + 0.5)/4) (samples.hpp).
  return {(column_sum / double(count) + 0.5) / MASK_COLUMNS, (row_sum / double(count) + 0.5) / MASK_ROWS};
}

namespace {

// Squared distance from the centre (the origin) to segment ab.
double segment_distance2(const glm::dvec3& a, const glm::dvec3& b) {
  const glm::dvec3 ab = b - a;
  const double len2 = glm::dot(ab, ab);
  const double t = len2 > 0.0 ? std::clamp(-glm::dot(a, ab) / len2, 0.0, 1.0) : 0.0;
  const glm::dvec3 p = a + t * ab;
  return glm::dot(p, p);
}

// Whether the whole pixel square is inside every edge function (with the trivial margin).
bool pixel_inside(const TriangleSetup& s, int x, int y) {
  for (int k = 0; k < s.edge_count; ++k) {
    const glm::dvec3& e = s.edge[static_cast<size_t>(k)];
    const double tol = RASTER_TRIVIAL_REL * (std::fabs(e.x) * (x + 2.0) + std::fabs(e.y) * (y + 2.0) + std::fabs(e.z));
    if (!(e.x * (e.x > 0 ? x : x + 1.0) + e.y * (e.y > 0 ? y : y + 1.0) + e.z > tol)) return false;
  }
  return true;
}

// The triangle (already in front of the near plane) clipped to the frustum of pixel (x, y).
int pixel_polygon(const RasterView& view, const TriangleSetup& s, int x, int y, glm::dvec3* out) {
  if (pixel_inside(s, x, y)) {  // the pixel's corners on the plane
    const double cx[4] = {0, 1, 1, 0}, cy[4] = {0, 0, 1, 1};
    for (int i = 0; i < 4; ++i) {
      const glm::dvec3 d = view.direction(x + cx[i], y + cy[i]);
      out[i] = (s.plane_offset / glm::dot(s.plane_normal, d)) * d;
    }
    return 4;
  }
  glm::dvec3 a[8], b[8];
  int m = s.polygon_size;
  std::copy(s.polygon.begin(), s.polygon.begin() + m, a);
  // x >= px, x <= px + 1, y >= py, y <= py + 1 as planes through the centre.
  m = clip_polygon(a, m, view.row_x - double(x) * view.row_w, 0.0, b);
  m = clip_polygon(b, m, double(x + 1) * view.row_w - view.row_x, 0.0, a);
  m = clip_polygon(a, m, view.row_y - double(y) * view.row_w, 0.0, b);
  m = clip_polygon(b, m, double(y + 1) * view.row_w - view.row_y, 0.0, out);
  return m;
}

}  // namespace

FragmentGeometry fragment_geometry(const RasterView& view, const TriangleSetup& s, int x, int y, CoverageMask mask) {
  FragmentGeometry g;
  const glm::dvec2 c = mask_centroid(mask);
  const glm::dvec3 d = view.direction(x + c.x, y + c.y);

  // Perspective-correct barycentrics of the plane point along d: edge k's function is
  // proportional to the weight of the opposite vertex k+2.
  std::array<double, 3> lambda{};
  for (size_t k = 0; k < 3; ++k) lambda[(k + 2) % 3] = std::max(glm::dot(s.edge_3d[k], d), 0.0);
  glm::dvec3 n(0.0);
  for (size_t k = 0; k < 3; ++k) n += lambda[k] * s.normal[k];
  const double len = glm::length(n);
  g.normal = len > 0.0 && std::isfinite(len) ? n / len : glm::normalize(s.plane_normal);

  glm::dvec3 poly[8];
  const int m = pixel_polygon(view, s, x, y, poly);
  if (m == 0) {  // only rounding can empty it when samples are covered: use the centroid point
    const double denom = glm::dot(s.plane_normal, d);
    g.zmin = g.zmax = denom != 0.0 ? std::fabs(s.plane_offset / denom) * glm::length(d) : s.plane_distance;
    return g;
  }
  double zmax2 = 0.0, zmin2 = HUGE_VAL;  // squared
  const bool foot_inside = x == s.foot_x && y == s.foot_y;
  for (int i = 0; i < m; ++i) {
    zmax2 = std::max(zmax2, glm::dot(poly[i], poly[i]));
    if (!foot_inside) zmin2 = std::min(zmin2, segment_distance2(poly[i], poly[i + 1 < m ? i + 1 : 0]));
  }
  g.zmax = std::sqrt(zmax2);
  g.zmin = std::min(foot_inside ? s.plane_distance : std::sqrt(zmin2), g.zmax);
  return g;
}

glm::dvec3 point_on_triangle_plane(const RasterView& view, const TriangleSoup& soup, uint32_t index, double x,
                                   double y) {
  const size_t base = 3 * static_cast<size_t>(index);
  const glm::dvec3 r0 = glm::dvec3(soup.positions[base]) - view.centre;
  const glm::dvec3 n = glm::cross(glm::dvec3(soup.positions[base + 1]) - view.centre - r0,
                                  glm::dvec3(soup.positions[base + 2]) - view.centre - r0);
  const glm::dvec3 d = view.direction(x, y);
  const double denom = glm::dot(n, d);
  if (denom == 0.0) return view.centre;
  return view.centre + (glm::dot(n, r0) / denom) * d;
}

}  // namespace abcube
