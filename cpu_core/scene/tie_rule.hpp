// THE TIE RULE for coincident surfaces, defined once; every path that decides which of two
// surfaces a ray meets first calls these functions. Two surfaces met along one ray are AT
// THE SAME DISTANCE iff their separation along their normals is at most tie_bound =
// TIE_RELATIVE * M (M the largest absolute vertex coordinate of the two): the float rounding
// of the vertices, far above the double rounding of the comparisons and far below any
// modelled detail. Then the one RANKING higher wins (the object listed later, then the
// higher triangle); otherwise the nearer one. The GL passes scale each object's depth by
// gl_tie_step (below). docs/design/tie-rule.md has the bound's proof and the paths.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "scene/scene_data.hpp"

namespace abcube {

// tie_bound = TIE_RELATIVE * (largest absolute vertex coordinate of the two triangles).
constexpr double TIE_RELATIVE = 0x1p-22;

// The largest absolute coordinate of a triangle's vertices.
inline double triangle_magnitude(const TriangleSoup& soup, uint32_t triangle) {
  float m = 0.0f;
  for (int k = 0; k < 3; ++k) {
    const glm::vec3& p = soup.positions[3 * static_cast<size_t>(triangle) + static_cast<size_t>(k)];
    m = std::max(m, std::max(std::fabs(p.x), std::max(std::fabs(p.y), std::fabs(p.z))));
  }
  return m;
}

// The separation along the normals under which a and b are at the same distance.
inline double tie_bound(const TriangleSoup& soup, uint32_t a, uint32_t b) {
  return TIE_RELATIVE * std::max(triangle_magnitude(soup, a), triangle_magnitude(soup, b));
}

// Unit geometric normal of a triangle (zero for a degenerate one).
inline glm::dvec3 tie_normal(const TriangleSoup& soup, uint32_t triangle) {
  const size_t v = 3 * static_cast<size_t>(triangle);
  const glm::dvec3 a(soup.positions[v]), b(soup.positions[v + 1]), c(soup.positions[v + 2]);
  const glm::dvec3 n = glm::cross(b - a, c - a);
  const double len = glm::length(n);
  return len > 0.0 ? n / len : glm::dvec3(0.0);
}

// Whether triangle b ranks above triangle a: later object, then higher triangle index.
inline bool ranks_above(const TriangleSoup& soup, uint32_t b, uint32_t a) {
  const uint32_t ob = soup.object_id[b], oa = soup.object_id[a];
  return ob != oa ? ob > oa : b > a;
}

// A surface met along a ray: its triangle and ray parameter.
struct SurfaceAt {
  uint32_t triangle = 0;
  double t = 0;
};

// Whether a and b, met along `dir` (t in units of |dir|), are at the same distance.
inline bool same_distance(const TriangleSoup& soup, const glm::dvec3& dir, SurfaceAt a, SurfaceAt b) {
  const double gap = std::fabs(a.t - b.t);
  const double bound = tie_bound(soup, a.triangle, b.triangle);
  if (gap * glm::length(dir) <= bound) return true;  // max |n . dir| <= |dir|
  const double cos_max = std::max(std::fabs(glm::dot(tie_normal(soup, a.triangle), dir)),
                                  std::fabs(glm::dot(tie_normal(soup, b.triangle), dir)));
  return gap * cos_max <= bound;
}

// THE RULE: whether b is seen before a along `dir`: nearer beyond the bound, or at the same
// distance and ranking above. A strict order between two different triangles.
inline bool seen_before(const TriangleSoup& soup, const glm::dvec3& dir, SurfaceAt b, SurfaceAt a) {
  if (b.triangle == a.triangle) return false;
  if (same_distance(soup, dir, a, b)) return ranks_above(soup, b.triangle, a.triangle);
  return b.t < a.t;
}

// GL passes (float depth): window depth near/w is scaled by 1 + GL_TIE_STEP * (object + 1),
// so at equal depth the later object passes GL_GREATER; the steps of all objects together
// stay under GL_TIE_SPAN relative (gl_tie_step). A step of at least 2^-21 is 8 float ulps
// of the depth, above the rounding llvmpipe's interpolation leaves between two coplanar
// triangles (tests/gl/test_passes_gl.cpp measures that the later one wins every pixel).
constexpr double GL_TIE_SPAN = 0x1p-15;      // 3.1e-5: far below a 1e-4 decal seen at any angle
constexpr double GL_TIE_MIN_STEP = 0x1p-21;  // 4.8e-7
// The per-object step for a scene of `objects` objects: GL_TIE_SPAN spread over them, at
// least GL_TIE_MIN_STEP (past 64 objects the span grows with them).
inline double gl_tie_step(size_t objects) {
  return std::max(GL_TIE_MIN_STEP, GL_TIE_SPAN / static_cast<double>(std::max<size_t>(objects, 1)));
}

}  // namespace abcube
