// One fragment's answer for a ray (docs/design/search.md: MODE crossing, MODE thesis), the
// zero-area check, THE SIDE STRUCTURE's crossings, and the result a search returns.
#include <algorithm>
#include <cmath>

#include "base/error.hpp"
#include "scene/tie_rule.hpp"
#include "search/search_internal.hpp"
#include "search/search_scan.hpp"

namespace abcube::detail {

namespace {

// Distance from p to triangle (a, b, c) whose plane has unit normal n and offset o.
double distance_to_triangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                            const glm::dvec3& n, double o) {
  const double off_plane = glm::dot(n, p) - o;
  const glm::dvec3 q = p - off_plane * n;  // p's projection on the plane
  const glm::dvec3 v[3] = {a, b, c};
  bool inside = true;
  for (int k = 0; k < 3; ++k) {
    inside = inside && glm::dot(glm::cross(v[(k + 1) % 3] - v[k], q - v[k]), n) >= 0.0;
  }
  if (inside) return std::fabs(off_plane);
  double in_plane = INF;
  for (int k = 0; k < 3; ++k) {
    const glm::dvec3 e = v[(k + 1) % 3] - v[k];
    const double len2 = glm::dot(e, e);
    const double u = len2 > 0.0 ? std::clamp(glm::dot(q - v[k], e) / len2, 0.0, 1.0) : 0.0;
    in_plane = std::min(in_plane, glm::length(q - (v[k] + u * e)));
  }
  return std::sqrt(in_plane * in_plane + off_plane * off_plane);
}

SearchResult make_result(const SearchContext& ctx, const SearchRay& q, const Candidate& c) {
  SearchResult r;
  r.hit = true;
  r.miss = MissReason::none;
  r.triangle = c.triangle;
  r.object_id = ctx.scene().triangles->object_id[r.triangle];
  r.material_id = ctx.scene().triangles->material_id[r.triangle];
  r.back_face = c.back_face;
  r.point = ctx.cube().centre + c.x;
  r.distance = glm::length(c.x - q.w);
  r.angle = c.angle;
  r.outside_texels = c.outside;
  r.texel = c.texel;
  return r;
}

}  // namespace

// Crossing mode (docs/design/search.md): the ray meets the fragment's triangle plane at X(l');
// refined on the mesh around that triangle unless the ray crosses the triangle itself there.
Candidate crossing_candidate(const SearchContext& ctx, const SearchRay& q, const SearchOptions& o, const WalkTexel& t,
                             const Fragment& f, const SearchContext::Plane& p) {
  Candidate c;
  const uint32_t tri = f.triangle();
  const double den = glm::dot(p.normal, q.d);
  const double l = den == 0.0 ? INF : (p.offset - glm::dot(p.normal, q.w)) / den;
  // The map's evidence: the point lies in the texel holding the fragment (to rounding).
  const double slack = 1e-9 * (std::fabs(l) + glm::length(q.w));
  const bool in_texel = den != 0.0 && l >= q.self && l <= q.l_max && l >= t.l0 - slack && l <= t.l1 + slack;
  c.fragment = &f;
  c.texel = {t.face, t.i, t.j};
  if (in_texel) {
    c.x = q.w + l * q.d;
    c.l = l;
    c.angle = 0.0;
    c.outside =
        distance_to_triangle(c.x, ctx.vertex(tri, 0), ctx.vertex(tri, 1), ctx.vertex(tri, 2), p.normal, p.offset) /
        texel_size_at(c.x, ctx.cube().n);
    c.exact = c.outside <= ON_TRIANGLE_TEXELS;
    c.tested = true;
  }
  if (!c.exact && o.refine == SearchRefine::mesh) {
    const double l_ref = std::isinf(t.l1) ? t.l0 : 0.5 * (t.l0 + t.l1);
    const double radius = std::max(o.tolerance_texels, 1.0) * texel_size_at(q.w + l_ref * q.d, ctx.cube().n);
    const MeshAnswer m = refine_on_mesh(ctx, q, tri, t.l0 - radius, t.l1 + radius, radius);
    c.mesh_triangles = m.tested;
    if (m.result == Refined::hit) {
      c.x = q.w + m.l * q.d;
      c.l = m.l;
      c.angle = 0.0;
      c.outside = 0.0;
      c.exact = c.tested = c.valid = true;
      c.triangle = m.triangle;
      c.back_face = ctx.plane(m.triangle).offset > 0.0;
      return c;
    }
    if (m.result == Refined::miss) {  // the mesh says the ray passes by: not a crossing
      c.tested = in_texel;
      c.outside = INF;
      return c;
    }
  }
  if (!c.tested) {
    Candidate none;
    none.mesh_triangles = c.mesh_triangles;
    return none;
  }
  c.valid = c.outside <= o.tolerance_texels && (c.exact || l >= q.self_tolerance);
  c.triangle = tri;
  c.back_face = f.back_face();
  return c;
}

// Thesis mode (thesis 7.4.1, 9.3.4): the point a V of the texel centre on the fragment's plane.
Candidate thesis_candidate(const SearchRay& q, const WalkTexel& t, const Fragment& f, const glm::dvec3& v,
                           const SearchContext::Plane& p) {
  Candidate c;
  const double den = glm::dot(p.normal, v);
  if (den == 0.0) return c;
  const double a = p.offset / den;
  if (!(a > 0.0)) return c;
  c.x = a * v;
  const glm::dvec3 e = c.x - q.w;
  const double dist = glm::length(e);
  c.l = glm::dot(e, q.d);
  if (!(dist >= q.self) || !(c.l <= q.l_max)) return c;
  c.angle = std::atan2(glm::length(glm::cross(e, q.d)), c.l);
  c.valid = true;
  c.fragment = &f;
  c.triangle = f.triangle();
  c.back_face = f.back_face();
  c.texel = {t.face, t.i, t.j};
  return c;
}

// Does the exact ray meet a triangle the map cannot hold before parameter l_end?
bool meets_zero_area(const SearchContext& ctx, const SearchRay& q, double l_end) {
  for (const uint32_t tri : ctx.zero_area_triangles()) {
    if (!allowed(ctx, q, ctx.scene().triangles->object_id[tri])) continue;
    // Moller & Trumbore 1997.
    const glm::dvec3 a = ctx.vertex(tri, 0), e1 = ctx.vertex(tri, 1) - a, e2 = ctx.vertex(tri, 2) - a;
    const glm::dvec3 pv = glm::cross(q.d, e2);
    const double det = glm::dot(e1, pv);
    if (det == 0.0) continue;
    const glm::dvec3 tv = q.w - a;
    const double u = glm::dot(tv, pv) / det;
    const glm::dvec3 qv = glm::cross(tv, e1);
    const double v = glm::dot(q.d, qv) / det;
    const double l = glm::dot(e2, qv) / det;
    if (u >= 0 && v >= 0 && u + v <= 1 && l > q.self && l < l_end) return true;
  }
  return false;
}

bool side_crossing_counts(const SearchContext& ctx, const SearchRay& q, uint32_t tri, double l) {
  if (!(l > q.self)) return false;
  if (!allowed(ctx, q, ctx.scene().triangles->object_id[tri])) return false;
  return !own_surface(ctx.plane(tri), q);
}

bool side_back_face(const SearchContext& ctx, const SearchRay& q, uint32_t tri) {
  const bool zero_area = std::binary_search(ctx.zero_area_triangles().begin(), ctx.zero_area_triangles().end(), tri);
  const SearchContext::Plane& p = ctx.plane(tri);
  return zero_area ? glm::dot(p.normal, q.d) > 0.0 : p.offset > 0.0;
}

SideCrossing nearest_side_crossing(const SearchContext& ctx, const SearchRay& q, double l_end) {
  SideCrossing best;
  if (!q.side || !ctx.has_side_triangles()) return best;  // the common case: nothing to test
  const TriangleSoup& soup = *ctx.scene().triangles;
  ctx.for_each_side_crossing(q.w, q.d, l_end, [&](uint32_t tri, double l) {
    // The nearest; at the same distance THE TIE RULE (scene/tie_rule.hpp) picks.
    if ((best.l == INF || seen_before(soup, q.d, {tri, l}, {best.triangle, best.l})) &&
        side_crossing_counts(ctx, q, tri, l)) {
      best = {tri, l, false};
    }
    return true;
  });
  if (best.l < INF) best.back_face = side_back_face(ctx, q, best.triangle);
  return best;
}

// The answer: the chosen candidate or a miss (`miss` unless the walk was aborted); a side
// triangle crossed before it answers instead (THE SIDE STRUCTURE); without the side
// structure, a zero-area surface met before it turns it into a zero-area miss.
SearchResult finish(const SearchContext& ctx, const SearchRay& q, const Candidate* best, MissReason miss,
                    const ScanCounts& counts) {
  SearchResult r;
  if (best)
    r = make_result(ctx, q, *best);
  else
    r.miss = counts.aborted ? MissReason::aborted : miss;
  // Side crossings up to the map's answer and, for THE TIE RULE (scene/tie_rule.hpp), the
  // window past it where a side triangle may be at its distance; one there answers only if
  // the rule puts it first.
  const TriangleSoup& soup = *ctx.scene().triangles;
  double l_end = q.l_max;
  if (best) {
    const double c = std::fabs(glm::dot(ctx.plane(best->triangle).normal, q.d));
    const double bound = std::max(ctx.side_tie_bound_max(), tie_bound(soup, best->triangle, best->triangle));
    l_end = std::min(q.l_max, c > 0.0 ? best->l + bound / c : INF);
  }
  SideCrossing side = nearest_side_crossing(ctx, q, l_end);
  if (best && side.l < INF && !seen_before(soup, q.d, {side.triangle, side.l}, {best->triangle, best->l})) side = {};
  if (side.l < INF) {
    Candidate c;
    c.l = side.l;
    c.angle = 0.0;
    c.x = q.w + side.l * q.d;
    c.triangle = side.triangle;
    c.back_face = side.back_face;
    r = make_result(ctx, q, c);
    r.texel = direction_to_texel(c.x, ctx.cube().n);
    r.side = true;
  } else if (!q.side && meets_zero_area(ctx, q, best ? best->l : q.l_max)) {
    r.hit = false;
    r.miss = MissReason::zero_area_surface;
  }
  r.texels_visited = counts.texels;
  r.nodes_skipped = counts.nodes;
  r.fragments_tested = counts.fragments;
  r.candidates = counts.candidates;
  r.mesh_triangles = counts.mesh_triangles;
  return r;
}

}  // namespace abcube::detail
