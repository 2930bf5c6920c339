// Internal to the search stage: the walk of one ray over the cube A-buffer and the tests
// every fragment it meets must pass before it is a candidate (search.hpp CANDIDATES,
// SELF-HITS, BLOCK BOUNDS). A template, so each search's callbacks are inlined.
#pragma once
#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/glm.hpp>

#include "scene/tie_rule.hpp"
#include "search/search_internal.hpp"

namespace abcube::detail {

// The fragment nearest_layer() keeps for texel (x, y): a centre sample covered, the nearest
// plane along the texel-centre direction v (abuffer.hpp, the Z-buffered map's layer).
// At the same distance THE TIE RULE picks (scene/tie_rule.hpp).
inline const Fragment* nearest_fragment(const SearchContext& ctx, FragmentList list, const glm::dvec3& v) {
  const Fragment* best = nullptr;
  double best_a = INF;
  for (const Fragment& f : list) {
    if ((f.mask & CENTRE_SAMPLES) == 0) continue;
    const SearchContext::Plane& p = ctx.plane(f.triangle());
    const double den = glm::dot(p.normal, v);
    if (den == 0.0) continue;
    const double a = p.offset / den;
    if (a > 0.0 && (!best || seen_before(*ctx.scene().triangles, v, {f.triangle(), a}, {best->triangle(), best_a}))) {
      best_a = a;
      best = &f;
    }
  }
  return best;
}

// W's own surface (header, SELF-HITS): a plane passing within the self offset of W that the
// ray leaves, runs along, or crosses again within the offset. A neighbouring face near W
// that the ray really crosses further on is not.
inline bool own_surface(const SearchContext::Plane& p, const SearchRay& q) {
  const double delta = glm::dot(p.normal, q.w) - p.offset;
  if (!(std::fabs(delta) <= q.self)) return false;
  const double den = glm::dot(p.normal, q.d);
  return !(den != 0.0 && -delta / den > q.self);
}

// The squares of ray_distance_range (cube_walk.hpp) along one ray: [dmin^2, dmax^2] of
// |W + l D| over a texel's [l0, l1], with the value at the last texel's end kept
// (consecutive texels share it). Squares, because a square root per texel was a tenth
// of a render's time; a fragment's float zmin and zmax square exactly in double.
class SquaredDistanceRange {
 public:
  SquaredDistanceRange(const glm::dvec3& w, const glm::dvec3& d) : w_(w), d_(d), closest_(-glm::dot(w, d)) {}
  glm::dvec2 operator()(double l0, double l1) {
    const double lc = std::clamp(closest_, l0, l1);
    const double at_l0 = length2_at(l0);
    const double at_l1 = std::isinf(l1) ? INF : length2_at(l1);
    const glm::dvec3 xc = w_ + lc * d_;
    const double dmin = lc == l0 ? at_l0 : (lc == l1 ? at_l1 : glm::dot(xc, xc));
    return {dmin, std::isinf(l1) ? INF : std::max(at_l0, at_l1)};
  }

 private:
  double length2_at(double l) {
    if (l != cached_l_) {
      cached_l_ = l;
      const glm::dvec3 x = w_ + l * d_;
      cached_length2_ = glm::dot(x, x);
    }
    return cached_length2_;
  }
  glm::dvec3 w_, d_;
  double closest_;
  double cached_l_ = std::numeric_limits<double>::quiet_NaN(), cached_length2_ = 0;
};

// Walks the ray's texels; for each texel calls on_fragment(texel, fragment, v) for every
// fragment that passes the layer choice, the object restriction, the z-interval test
// (thesis 7.5) and the own-surface test, then after_texel(texel, index) -> keep walking?
//
// EMPTY FACES. When the rest of the walk on a face can only meet empty lists
// (SearchContext::empty_ahead), the walk goes on at the next face: nothing changes but the
// texels counted as visited. Only while may_skip() holds: the crossing and thesis windows
// count texels once they have a candidate.
template <class OnFragment, class AfterTexel, class MaySkip>
ScanCounts scan(const SearchContext& ctx, const SearchRay& q, const SearchOptions& o, OnFragment&& on_fragment,
                AfterTexel&& after_texel, MaySkip&& may_skip) {
  const CubeABuffer& cube = ctx.cube();
  const TriangleSoup& soup = *ctx.scene().triangles;
  CubeWalk walk(q.w, q.d, cube.n, q.l_max, cube.near_distance, o.max_texels);
  SquaredDistanceRange distances2(q.w, q.d);
  // Only the thesis mode and the nearest layer look at the texel-centre direction.
  const bool need_v = o.mode == SearchMode::thesis || o.layers == SearchLayers::nearest;
  ScanCounts counts;
  WalkTexel t;
  while (walk.next(&t)) {
    ++counts.texels;
    const ABuffer& b = cube.faces[static_cast<size_t>(t.face)];
    glm::dvec2 range2(0.0);  // squared distances from the centre
    bool skip = ctx.block_empty(t.face, t.i, t.j);  // BLOCK BOUNDS
    if (!skip) {
      range2 = distances2(t.l0, t.l1);
      skip = ctx.block_misses2(t.face, t.i, t.j, range2.x, range2.y);
    }
    const FragmentList list = skip ? FragmentList{} : b.list(t.i, t.j);
    if (!list.empty()) {
      const glm::dvec3 v = need_v ? b.view.direction(t.i + 0.5, t.j + 0.5) : glm::dvec3(0.0);  // texel centre
      const Fragment* only = o.layers == SearchLayers::nearest ? nearest_fragment(ctx, list, v) : nullptr;
      for (const Fragment& f : list) {
        if (o.layers == SearchLayers::nearest && &f != only) continue;
        ++counts.fragments;
        if (static_cast<double>(f.zmax) * f.zmax < range2.x || static_cast<double>(f.zmin) * f.zmin > range2.y) continue;
        if (!allowed(ctx, q, soup.object_id[f.triangle()])) continue;
        const SearchContext::Plane& p = ctx.plane(f.triangle());
        if (own_surface(p, q)) continue;
        ++counts.candidates;
        on_fragment(t, f, v);
      }
    }
    if (!after_texel(t, counts.texels - 1)) break;
    if (may_skip() && ctx.empty_ahead(t.face, t.i, t.j, walk.step(0), walk.step(1))) walk.leave_face();
  }
  counts.aborted = walk.aborted();
  return counts;
}

}  // namespace abcube::detail
