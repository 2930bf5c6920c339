// The three searches (search.hpp): reflection, refraction exit and shadow, each a walk of
// the map (search_scan.hpp) with its own rule for which candidate answers.
#include <algorithm>
#include <vector>

#include "base/error.hpp"
#include "reference/triangle_test.hpp"
#include "search/search_scan.hpp"
#include "material/shading.hpp"

namespace abcube {

namespace {

// The ray of a search from W (world space) along unit `dir`, with the self offsets of `o`.
SearchRay make_query(const SearchContext& ctx, const glm::dvec3& w_world, const glm::dvec3& dir,
                     const SearchOptions& o) {
  ABCUBE_CHECK(std::fabs(glm::length(dir) - 1.0) < 1e-6, "search direction must be unit");
  SearchRay q;
  q.w = w_world - ctx.cube().centre;
  q.d = dir;
  const double texel = texel_size_at(q.w, ctx.cube().n);
  q.self = self_offset_texels(o) * texel;
  q.self_tolerance = 2.0 * o.tolerance_texels * texel;
  q.side = o.side_structure;
  return q;
}

using namespace detail;

// Crossing mode's choice among a ray's candidates, in the walk's order (docs/design/search.md):
// an exact crossing before a near one, the first crossing of each, THE TIE RULE
// (scene/tie_rule.hpp) at the same distance; the walk goes CROSSING_WINDOW_TEXELS texels past
// the first texel with an accepted candidate, and on while a texel ends before the best. The
// search's walk and search_from_candidates both feed it.
class CrossingChoice {
 public:
  CrossingChoice(const SearchContext& ctx, const SearchRay& q, const SearchOptions& o) : ctx_(ctx), q_(q), o_(o) {}
  void take(const Candidate& c) {
    mesh_triangles_ += c.mesh_triangles;
    if (!c.valid) {
      rejected_ = rejected_ || (c.tested && c.outside > o_.tolerance_texels);
      return;
    }
    Candidate& best = c.exact ? exact_ : near_;
    if (!best.fragment || seen_before(*ctx_.scene().triangles, q_.d, {c.triangle, c.l}, {best.triangle, best.l}))
      best = c;
  }
  // After the walk's texel `index`, which ends at l1: keep walking?
  bool after_texel(double l1, uint32_t index) {
    const double best_l = std::min(exact_.l, near_.l);
    if (best_l == INF) return true;
    if (first_ < 0) first_ = index;
    return index < first_ + CROSSING_WINDOW_TEXELS || l1 <= best_l;
  }
  bool found() const { return first_ >= 0; }
  SearchResult answer(ScanCounts counts) const {
    counts.mesh_triangles = mesh_triangles_;
    const Candidate& best = exact_.fragment ? exact_ : near_;
    return finish(ctx_, q_, best.fragment ? &best : nullptr,
                  rejected_ ? MissReason::threshold_rejection : MissReason::no_crossing, counts);
  }

 private:
  const SearchContext& ctx_;
  const SearchRay& q_;
  const SearchOptions& o_;
  Candidate exact_, near_;
  bool rejected_ = false;
  int64_t first_ = -1;
  uint32_t mesh_triangles_ = 0;
};

// Crossing mode: the first crossing, exact ones first (docs/design/search.md).
SearchResult search_crossing(const SearchContext& ctx, const SearchRay& q, const SearchOptions& o) {
  CrossingChoice choice(ctx, q, o);
  const auto on_fragment = [&](const WalkTexel& t, const Fragment& f, const glm::dvec3&,
                               const SearchContext::Plane& p) { choice.take(crossing_candidate(ctx, q, o, t, f, p)); };
  const auto after_texel = [&](const WalkTexel& t, uint32_t index) { return choice.after_texel(t.l1, index); };
  return choice.answer(scan(ctx, q, o, on_fragment, after_texel, [&] { return !choice.found(); }));
}

// Thesis mode: the smallest angle over the first candidates under theta_max
// (docs/design/search.md).
SearchResult search_thesis(const SearchContext& ctx, const SearchRay& q, const SearchOptions& o) {
  Candidate best;
  int64_t first = -1;
  const auto on_fragment = [&](const WalkTexel& t, const Fragment& f, const glm::dvec3& v,
                               const SearchContext::Plane& p) {
    const Candidate c = thesis_candidate(q, t, f, v, p);
    if (c.valid && c.angle < best.angle) best = c;
  };
  const auto after_texel = [&](const WalkTexel&, uint32_t index) {
    if (first < 0 && best.angle <= o.theta_max) first = index;
    return first < 0 || index < first + THESIS_WINDOW_TEXELS;
  };
  const ScanCounts counts = scan(ctx, q, o, on_fragment, after_texel, [&] { return first < 0; });
  const bool accepted = best.fragment && best.angle <= o.theta_max;
  SearchResult r = finish(ctx, q, accepted ? &best : nullptr,
                          best.fragment ? MissReason::threshold_rejection : MissReason::no_crossing, counts);
  if (!accepted) r.angle = best.angle;  // the best approximator's angle, for diagnostics
  return r;
}

SearchResult search_ray(const SearchContext& ctx, const SearchRay& q, const SearchOptions& o) {
  return o.mode == SearchMode::thesis ? search_thesis(ctx, q, o) : search_crossing(ctx, q, o);
}

// A surface already counted on a shadow segment.
struct ShadowCrossing {
  uint32_t triangle, object;
  bool back_face;
  glm::dvec3 x;
  double l;
  bool exact;  // on its triangle (crossing mode, or the side structure)
};

// Is c the same surface crossing as one already counted? The same triangle always (a plane is
// crossed once); in crossing mode the same object and facing within (tolerance + 1) texels (a
// shared edge, or one surface found in two texels), but two crossings both on their triangles
// are one only at the same l to rounding (a shared edge): a chord of a sphere crosses its
// front twice a texel apart where the segment grazes it, and counting that once would leave
// speckles of kt Od instead of (kt Od)^2 in a glass ball's shadow (scenes/cornell.json); in
// thesis mode the same object and facing anywhere on the segment (its points under theta_max
// spread along a grazing surface, so a concave transparent object crossed twice with one
// facing counts once).
bool already_counted(const std::vector<ShadowCrossing>& counted, const SearchContext& ctx, const SearchOptions& o,
                     const Candidate& c) {
  const uint32_t tri = c.triangle;
  const uint32_t object = ctx.scene().triangles->object_id[tri];
  const double near = (o.tolerance_texels + 1.0) * texel_size_at(c.x, ctx.cube().n);
  for (const ShadowCrossing& k : counted) {
    if (k.triangle == tri) return true;
    if (k.object != object || k.back_face != c.back_face) continue;
    if (o.mode == SearchMode::thesis) return true;
    if (k.exact && c.exact) {
      if (std::fabs(k.l - c.l) <= 1e-9 * (std::fabs(c.l) + glm::length(c.x))) return true;
      continue;
    }
    if (glm::length(k.x - c.x) <= near) return true;
  }
  return false;
}

// THE SIDE STRUCTURE on a shadow segment: every side triangle it crosses, nearest first, is
// a blocker (counted once, as the map's), until an opaque one.
void add_side_blockers(const SearchContext& ctx, const SearchRay& q, const SearchOptions& o, const glm::dvec3& light,
                       std::vector<ShadowCrossing>* counted, ShadowResult* res) {
  if (!q.side || !ctx.has_side_triangles()) return;  // the common case: nothing to test
  std::vector<SideCrossing> crossings;
  ctx.for_each_side_crossing(q.w, q.d, q.l_max, [&](uint32_t tri, double l) {
    if (side_crossing_counts(ctx, q, tri, l) && !plane_holds_light(*ctx.scene().triangles, tri, light))
      crossings.push_back({tri, l, side_back_face(ctx, q, tri)});
    return true;
  });
  std::sort(crossings.begin(), crossings.end(), [](const SideCrossing& a, const SideCrossing& b) { return a.l < b.l; });
  const TriangleSoup& soup = *ctx.scene().triangles;
  for (const SideCrossing& s : crossings) {
    Candidate c;
    c.triangle = s.triangle;
    c.back_face = s.back_face;
    c.l = s.l;
    c.x = q.w + s.l * q.d;
    c.exact = true;
    if (already_counted(*counted, ctx, o, c)) continue;
    counted->push_back({s.triangle, soup.object_id[s.triangle], s.back_face, c.x, s.l, true});
    ++res->side_blockers;
    const glm::dvec3 kt = blocker_transmittance(ctx.scene().materials[soup.material_id[s.triangle]]);  // thesis 8.3
    res->transmittance *= kt;
    res->blocked = res->transmittance == glm::dvec3(0.0);
    if (kt == glm::dvec3(0.0)) res->opaque_blocker = s.triangle;
    if (res->blocked) return;
  }
}

// KNOWN BLOCKER (search.hpp): does opaque triangle `tri` block the segment q, by THE SIDE
// STRUCTURE's rules?
bool blocks(const SearchContext& ctx, const SearchRay& q, uint32_t tri, const glm::dvec3& light) {
  const TriangleSoup& soup = *ctx.scene().triangles;
  if (blocker_transmittance(ctx.scene().materials[soup.material_id[tri]]) != glm::dvec3(0.0)) return false;
  TriangleHit hit;
  return intersect_triangle(RayQuery(ctx.cube().centre + q.w, q.d), soup, tri, q.l_max, &hit) &&
         side_crossing_counts(ctx, q, tri, hit.t) && !plane_holds_light(soup, tri, light);
}

// The shadow searches' choice among a segment's candidates, in the walk's order (thesis 8.3,
// SHADOWS in docs/design/search.md): each accepted crossing before the light, not on a plane
// through the light, and not a surface already counted, is a blocker whose transmittance
// multiplies S_l; the walk stops once S_l is zero. Then THE SIDE STRUCTURE's blockers. The
// search's walk and shadow_from_candidates both feed it.
class ShadowChoice {
 public:
  ShadowChoice(const SearchContext& ctx, const SearchRay& q, const SearchOptions& o, const glm::dvec3& light)
      : ctx_(ctx), q_(q), o_(o), light_(light) {}
  bool blocked() const { return res_.blocked; }
  void take(const Candidate& c) {
    const double len = q_.l_max;
    res_.mesh_triangles += c.mesh_triangles;
    const bool thesis = o_.mode == SearchMode::thesis;
    const bool accepted = thesis ? c.valid && c.angle <= o_.theta_max : c.valid;
    if (!accepted || !(c.l < len)) {
      if (c.l < len && (thesis ? c.valid : c.tested)) ++res_.threshold_rejections;
      return;
    }
    const TriangleSoup& soup = *ctx_.scene().triangles;
    if (plane_holds_light(soup, c.triangle, light_)) return;
    if (already_counted(counted_, ctx_, o_, c)) return;
    const uint32_t tri = c.triangle;
    counted_.push_back({tri, soup.object_id[tri], c.back_face, c.x, c.l, !thesis && c.exact});
    // thesis 8.3; rule "shadows" (shading.hpp): S_l is the product over the blockers.
    const glm::dvec3 kt = blocker_transmittance(ctx_.scene().materials[soup.material_id[tri]]);
    res_.transmittance *= kt;
    res_.blocked = res_.transmittance == glm::dvec3(0.0);
    if (kt == glm::dvec3(0.0)) res_.opaque_blocker = tri;
  }
  ShadowResult answer(const ScanCounts& counts) {
    if (!res_.blocked) add_side_blockers(ctx_, q_, o_, light_, &counted_, &res_);
    res_.blockers = static_cast<uint32_t>(counted_.size());
    if (!counted_.empty()) {
      res_.first_blocker =
          std::min_element(counted_.begin(), counted_.end(), [](const ShadowCrossing& a, const ShadowCrossing& b) {
            return a.l < b.l;
          })->triangle;
    }
    res_.aborted = counts.aborted;
    res_.zero_area = !q_.side && meets_zero_area(ctx_, q_, q_.l_max);
    res_.texels_visited = counts.texels;
    res_.nodes_skipped = counts.nodes;
    res_.fragments_tested = counts.fragments;
    res_.candidates = counts.candidates;
    return res_;
  }

 private:
  const SearchContext& ctx_;
  const SearchRay& q_;
  const SearchOptions& o_;
  const glm::dvec3 light_;
  ShadowResult res_;
  std::vector<ShadowCrossing> counted_;
};

}  // namespace

SearchRay reflection_ray(const SearchContext& ctx, const glm::dvec3& w, const glm::dvec3& r,
                         const SearchOptions& options) {
  return make_query(ctx, w, r, options);
}

SearchRay refraction_exit_ray(const SearchContext& ctx, const glm::dvec3& w, const glm::dvec3& t, uint32_t object_id,
                              const SearchOptions& options) {
  SearchRay q = make_query(ctx, w, t, options);
  q.restrict_object = true;
  q.object = object_id;
  return q;
}

bool shadow_ray(const SearchContext& ctx, const glm::dvec3& p, const glm::dvec3& light_position,
                const SearchOptions& options, SearchRay* out) {
  const glm::dvec3 seg = light_position - p;
  const double len = glm::length(seg);
  if (!(len > 0.0)) return false;
  *out = make_query(ctx, p, seg / len, options);
  out->l_max = len;
  return true;
}

SearchResult reflection_search(const SearchContext& ctx, const glm::dvec3& w, const glm::dvec3& r,
                               const SearchOptions& options) {
  return search_ray(ctx, reflection_ray(ctx, w, r, options), options);
}

SearchResult refraction_exit_search(const SearchContext& ctx, const glm::dvec3& w, const glm::dvec3& t,
                                    uint32_t object_id, const SearchOptions& options) {
  return search_ray(ctx, refraction_exit_ray(ctx, w, t, object_id, options), options);
}

ShadowResult shadow_search(const SearchContext& ctx, const glm::dvec3& p, const glm::dvec3& light_position,
                           const SearchOptions& options, uint32_t known_blocker) {
  ShadowResult res;
  SearchRay q;
  if (!shadow_ray(ctx, p, light_position, options, &q)) return res;
  if (known_blocker_answer(ctx, q, light_position, options, known_blocker, &res)) return res;
  return shadow_along(ctx, q, light_position, options);
}

bool known_blocker_answer(const SearchContext& ctx, const SearchRay& q, const glm::dvec3& light_position,
                          const SearchOptions& options, uint32_t known_blocker, ShadowResult* out) {
  if (known_blocker == NO_TRIANGLE || !options.known_blockers || !options.side_structure ||
      options.mode != SearchMode::crossing || options.layers != SearchLayers::all ||
      !blocks(ctx, q, known_blocker, light_position)) {
    return false;
  }
  *out = ShadowResult{};
  out->transmittance = glm::dvec3(0.0);
  out->blocked = out->known_blocker = true;
  out->blockers = 1;
  out->first_blocker = out->opaque_blocker = known_blocker;
  return true;
}

ShadowResult shadow_along(const SearchContext& ctx, const SearchRay& q, const glm::dvec3& light_position,
                          const SearchOptions& options) {
  ShadowChoice choice(ctx, q, options, light_position);
  const auto on_fragment = [&](const WalkTexel& t, const Fragment& f, const glm::dvec3& v,
                               const SearchContext::Plane& plane) {
    if (choice.blocked()) return;
    choice.take(options.mode == SearchMode::thesis ? thesis_candidate(q, t, f, v, plane)
                                                   : crossing_candidate(ctx, q, options, t, f, plane));
  };
  const auto after_texel = [&](const WalkTexel&, uint32_t) { return !choice.blocked(); };
  return choice.answer(scan(ctx, q, options, on_fragment, after_texel, [] { return true; }));
}

CandidateScan scan_candidates(const SearchContext& ctx, const SearchRay& q, const SearchOptions& options,
                              ScanStop stop) {
  CandidateScan out;
  double before_l1 = -INF;  // the end of the texel before the current one
  // STOP HINTS (search.hpp): the first texel with a crossing on its own triangle, the nearest
  // such crossing, and whether one blocks all light.
  int64_t first = -1;
  double nearest = INF;
  bool blocked = false;
  const TriangleSoup& soup = *ctx.scene().triangles;
  const auto on_fragment = [&](const WalkTexel& t, const Fragment& f, const glm::dvec3&,
                               const SearchContext::Plane& p) {
    const std::vector<Fragment>& face = ctx.cube().faces[static_cast<size_t>(t.face)].fragments;
    const Candidate c = crossing_candidate(ctx, q, options, t, f, p);
    out.candidates.push_back({out.texels, static_cast<uint32_t>(t.face), static_cast<uint32_t>(&f - face.data()), t.i,
                              t.j, t.l1, before_l1, c.tested, c.exact, c.valid, c.back_face, c.triangle, c.l, c.outside,
                              c.mesh_triangles});
    if (stop == ScanStop::none || !c.valid || !c.exact || c.mesh_triangles > 0) return;
    if (stop == ScanStop::crossing) {
      if (first < 0) first = out.texels;
      nearest = std::min(nearest, c.l);
    } else if (c.l < q.l_max) {
      blocked =
          blocked || blocker_transmittance(ctx.scene().materials[soup.material_id[c.triangle]]) == glm::dvec3(0.0);
    }
  };
  const auto after_texel = [&](const WalkTexel& t, uint32_t index) {
    out.texels = index + 1;
    before_l1 = t.l1;
    const bool past =
        stop == ScanStop::crossing && first >= 0 && index >= first + CROSSING_WINDOW_TEXELS && t.l1 > nearest;
    if (!past && !(stop == ScanStop::shadow && blocked)) return true;
    out.stopped = true;
    out.last_l1 = t.l1;
    return false;
  };
  out.aborted = scan(ctx, q, options, on_fragment, after_texel, [] { return false; }).aborted;
  return out;
}

SearchResult search_along(const SearchContext& ctx, const SearchRay& q, const SearchOptions& options) {
  return search_ray(ctx, q, options);
}

namespace {

// A listed candidate as crossing_candidate gave it (the fields a choice reads).
Candidate listed_candidate(const SearchContext& ctx, const SearchRay& q, const ScanCandidate& s) {
  Candidate c;
  c.valid = s.valid, c.exact = s.exact, c.tested = s.tested;
  c.l = s.l, c.outside = s.outside, c.angle = 0.0;
  c.x = q.w + s.l * q.d;  // as crossing_candidate computes it
  c.fragment = &ctx.cube().faces[s.face].fragments[s.fragment];
  c.triangle = s.triangle, c.back_face = s.back_face;
  c.texel = {static_cast<int>(s.face), s.i, s.j};
  c.mesh_triangles = s.mesh_triangles;
  return c;
}

// Feeds a ray's listed candidates to a choice as its walk would: take(candidate) for each, and
// after_texel(l1, index) -> keep walking? after each texel holding one. The texels without
// candidates are asked through the one before the next candidate's (its end, before_l1): the
// texels' ends grow along the walk, so if any of them stops the walk, that one does. The
// counts of a walk stopped where the choice stops it (no texels, nodes or fragments read).
template <class Take, class AfterTexel>
ScanCounts replay(const SearchContext& ctx, const SearchRay& q, const SearchOptions& options, const CandidateScan& scan,
                  Take&& take, AfterTexel&& after_texel) {
  if (options.mode != SearchMode::crossing || options.layers != SearchLayers::all) {
    throw InputError("a search from candidates: the crossing mode over all layers only");
  }
  ScanCounts counts;
  counts.aborted = scan.aborted || scan.stopped;
  const std::vector<ScanCandidate>& list = scan.candidates;
  int64_t last = -1;  // the last texel asked
  const auto walk_on = [&](double l1, uint32_t index) {
    last = index;
    if (after_texel(l1, index)) return true;
    counts.aborted = false;  // stopped by the choice, not by the cap
    return false;
  };
  for (size_t k = 0; k < list.size();) {
    const uint32_t texel = list[k].texel;
    if (static_cast<int64_t>(texel) > last + 1 && !walk_on(list[k].before_l1, texel - 1)) return counts;
    for (; k < list.size() && list[k].texel == texel; ++k) {
      take(listed_candidate(ctx, q, list[k]));
      ++counts.candidates;
    }
    if (!walk_on(list[k - 1].l1, texel)) return counts;
  }
  // A scan a STOP HINT ended: its last texel asked too (texels' ends grow along the walk).
  if (scan.stopped && scan.texels > 0 && last + 1 < static_cast<int64_t>(scan.texels)) {
    walk_on(scan.last_l1, scan.texels - 1);
  }
  return counts;
}

}  // namespace

SearchResult search_from_candidates(const SearchContext& ctx, const SearchRay& q, const SearchOptions& options,
                                    const CandidateScan& scan, bool* complete) {
  CrossingChoice choice(ctx, q, options);
  const ScanCounts counts = replay(
      ctx, q, options, scan, [&](const Candidate& c) { choice.take(c); },
      [&](double l1, uint32_t index) { return choice.after_texel(l1, index); });
  if (complete) *complete = !counts.aborted;
  return choice.answer(counts);
}

ShadowResult shadow_from_candidates(const SearchContext& ctx, const SearchRay& q, const glm::dvec3& light_position,
                                    const SearchOptions& options, const CandidateScan& scan, bool* complete) {
  ShadowChoice choice(ctx, q, options, light_position);
  const ScanCounts counts = replay(
      ctx, q, options, scan,
      [&](const Candidate& c) {
        if (!choice.blocked()) choice.take(c);
      },
      [&](double, uint32_t) { return !choice.blocked(); });
  if (complete) *complete = !counts.aborted;
  return choice.answer(counts);
}

}  // namespace abcube
