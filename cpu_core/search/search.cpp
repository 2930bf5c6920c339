#include "search/search.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <tuple>
#include <limits>

#include "search/cube_walk.hpp"
#include "base/error.hpp"
#include "raster/raster.hpp"
#include "shading/shading.hpp"

namespace abcube {

// scene_load.cpp's memory estimate (TRIANGLE_BYTES) counts these sizes per triangle.
static_assert(sizeof(SearchContext::Plane) <= 32 && sizeof(SearchContext::Bounds) <= 128,
              "update TRIANGLE_BYTES in scene_load.cpp");

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();
// A refined point this close to its triangle (in texels) is on it: rounding, not tolerance.
constexpr double ON_TRIANGLE_TEXELS = 1e-6;

// One search's ray, relative to the cube centre.
struct SearchRay {
  glm::dvec3 w{0.0}, d{0.0};  // origin and unit direction
  double l_max = INF;         // end of the ray (shadow segments)
  double self = 0;            // self offset in world units (header, SELF-HITS)
  double self_tolerance = 0;  // nearest tolerance candidate accepted, world units (SELF-HITS)
  bool restrict_object = false;
  uint32_t object = 0;
};

// What the walk over the map saw of one ray.
struct ScanCounts {
  uint32_t texels = 0, fragments = 0, candidates = 0;
  bool aborted = false;
};

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

// The fragment nearest_layer() keeps for texel (x, y): a centre sample covered, the nearest
// plane along the texel-centre direction v (abuffer.hpp, the Z-buffered map's layer).
const Fragment* nearest_fragment(const SearchContext& ctx, FragmentList list, const glm::dvec3& v) {
  const Fragment* best = nullptr;
  double best_a = INF;
  for (const Fragment& f : list) {
    if ((f.mask & CENTRE_SAMPLES) == 0) continue;
    const SearchContext::Plane& p = ctx.plane(f.triangle());
    const double den = glm::dot(p.normal, v);
    if (den == 0.0) continue;
    const double a = p.offset / den;
    if (a > 0.0 && a < best_a) {
      best_a = a;
      best = &f;
    }
  }
  return best;
}

// W's own surface (header, SELF-HITS): a plane passing within the self offset of W that the
// ray leaves, runs along, or crosses again within the offset. A neighbouring face near W
// that the ray really crosses further on is not.
bool own_surface(const SearchContext::Plane& p, const SearchRay& q) {
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
        if (q.restrict_object && soup.object_id[f.triangle()] != q.object) continue;
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

// One fragment's answer for a ray.
struct Candidate {
  bool valid = false;
  bool exact = false;   // crossing mode: the refined point is on the triangle
  bool tested = false;  // crossing mode: a refined point in the texel was measured
  double l = INF;       // crossing: ray parameter; thesis: projection of X' - W on the ray
  double angle = INF;   // thesis: angle between the ray and X' - W
  double outside = 0;   // crossing: distance from the triangle, in texels
  glm::dvec3 x{0.0};    // X', relative to the centre
  const Fragment* fragment = nullptr;
  uint32_t triangle = 0;   // the surface found: the fragment's triangle or, refined on the mesh, the one crossed
  bool back_face = false;  // its facing as seen from the centre (abuffer.hpp)
  CubeTexel texel{0, 0, 0};
};

// Where the ray meets triangle `tri`'s plane: l (INF when parallel or degenerate) and the
// edge whose line the point lies furthest outside of, in the plane, by more than
// ON_TRIANGLE_TEXELS (-1: on the triangle; near a corner this admits up to the tolerance
// times 1/sin(corner angle / 2)).
struct PlaneCrossing {
  double l = INF;
  int outside_edge = -1;
};

PlaneCrossing plane_crossing(const SearchContext& ctx, const SearchRay& q, uint32_t tri) {
  PlaneCrossing c;
  const SearchContext::Plane& p = ctx.plane(tri);
  const SearchContext::Bounds& b = ctx.bounds(tri);
  const double den = glm::dot(p.normal, q.d);
  if (den == 0.0 || !(b.radius > 0.0)) return c;
  c.l = (p.offset - glm::dot(p.normal, q.w)) / den;
  const glm::dvec3 x = q.w + c.l * q.d;
  double worst = -ON_TRIANGLE_TEXELS * texel_size_at(x, ctx.cube().n);
  for (int k = 0; k < 3; ++k) {
    const double outside = glm::dot(b.edge_normal[static_cast<size_t>(k)], x) - b.edge_offset[static_cast<size_t>(k)];
    if (outside < worst) {
      worst = outside;
      c.outside_edge = k;
    }
  }
  return c;
}

// The exact crossing of the ray with triangle `tri` (on the triangle, l in [self, l_max]):
// its parameter l, or INF.
double exact_crossing(const SearchContext& ctx, const SearchRay& q, uint32_t tri) {
  const PlaneCrossing c = plane_crossing(ctx, q, tri);
  return c.outside_edge < 0 && c.l >= q.self && c.l <= q.l_max ? c.l : INF;
}

// MESH REFINEMENT (crossing mode; header). The answer of the mesh around a fragment's
// triangle when the ray does not cross that triangle itself.
enum class Refined { hit, miss, unknown };
struct MeshAnswer {
  Refined result = Refined::unknown;
  uint32_t triangle = 0;
  double l = INF;
};

// Does a triangle's bounding sphere come within `radius` of the ray's stretch [l_lo, l_hi]?
bool near_ray(const SearchContext::Bounds& b, const SearchRay& q, double l_lo, double l_hi, double radius) {
  const double along = std::clamp(glm::dot(b.centroid - q.w, q.d), l_lo, l_hi);
  const glm::dvec3 off = b.centroid - (q.w + along * q.d);
  const double reach = b.radius + radius;
  return glm::dot(off, off) <= reach * reach;
}

// Floods the edge-connected triangles of `start` that come within `radius` of the ray's
// stretch [l_lo, l_hi] (bounding spheres), testing each for an exact crossing: hit (the
// smallest l), miss (the flood ended with none), or unknown (more than
// REFINE_MAX_TRIANGLES triangles were near: the caller falls back on the plane tolerance).
MeshAnswer refine_on_mesh(const SearchContext& ctx, const SearchRay& q, uint32_t start, double l_lo, double l_hi,
                          double radius) {
  MeshAnswer a;
  // A start triangle away from the ray: the mesh near the ray may be elsewhere in the
  // fragment's patch (merged), the flood cannot say.
  if (!near_ray(ctx.bounds(start), q, l_lo, l_hi, radius)) return a;
  // First the straight way: from triangle to triangle across the edge the ray's crossing
  // of the current plane lies furthest outside of, while the next is near the ray. On a
  // smooth patch this reaches the triangle crossed in a few steps.
  uint32_t walker = start;
  for (size_t step = 0; step < REFINE_MAX_TRIANGLES; ++step) {
    const PlaneCrossing c = plane_crossing(ctx, q, walker);
    if (c.l == INF) break;
    if (c.outside_edge < 0) {  // on this triangle
      if (c.l >= q.self && c.l <= q.l_max) {
        a.result = Refined::hit;
        a.triangle = walker;
        a.l = c.l;
        return a;
      }
      break;
    }
    const uint32_t nb = ctx.neighbour(walker, c.outside_edge);
    if (nb == SearchContext::NO_NEIGHBOUR || !near_ray(ctx.bounds(nb), q, l_lo, l_hi, radius)) break;
    walker = nb;
  }
  // Then every triangle near the ray, breadth-first.
  std::array<uint32_t, REFINE_MAX_TRIANGLES> seen{};
  size_t count = 0, next = 0;
  seen[count++] = start;
  bool overflow = false;
  while (next < count) {
    const uint32_t tri = seen[next++];
    const double l = exact_crossing(ctx, q, tri);
    if (l < a.l) {
      a.l = l;
      a.triangle = tri;
      if (tri == start) break;  // the ray crosses the start triangle itself
    }
    for (int k = 0; k < 3; ++k) {
      const uint32_t nb = ctx.neighbour(tri, k);
      const auto seen_end = seen.begin() + static_cast<std::ptrdiff_t>(count);
      if (nb == SearchContext::NO_NEIGHBOUR || std::find(seen.begin(), seen_end, nb) != seen_end) continue;
      if (!near_ray(ctx.bounds(nb), q, l_lo, l_hi, radius)) continue;
      if (count == seen.size()) {
        overflow = true;
        continue;
      }
      seen[count++] = nb;
    }
  }
  if (a.l < INF) a.result = Refined::hit;
  else a.result = overflow ? Refined::unknown : Refined::miss;
  return a;
}

// Crossing mode (header): the ray meets the fragment's triangle plane at X(l'); refined on
// the mesh around that triangle unless the ray crosses the triangle itself there.
Candidate crossing_candidate(const SearchContext& ctx, const SearchRay& q, const SearchOptions& o, const WalkTexel& t,
                             const Fragment& f) {
  Candidate c;
  const uint32_t tri = f.triangle();
  const SearchContext::Plane& p = ctx.plane(tri);
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
    c.outside = distance_to_triangle(c.x, ctx.vertex(tri, 0), ctx.vertex(tri, 1), ctx.vertex(tri, 2), p.normal,
                                     p.offset) /
                texel_size_at(c.x, ctx.cube().n);
    c.exact = c.outside <= ON_TRIANGLE_TEXELS;
    c.tested = true;
  }
  if (!c.exact && o.refine == SearchRefine::mesh) {
    const double l_ref = std::isinf(t.l1) ? t.l0 : 0.5 * (t.l0 + t.l1);
    const double radius = std::max(o.tolerance_texels, 1.0) * texel_size_at(q.w + l_ref * q.d, ctx.cube().n);
    const MeshAnswer m = refine_on_mesh(ctx, q, tri, t.l0 - radius, t.l1 + radius, radius);
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
  if (!c.tested) return Candidate{};
  c.valid = c.outside <= o.tolerance_texels && (c.exact || l >= q.self_tolerance);
  c.triangle = tri;
  c.back_face = f.back_face();
  return c;
}

// Thesis mode (thesis 7.4.1, 9.3.4): the point a V of the texel centre on the fragment's plane.
Candidate thesis_candidate(const SearchContext& ctx, const SearchRay& q, const WalkTexel& t, const Fragment& f,
                           const glm::dvec3& v) {
  Candidate c;
  const SearchContext::Plane& p = ctx.plane(f.triangle());
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
    if (q.restrict_object && ctx.scene().triangles->object_id[tri] != q.object) continue;
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

// The answer: the chosen candidate or a miss (`miss` unless the walk was aborted); a surface
// the map cannot hold met before it turns it into a zero-area miss.
SearchResult finish(const SearchContext& ctx, const SearchRay& q, const Candidate* best, MissReason miss,
                    const ScanCounts& counts) {
  SearchResult r;
  if (best) r = make_result(ctx, q, *best);
  else r.miss = counts.aborted ? MissReason::aborted : miss;
  if (meets_zero_area(ctx, q, best ? best->l : q.l_max)) {
    r.hit = false;
    r.miss = MissReason::zero_area_surface;
  }
  r.texels_visited = counts.texels;
  r.fragments_tested = counts.fragments;
  r.candidates = counts.candidates;
  return r;
}

// Crossing mode: the first crossing, exact ones first (header).
SearchResult search_crossing(const SearchContext& ctx, const SearchRay& q, const SearchOptions& o) {
  Candidate exact, near;
  bool rejected = false;
  int64_t first = -1;
  const auto on_fragment = [&](const WalkTexel& t, const Fragment& f, const glm::dvec3&) {
    const Candidate c = crossing_candidate(ctx, q, o, t, f);
    if (!c.valid) {
      rejected = rejected || (c.tested && c.outside > o.tolerance_texels);
      return;
    }
    Candidate& best = c.exact ? exact : near;
    if (c.l < best.l) best = c;
  };
  const auto after_texel = [&](const WalkTexel& t, uint32_t index) {
    const double best_l = std::min(exact.l, near.l);
    if (best_l == INF) return true;
    if (first < 0) first = index;
    return index < first + CROSSING_WINDOW_TEXELS || t.l1 <= best_l;
  };
  const ScanCounts counts = scan(ctx, q, o, on_fragment, after_texel, [&] { return first < 0; });
  const Candidate& best = exact.fragment ? exact : near;
  return finish(ctx, q, best.fragment ? &best : nullptr,
                rejected ? MissReason::threshold_rejection : MissReason::no_crossing, counts);
}

// Thesis mode: the smallest angle over the first candidates under theta_max (header).
SearchResult search_thesis(const SearchContext& ctx, const SearchRay& q, const SearchOptions& o) {
  Candidate best;
  int64_t first = -1;
  const auto on_fragment = [&](const WalkTexel& t, const Fragment& f, const glm::dvec3& v) {
    const Candidate c = thesis_candidate(ctx, q, t, f, v);
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

SearchRay make_query(const SearchContext& ctx, const glm::dvec3& w_world, const glm::dvec3& dir,
                    const SearchOptions& o) {
  ABCUBE_CHECK(std::fabs(glm::length(dir) - 1.0) < 1e-6, "search direction must be unit");
  SearchRay q;
  q.w = w_world - ctx.cube().centre;
  q.d = dir;
  const double texel = texel_size_at(q.w, ctx.cube().n);
  q.self = self_offset_texels(o) * texel;
  q.self_tolerance = 2.0 * o.tolerance_texels * texel;
  return q;
}

SearchResult search_ray(const SearchContext& ctx, const SearchRay& q, const SearchOptions& o) {
  return o.mode == SearchMode::thesis ? search_thesis(ctx, q, o) : search_crossing(ctx, q, o);
}

}  // namespace

double self_offset_texels(const SearchOptions& o) {
  if (o.self_offset_texels > 0.0) return o.self_offset_texels;
  return o.mode == SearchMode::thesis ? SELF_OFFSET_THESIS_TEXELS : SELF_OFFSET_CROSSING_TEXELS;
}

const char* search_mode_name(SearchMode m) { return m == SearchMode::thesis ? "thesis" : "crossing"; }

bool parse_search_mode(const std::string& s, SearchMode* out) {
  if (s == "crossing") *out = SearchMode::crossing;
  else if (s == "thesis") *out = SearchMode::thesis;
  else return false;
  return true;
}

const char* search_refine_name(SearchRefine r) { return r == SearchRefine::plane ? "plane" : "mesh"; }

bool parse_search_refine(const std::string& s, SearchRefine* out) {
  if (s == "mesh") *out = SearchRefine::mesh;
  else if (s == "plane") *out = SearchRefine::plane;
  else return false;
  return true;
}

const char* miss_reason_name(MissReason r) {
  switch (r) {
    case MissReason::none: return "none";
    case MissReason::no_crossing: return "no_crossing";
    case MissReason::threshold_rejection: return "threshold_rejection";
    case MissReason::zero_area_surface: return "zero_area_surface";
    case MissReason::aborted: return "aborted";
  }
  return "?";
}

SearchContext::SearchContext(const SceneData& scene, const CubeABuffer& cube,
                             std::shared_ptr<const MeshNeighbours> neighbours)
    : scene_(&scene), cube_(&cube), neighbours_(std::move(neighbours)) {
  const TriangleSoup& soup = *scene.triangles;
  const uint32_t count = static_cast<uint32_t>(soup.triangle_count());
  planes_.resize(count);
  bounds_.resize(count);
  // The raster's own rule decides which triangles the map cannot hold (raster.hpp).
  const RasterView view = cube_face_view(0, cube.centre, std::max(cube.n, 1), cube.near_distance);
  TriangleSetup setup;
  for (uint32_t k = 0; k < count; ++k) {
    const glm::dvec3 a = vertex(k, 0);
    const glm::dvec3 n = glm::cross(vertex(k, 1) - a, vertex(k, 2) - a);
    const double len = glm::length(n);
    if (len > 0.0 && std::isfinite(len)) {
      planes_[k] = {n / len, glm::dot(n / len, a)};
      Bounds& b = bounds_[k];
      const glm::dvec3 v[3] = {a, vertex(k, 1), vertex(k, 2)};
      b.centroid = (v[0] + v[1] + v[2]) / 3.0;
      for (size_t e = 0; e < 3; ++e) {
        const glm::dvec3 m = glm::cross(n / len, v[(e + 1) % 3] - v[e]);
        const double ml = glm::length(m);
        if (ml > 0.0) b.edge_normal[e] = m / ml;
        b.edge_offset[e] = glm::dot(b.edge_normal[e], v[e]);
        b.radius = std::max(b.radius, glm::length(v[e] - b.centroid));
      }
    }
    if (setup_triangle(view, soup, k, &setup) == SetupResult::edge_on) zero_area_.push_back(k);
  }
  if (!neighbours_) neighbours_ = std::make_shared<const MeshNeighbours>(build_mesh_neighbours(soup));
  // Where each face holds fragments, row by row (empty_ahead), and BLOCK BOUNDS.
  const int n = cube.n;
  blocks_per_row_ = (std::max(n, 0) + BOUNDS_BLOCK - 1) / BOUNDS_BLOCK;
  for (size_t f = 0; f < occupied_.size(); ++f) {
    RowBounds& rb = occupied_[f];
    const ABuffer& b = cube.faces[f];
    const bool known = b.width() == n && b.height() == n &&
                       b.offsets.size() == static_cast<size_t>(n) * static_cast<size_t>(n) + 1;
    // A face not laid out as n x n lists is taken as full: never skipped.
    rb.min_row.assign(static_cast<size_t>(std::max(n, 0)), known ? n : 0);
    rb.max_row.assign(static_cast<size_t>(std::max(n, 0)), known ? -1 : n - 1);
    for (int j = 0; known && j < n; ++j) {
      const uint32_t* row = b.offsets.data() + static_cast<size_t>(j) * static_cast<size_t>(n);
      for (int i = 0; i < n; ++i) {
        if (row[i + 1] == row[i]) continue;
        rb.min_row[static_cast<size_t>(j)] = std::min(rb.min_row[static_cast<size_t>(j)], i);
        rb.max_row[static_cast<size_t>(j)] = i;
      }
    }
    // A face not laid out as n x n lists gets blocks spanning every depth: never passed.
    const float inf = std::numeric_limits<float>::infinity();
    block_z_[f].assign(static_cast<size_t>(blocks_per_row_) * static_cast<size_t>(blocks_per_row_),
                       known ? glm::vec2(inf, -inf) : glm::vec2(-inf, inf));
    for (int j = 0; known && j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        glm::vec2& z = block_z_[f][static_cast<size_t>(j / BOUNDS_BLOCK) * static_cast<size_t>(blocks_per_row_) +
                                   static_cast<size_t>(i / BOUNDS_BLOCK)];
        for (const Fragment& frag : b.list(i, j)) {
          z.x = std::min(z.x, frag.zmin);
          z.y = std::max(z.y, frag.zmax);
        }
      }
    }
    rb.min_prefix = rb.min_row;
    rb.max_prefix = rb.max_row;
    for (size_t j = 1; j < rb.min_prefix.size(); ++j) {
      rb.min_prefix[j] = std::min(rb.min_prefix[j], rb.min_prefix[j - 1]);
      rb.max_prefix[j] = std::max(rb.max_prefix[j], rb.max_prefix[j - 1]);
    }
    rb.min_suffix = rb.min_row;
    rb.max_suffix = rb.max_row;
    for (size_t j = rb.min_suffix.size(); j-- > 1;) {
      rb.min_suffix[j - 1] = std::min(rb.min_suffix[j - 1], rb.min_suffix[j]);
      rb.max_suffix[j - 1] = std::max(rb.max_suffix[j - 1], rb.max_suffix[j]);
    }
  }
}

// Vertices are the same when their object and float position are (bit for bit, -0 = +0);
// an edge links the two triangles that have it, in either direction.
MeshNeighbours build_mesh_neighbours(const TriangleSoup& soup) {
  constexpr uint32_t NO_NEIGHBOUR = SearchContext::NO_NEIGHBOUR;
  const size_t count = soup.triangle_count();
  MeshNeighbours neighbours(count, {NO_NEIGHBOUR, NO_NEIGHBOUR, NO_NEIGHBOUR});
  struct Corner {
    uint32_t object;
    std::array<uint32_t, 3> bits;
    uint32_t index;  // 3 * triangle + k
  };
  std::vector<Corner> corners(3 * count);
  for (size_t c = 0; c < corners.size(); ++c) {
    const glm::vec3 v = soup.positions[c] + glm::vec3(0.0f);  // -0 -> +0
    Corner& k = corners[c];
    k.object = soup.object_id[c / 3];
    std::memcpy(k.bits.data(), &v[0], sizeof(float));
    std::memcpy(k.bits.data() + 1, &v[1], sizeof(float));
    std::memcpy(k.bits.data() + 2, &v[2], sizeof(float));
    k.index = static_cast<uint32_t>(c);
  }
  std::sort(corners.begin(), corners.end(), [](const Corner& a, const Corner& b) {
    return std::tie(a.object, a.bits, a.index) < std::tie(b.object, b.bits, b.index);
  });
  std::vector<uint32_t> vertex_id(corners.size());
  uint32_t id = 0;
  for (size_t c = 0; c < corners.size(); ++c) {
    if (c > 0 && (corners[c].object != corners[c - 1].object || corners[c].bits != corners[c - 1].bits)) ++id;
    vertex_id[corners[c].index] = id;
  }
  // (smaller vertex id, larger vertex id, 3 * triangle + edge), sorted: equal edges adjacent.
  std::vector<std::pair<uint64_t, uint32_t>> edges;
  edges.reserve(3 * count);
  for (size_t t = 0; t < count; ++t) {
    for (size_t k = 0; k < 3; ++k) {
      const uint64_t a = vertex_id[3 * t + k], b = vertex_id[3 * t + (k + 1) % 3];
      if (a == b) continue;
      edges.push_back({std::min(a, b) << 32 | std::max(a, b), static_cast<uint32_t>(3 * t + k)});
    }
  }
  std::sort(edges.begin(), edges.end());
  for (size_t e = 0; e < edges.size();) {
    size_t end = e + 1;
    while (end < edges.size() && edges[end].first == edges[e].first) ++end;
    if (end - e == 2) {  // manifold edge; a border (1) or a non-manifold edge (> 2) links nothing
      const uint32_t x = edges[e].second, y = edges[e + 1].second;
      neighbours[x / 3][x % 3] = y / 3;
      neighbours[y / 3][y % 3] = x / 3;
    }
    e = end;
  }
  return neighbours;
}

bool SearchContext::empty_ahead(int face, int i, int j, int step_i, int step_j) const {
  const RowBounds& rb = occupied_[static_cast<size_t>(face)];
  const size_t row = static_cast<size_t>(j);
  // The occupied columns over the rows the walk may still visit.
  const int lo = step_j > 0 ? rb.min_suffix[row] : (step_j < 0 ? rb.min_prefix[row] : rb.min_row[row]);
  const int hi = step_j > 0 ? rb.max_suffix[row] : (step_j < 0 ? rb.max_prefix[row] : rb.max_row[row]);
  if (step_i > 0) return hi < i;
  if (step_i < 0) return lo > i;
  return hi < i || lo > i;  // column i only
}

glm::dvec3 SearchContext::vertex(uint32_t triangle, int k) const {
  return glm::dvec3(scene_->triangles->positions[3 * static_cast<size_t>(triangle) + static_cast<size_t>(k)]) -
         cube_->centre;
}

bool mesh_crossing(const SearchContext& ctx, const glm::dvec3& w, const glm::dvec3& dir, uint32_t triangle,
                   double l_near, double radius, uint32_t* crossed, double* l) {
  SearchRay q;
  q.w = w - ctx.cube().centre;
  q.d = dir;
  q.self = -INF;
  const MeshAnswer m = refine_on_mesh(ctx, q, triangle, l_near - radius, l_near + radius, radius);
  if (m.result != Refined::hit) return false;
  *crossed = m.triangle;
  *l = m.l;
  return true;
}

SearchResult reflection_search(const SearchContext& ctx, const glm::dvec3& w, const glm::dvec3& r,
                               const SearchOptions& options) {
  return search_ray(ctx, make_query(ctx, w, r, options), options);
}

SearchResult refraction_exit_search(const SearchContext& ctx, const glm::dvec3& w, const glm::dvec3& t,
                                    uint32_t object_id, const SearchOptions& options) {
  SearchRay q = make_query(ctx, w, t, options);
  q.restrict_object = true;
  q.object = object_id;
  return search_ray(ctx, q, options);
}


namespace {

// A surface already counted on a shadow segment.
struct ShadowCrossing {
  uint32_t triangle, object;
  bool back_face;
  glm::dvec3 x;
  double l;
};

// Is c the same surface crossing as one already counted? The same triangle always (a plane
// is crossed once); in crossing mode the same object and facing within (tolerance + 1)
// texels (a shared edge, or one surface found in two texels); in thesis mode the same
// object and facing anywhere on the segment (its points under theta_max spread along a
// grazing surface, so a concave transparent object crossed twice with one facing counts once).
bool already_counted(const std::vector<ShadowCrossing>& counted, const SearchContext& ctx, const SearchOptions& o,
                     const Candidate& c) {
  const uint32_t tri = c.triangle;
  const uint32_t object = ctx.scene().triangles->object_id[tri];
  const double near = (o.tolerance_texels + 1.0) * texel_size_at(c.x, ctx.cube().n);
  for (const ShadowCrossing& k : counted) {
    if (k.triangle == tri) return true;
    if (k.object != object || k.back_face != c.back_face) continue;
    if (o.mode == SearchMode::thesis || glm::length(k.x - c.x) <= near) return true;
  }
  return false;
}

}  // namespace

ShadowResult shadow_search(const SearchContext& ctx, const glm::dvec3& p, const glm::dvec3& light_position,
                           const SearchOptions& options) {
  ShadowResult res;
  const glm::dvec3 seg = light_position - p;
  const double len = glm::length(seg);
  if (!(len > 0.0)) return res;
  SearchRay q = make_query(ctx, p, seg / len, options);
  q.l_max = len;
  std::vector<ShadowCrossing> counted;
  const auto on_fragment = [&](const WalkTexel& t, const Fragment& f, const glm::dvec3& v) {
    if (res.blocked) return;
    const Candidate c = options.mode == SearchMode::thesis ? thesis_candidate(ctx, q, t, f, v)
                                                           : crossing_candidate(ctx, q, options, t, f);
    const bool accepted = options.mode == SearchMode::thesis ? c.valid && c.angle <= options.theta_max : c.valid;
    if (!accepted || !(c.l < len)) {
      if (c.l < len && (options.mode == SearchMode::thesis ? c.valid : c.tested)) {
        ++res.threshold_rejections;
      }
      return;
    }
    if (already_counted(counted, ctx, options, c)) return;
    const uint32_t tri = c.triangle;
    counted.push_back({tri, ctx.scene().triangles->object_id[tri], c.back_face, c.x, c.l});
    // thesis 8.3; rule "shadows" (shading.hpp): S_l is the product over the blockers.
    res.transmittance *= blocker_transmittance(ctx.scene().materials[ctx.scene().triangles->material_id[tri]]);
    res.blocked = res.transmittance == glm::dvec3(0.0);
  };
  const auto after_texel = [&](const WalkTexel&, uint32_t) { return !res.blocked; };
  const ScanCounts counts = scan(ctx, q, options, on_fragment, after_texel, [] { return true; });
  res.blockers = static_cast<uint32_t>(counted.size());
  if (!counted.empty()) {
    res.first_blocker = std::min_element(counted.begin(), counted.end(), [](const ShadowCrossing& a,
                                                                            const ShadowCrossing& b) {
                          return a.l < b.l;
                        })->triangle;
  }
  res.aborted = counts.aborted;
  res.zero_area = meets_zero_area(ctx, q, len);
  res.texels_visited = counts.texels;
  res.fragments_tested = counts.fragments;
  res.candidates = counts.candidates;
  return res;
}

void SearchKindStats::add(const SearchResult& r) {
  ++rays;
  texels += r.texels_visited;
  max_texels = std::max<uint64_t>(max_texels, r.texels_visited);
  fragments += r.fragments_tested;
  candidates += r.candidates;
  if (r.hit) {
    ++hits;
    return;
  }
  ++misses;
  threshold_rejections += r.miss == MissReason::threshold_rejection;
  zero_area += r.miss == MissReason::zero_area_surface;
  aborted += r.miss == MissReason::aborted;
}

void SearchKindStats::add(const ShadowResult& r) {
  ++rays;
  texels += r.texels_visited;
  max_texels = std::max<uint64_t>(max_texels, r.texels_visited);
  fragments += r.fragments_tested;
  candidates += r.candidates;
  if (r.blockers > 0) ++hits;
  else ++misses;
  threshold_rejections += r.blockers == 0 && r.threshold_rejections > 0;
  zero_area += r.zero_area;
  aborted += r.aborted;
}

void SearchKindStats::merge(const SearchKindStats& o) {
  rays += o.rays;
  texels += o.texels;
  max_texels = std::max(max_texels, o.max_texels);
  fragments += o.fragments;
  candidates += o.candidates;
  hits += o.hits;
  misses += o.misses;
  threshold_rejections += o.threshold_rejections;
  zero_area += o.zero_area;
  aborted += o.aborted;
}

void SearchStats::merge(const SearchStats& o) {
  reflection.merge(o.reflection);
  refraction_exit.merge(o.refraction_exit);
  shadow.merge(o.shadow);
}

}  // namespace abcube
