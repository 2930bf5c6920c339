// The exact ray-triangle test: every hit the tracer (and the searches' side structure)
// accepts is decided here, in double precision, on the float vertices of a TriangleSoup.
//
// It is the watertight test of Woop, Benthin and Wald 2013 ("Watertight ray/triangle
// intersection", JCGT 2(1)), figure 10, without back-face culling: the float vertices are
// converted to double exactly, the ray is sheared so that it runs along +z, and the three
// edge functions decide. A ray through a shared edge or vertex of a closed mesh hits at
// least one of the triangles around it, never slips through (two triangles sharing an edge
// compute its edge function from the same two vertices, so the signs cannot both exclude).
//
// THE ORIGIN RULE: a hit counts only where t > 0 beyond the rounding of its computation
// (t_error_bound below). A triangle whose plane passes through the ray's origin, a camera on
// a floor or a ray started on its own surface, is never hit by that ray: exactly as the
// cube map gives such a plane no area. Without the bound, the sign of a t that is exactly 0
// is the sign of the rounding, and such a plane is hit by some rays and missed by their
// neighbours (streaks).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

#include <glm/glm.hpp>

#include "scene/scene_data.hpp"

namespace abcube {

// A ray prepared for the watertight test: the axis kz of the largest direction component,
// kx, ky the other two (swapped to keep the winding), and the shear (sx, sy, sz).
struct RayQuery {
  glm::dvec3 origin{0.0}, dir{0.0};
  int kx = 0, ky = 1, kz = 2;
  double sx = 0, sy = 0, sz = 1;
  RayQuery(const glm::dvec3& o, const glm::dvec3& d) : origin(o), dir(d) {
    // Woop et al. 2013, section 3: permute so that z is the largest direction component,
    // swap x and y when that component is negative (keeps the winding), then shear.
    const glm::dvec3 a = glm::abs(d);
    kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
    kx = (kz + 1) % 3;
    ky = (kx + 1) % 3;
    if (d[kz] < 0.0) std::swap(kx, ky);
    sx = d[kx] / d[kz];
    sy = d[ky] / d[kz];
    sz = 1.0 / d[kz];
  }
};

// One ray-triangle intersection: origin + t * dir, t > 0, lies on the triangle at
// barycentric weights (b0, b1, b2) of its vertices 0, 1, 2 (sum 1, each >= 0).
struct TriangleHit {
  double t = 0;
  uint32_t triangle = 0;  // index into the TriangleSoup
  double b0 = 0, b1 = 0, b2 = 0;
};

// gamma(n) = n u / (1 - n u), u the unit roundoff of double: the relative error of n
// rounded operations (Higham, "Accuracy and Stability of Numerical Algorithms", 3.1).
constexpr double rounding_gamma(int n) {
  constexpr double u = 0x1p-53;
  return n * u / (1.0 - n * u);
}

// A bound on the rounding of s = u az + v bz + w cz in intersect_triangle (t = s sz / det),
// from the magnitudes of the sheared coordinates x, y, z of the three vertices and of the
// edge functions e = (u, v, w), each error bounded by the error of its inputs plus its own
// operations: the vertices are exact doubles, each relative coordinate one subtraction off
// (z), the shear two operations more with |sx|, |sy| <= 1 (x, y); an edge function two
// products and a difference of them; s three products and two sums. Each gamma carries one
// operation more than it counts, for the second-order terms. The exact s is zero exactly when
// the origin lies on the triangle's plane (s is the triple product of the relative vertices,
// which the shear keeps), so |s| <= this bound is that case within rounding.
inline double s_error_bound(double x, double y, double z, double e) {
  const double dz = rounding_gamma(2) * z;
  const double dx = rounding_gamma(4) * (x + 2.0 * z), dy = rounding_gamma(4) * (y + 2.0 * z);
  const double de = 2.0 * (rounding_gamma(3) * x * y + x * dy + y * dx);
  return 3.0 * (rounding_gamma(4) * e * z + e * dz + z * de);
}

// Whether the ray meets triangle `triangle` of `soup` at 0 < t < tmax, t positive beyond its
// rounding (THE ORIGIN RULE); fills *hit if so.
inline bool intersect_triangle(const RayQuery& ray, const TriangleSoup& soup, uint32_t triangle, double tmax,
                               TriangleHit* hit) {
  const glm::vec3* p = &soup.positions[3 * static_cast<size_t>(triangle)];
  const glm::dvec3 a = glm::dvec3(p[0]) - ray.origin;
  const glm::dvec3 b = glm::dvec3(p[1]) - ray.origin;
  const glm::dvec3 c = glm::dvec3(p[2]) - ray.origin;
  const double ax = a[ray.kx] - ray.sx * a[ray.kz], ay = a[ray.ky] - ray.sy * a[ray.kz];
  const double bx = b[ray.kx] - ray.sx * b[ray.kz], by = b[ray.ky] - ray.sy * b[ray.kz];
  const double cx = c[ray.kx] - ray.sx * c[ray.kz], cy = c[ray.ky] - ray.sy * c[ray.kz];
  const double u = cx * by - cy * bx;
  const double v = ax * cy - ay * cx;
  const double w = bx * ay - by * ax;
  if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) return false;
  const double det = u + v + w;
  if (det == 0.0) return false;
  const double s = u * a[ray.kz] + v * b[ray.kz] + w * c[ray.kz];
  const double t_scaled = ray.sz * s;
  if (det > 0.0 ? (t_scaled <= 0.0 || t_scaled >= tmax * det) : (t_scaled >= 0.0 || t_scaled <= tmax * det)) {
    return false;
  }
  // THE ORIGIN RULE, on the few tests that reach here: s of the sign of det, and zero within
  // its rounding, is the origin on the plane.
  const double z = std::max({std::fabs(a[ray.kz]), std::fabs(b[ray.kz]), std::fabs(c[ray.kz])});
  const double x = std::max({std::fabs(ax), std::fabs(bx), std::fabs(cx)});
  const double y = std::max({std::fabs(ay), std::fabs(by), std::fabs(cy)});
  const double e = std::max({std::fabs(u), std::fabs(v), std::fabs(w)});
  if (std::fabs(s) <= s_error_bound(x, y, z, e)) return false;
  const double inv_det = 1.0 / det;
  hit->t = t_scaled * inv_det;
  hit->triangle = triangle;
  hit->b0 = u * inv_det;
  hit->b1 = v * inv_det;
  hit->b2 = w * inv_det;
  return true;
}

}  // namespace abcube
