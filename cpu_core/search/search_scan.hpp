// Internal to the search stage: the walk of one ray over the cube A-buffer and the tests every
// fragment it meets must pass before it is a candidate (docs/design/search.md: CANDIDATES,
// SELF-HITS; search.hpp BLOCK BOUNDS). A template, so each search's callbacks are inlined.
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

// W's own surface (SELF-HITS, docs/design/search.md): a plane passing within the self offset of
// W that the ray leaves, runs along, or crosses again within the offset. A neighbouring face
// near W that the ray really crosses further on is not.
inline bool own_surface(const SearchContext::Plane& p, const SearchRay& q) {
  const double delta = glm::dot(p.normal, q.w) - p.offset;
  if (!(std::fabs(delta) <= q.self)) return false;
  const double den = glm::dot(p.normal, q.d);
  return !(den != 0.0 && -delta / den > q.self);
}

// The squares of ray_distance_range (cube_walk.hpp) along one ray: [dmin^2, dmax^2] of
// |W + l D| over a texel's [l0, l1], with the value at the last texel's end kept
// (consecutive texels share it). Squares, because a square root per texel would be a
// noticeable share of a render's time; a fragment's float zmin and zmax square exactly in
// double.
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
  // |X(l)|^2 as operator() computes it.
  double at(double l) { return length2_at(l); }
  // HIERARCHICAL SKIP: [lo, hi] holding every value operator() gives over sub-intervals of
  // [l0, l1] (l0 >= 0), whatever the roundings. Each is |X(l)|^2 computed at some l in
  // [l0, l1], within 8 eps S(l)^2 of the exact value (S(l) = |W|_1 + l |D|_1): above by
  // convexity, max at an end plus that; below, the exact minimum over [l0, l1] (which the
  // clamped closest point misses by at most 2e-6 |W|, D being unit to 1e-6: 5e-12 |W|^2)
  // less the same; where l > 3 |W| the error is under 96 eps of the value itself. The
  // widening below is each of those terms at least twentyfold.
  glm::dvec2 widened(double l0, double l1) {
    const glm::dvec2 r = (*this)(l0, l1);
    const double wn = std::fabs(w_.x) + std::fabs(w_.y) + std::fabs(w_.z);
    const double lc = std::clamp(closest_, l0, l1);
    const double near = (wn + lc) * (wn + lc), far = (wn + l1) * (wn + l1);
    const double lo = r.x * (1.0 - 1e-12) - 1e-12 * near - 1e-10 * wn * wn;
    return {lo, std::isinf(l1) ? INF : r.y * (1.0 + 1e-12) + 1e-12 * far};
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

// HIERARCHICAL SKIP (maximum mipmaps, Tevs et al. 2008; hierarchical-Z tracing, McGuire &
// Mara 2014, on the thesis's arc walk). Before the pending texel is visited, the nodes of
// THE Z PYRAMID (search.hpp) holding it are tried, from one level above the last success
// down to the block: a node is stepped over, the walk jumping to where it leaves the node's
// square (CubeWalk::square_exit, exact), when it is empty or when the ray's squared distance
// range over that stretch, widened against every rounding (SquaredDistanceRange::widened),
// misses [zmin^2, zmax^2] of the node. Every texel of the square would then have had its
// block passed by the BLOCK BOUNDS test (its block's bounds lie in the node's, its range in
// the widened one), so no fragment is read or counted either way: the answers, fragments
// tested and candidates are the plain walk's bit for bit; only the texels visited fall (and
// the nodes stepped over are counted). A node whose range holds |X(l0)| is not tried (it
// cannot pass), nor one whose exit the walk cannot prove; the walk then descends or visits
// the texel.
inline bool skip_node(const SearchContext& ctx, CubeWalk& walk, const WalkTexel& t, SquaredDistanceRange& distances2,
                      int* level) {
  const double at_l0 = distances2.at(t.l0);
  for (int k = std::min(*level + 1, ctx.pyramid_levels() - 1); k >= 0; --k) {
    const glm::vec2 z = ctx.node_bounds(t.face, k, t.i, t.j);
    const bool empty = z.x > z.y;
    const double zmin2 = static_cast<double>(z.x) * z.x, zmax2 = static_cast<double>(z.y) * z.y;
    if (!empty && zmin2 <= at_l0 && at_l0 <= zmax2) continue;
    const int size = SearchContext::BOUNDS_BLOCK << k;
    const int i0 = t.i / size * size, j0 = t.j / size * size;
    if (!empty) {  // the range up to square_exit's l_end, before its proof
      const glm::dvec2 range2 = distances2.widened(t.l0, walk.square_end(i0, j0, size));
      if (!(zmax2 < range2.x || zmin2 > range2.y)) continue;
    }
    CubeWalk::SquareExit exit;
    if (!walk.square_exit(i0, j0, size, &exit)) continue;
    walk.jump(exit);
    *level = k;
    return true;
  }
  *level = -1;
  return false;
}

// Walks the ray's texels; for each texel calls on_fragment(texel, fragment, v, plane) (the
// fragment's triangle's SearchContext::plane) for every
// fragment that passes the layer choice, the object restriction, the z-interval test
// (thesis 7.5) and the own-surface test, then after_texel(texel, index) -> keep walking?
//
// EMPTY FACES. When the rest of the walk on a face can only meet empty lists
// (SearchContext::empty_ahead), the walk goes on at the next face: nothing changes but the
// texels counted as visited. Only while may_skip() holds: the crossing and thesis windows
// count texels once they have a candidate. So does the HIERARCHICAL SKIP above (while
// may_skip() holds after_texel keeps walking on a texel without candidates).
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
  const bool hierarchy = o.hierarchy && walk.can_jump();
  int level = ctx.pyramid_levels() - 1;  // HIERARCHICAL SKIP: the last level stepped over
  WalkTexel t;
  for (;;) {
    if (hierarchy && may_skip()) {
      if (!walk.pending(&t)) break;
      if (skip_node(ctx, walk, t, distances2, &level)) {
        ++counts.nodes;
        continue;
      }
    }
    if (!walk.next(&t)) break;
    ++counts.texels;
    const ABuffer& b = cube.faces[static_cast<size_t>(t.face)];
    glm::dvec2 range2(0.0);                         // squared distances from the centre
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
        // ORDER (abuffer.hpp): the list runs by zmin, so past the range's far end every
        // fragment left starts further still and would fail this test too.
        if (static_cast<double>(f.zmin) * f.zmin > range2.y) break;
        if (static_cast<double>(f.zmax) * f.zmax < range2.x) continue;
        if (!allowed(ctx, q, soup.object_id[f.triangle()])) continue;
        const SearchContext::Plane& p = ctx.plane(f.triangle());
        if (own_surface(p, q)) continue;
        ++counts.candidates;
        on_fragment(t, f, v, p);
      }
    }
    if (!after_texel(t, counts.texels - 1)) break;
    if (may_skip() && ctx.empty_ahead(t.face, t.i, t.j, walk.step(0), walk.step(1))) walk.leave_face();
  }
  counts.aborted = walk.aborted();
  return counts;
}

}  // namespace abcube::detail
