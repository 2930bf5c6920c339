// MESH REFINEMENT (search.hpp): the exact crossing of a ray with the mesh around a
// fragment's triangle, first straight across the edges, then breadth-first.
#include <algorithm>
#include <array>

#include "search/search_internal.hpp"

namespace abcube {
namespace detail {

PlaneCrossing plane_crossing(const SearchContext& ctx, const SearchRay& q, uint32_t tri, double l_lo, double l_hi) {
  PlaneCrossing c;
  const SearchContext::EdgePlanes& e = edge_planes(ctx, tri);
  const double den = glm::dot(e.plane.normal, q.d);
  if (den == 0.0) return c;  // parallel, or degenerate (a zero normal)
  c.l = (e.plane.offset - glm::dot(e.plane.normal, q.w)) / den;
  if (!(c.l >= l_lo && c.l <= l_hi)) {
    c.outside_edge = PlaneCrossing::NOT_TESTED;
    return c;
  }
  const glm::dvec3 x = q.w + c.l * q.d;
  double outside[3];
  for (size_t k = 0; k < 3; ++k) outside[k] = glm::dot(e.edge_normal[k], x) - e.edge_offset[k];
  // The edge whose line the point lies furthest outside of (the first, at equal distances).
  double worst = 0.0;
  int edge = -1;
  for (int k = 0; k < 3; ++k) {
    if (outside[k] < worst) {
      worst = outside[k];
      edge = k;
    }
  }
  // Inside every edge's line: on the triangle, whatever the tolerance (it is not negative).
  if (edge < 0) return c;
  // Outside it by more than ON_TRIANGLE_TEXELS texels? The texel's width, 2 |x|_inf / n, is
  // at most 2 |x|_inf: far outside (nearly every triangle a flood tests) is decided without
  // its division; near the bound, by the tolerance itself.
  const double m = std::max({std::fabs(x.x), std::fabs(x.y), std::fabs(x.z)});
  if (worst < -2.000001 * ON_TRIANGLE_TEXELS * m || worst < -ON_TRIANGLE_TEXELS * texel_size_at(x, ctx.cube().n))
    c.outside_edge = edge;
  return c;
}

namespace {

// The exact crossing of the ray with triangle `tri` (on the triangle, l in [self, l_max]):
// its parameter l, or INF.
double exact_crossing(const SearchContext& ctx, const SearchRay& q, uint32_t tri) {
  // The range first: most planes of a flood are crossed behind the ray or before `self`.
  const PlaneCrossing c = plane_crossing(ctx, q, tri, q.self, q.l_max);
  return c.outside_edge < 0 ? c.l : INF;
}

// Does a triangle's bounding sphere come within `radius` of the ray's stretch [l_lo, l_hi]?
bool near_ray(const SearchContext::Sphere& b, const SearchRay& q, double l_lo, double l_hi, double radius) {
  const double along = std::clamp(glm::dot(b.centroid - q.w, q.d), l_lo, l_hi);
  const glm::dvec3 off = b.centroid - (q.w + along * q.d);
  const double reach = b.radius + radius;
  return glm::dot(off, off) <= reach * reach;
}

// The flood's table: what it knows of a triangle (TAKEN into the flood, found AWAY from the
// ray or past the flood's size, or NEW), by open addressing in a table each thread keeps
// across floods. Every flood starts from an empty table: the slots it used are reset when it
// ends (`used`), so a flood of a few triangles does not pay for clearing the whole table. A
// flood takes at most REFINE_MAX_TRIANGLES triangles and sets each slot it finds NEW at once,
// so it holds at most the start and three neighbours of each taken triangle: the table is
// never more than a fifth full.
class FloodTable {
 public:
  static constexpr uint8_t NEW = 0, TAKEN = 1, AWAY = 2;
  // The state of `tri`, a place the caller may set (the slot is kept as tri's).
  uint8_t* find(uint32_t tri) {
    size_t h = (tri * 2654435761u) & (SLOTS - 1);
    while (state_[h] != NEW && triangle_[h] != tri) h = (h + 1) & (SLOTS - 1);
    if (state_[h] == NEW) {
      triangle_[h] = tri;
      used_[used_count_++] = static_cast<uint16_t>(h);
    }
    return &state_[h];
  }
  void mark(uint32_t tri, uint8_t state) { *find(tri) = state; }
  void clear() {
    for (size_t k = 0; k < used_count_; ++k) state_[used_[k]] = NEW;
    used_count_ = 0;
  }

 private:
  static constexpr size_t MOST = REFINE_MAX_TRIANGLES * 4;  // taken, and their neighbours
  static constexpr size_t SLOTS = 4 * MOST;
  static_assert((SLOTS & (SLOTS - 1)) == 0, "a power of two");
  std::array<uint32_t, SLOTS> triangle_{};
  std::array<uint8_t, SLOTS> state_{};
  std::array<uint16_t, MOST> used_{};
  size_t used_count_ = 0;
};

FloodTable& flood_table() {
  thread_local FloodTable table;
  return table;
}

}  // namespace

// Floods the edge-connected triangles of `start` that come within `radius` of the ray's
// stretch [l_lo, l_hi] (bounding spheres), testing each for an exact crossing: hit (the
// smallest l), miss (the flood ended with none), or unknown (more than
// REFINE_MAX_TRIANGLES triangles were near: the caller falls back on the plane tolerance).
MeshAnswer refine_on_mesh(const SearchContext& ctx, const SearchRay& q, uint32_t start, double l_lo, double l_hi,
                          double radius) {
  MeshAnswer a;
  // A start triangle away from the ray: the mesh near the ray may be elsewhere in the
  // fragment's patch (merged). The straight walk below may still reach it, across
  // triangles away from the ray, and its crossing counts if it lies in [l_lo, l_hi];
  // otherwise the flood cannot say. (Such fragments must still be refined: a glass ball's
  // exit crossing seen only in a texel of a merged fragment would otherwise be lost,
  // speckles in its shadow on scenes/cornell.json.)
  Memo<SearchContext::Sphere>& spheres = Memo<SearchContext::Sphere>::of(ctx);
  const bool start_near = near_ray(bounding_sphere(spheres, ctx, start), q, l_lo, l_hi, radius);
  // First the straight way: from triangle to triangle across the edge the ray's crossing
  // of the current plane lies furthest outside of, while the next is near the ray. On a
  // smooth patch this reaches the triangle crossed in a few steps.
  uint32_t walker = start;
  for (size_t step = 0; step < REFINE_MAX_STEPS; ++step) {
    const PlaneCrossing c = plane_crossing(ctx, q, walker);
    ++a.tested;
    if (c.l == INF) break;
    if (c.outside_edge < 0) {  // on this triangle
      if (c.l >= q.self && c.l <= q.l_max && (start_near || (c.l >= l_lo && c.l <= l_hi))) {
        a.result = Refined::hit;
        a.triangle = walker;
        a.l = c.l;
        return a;
      }
      break;
    }
    const uint32_t nb = ctx.neighbour(walker, c.outside_edge);
    if (nb == SearchContext::NO_NEIGHBOUR ||
        (start_near && !near_ray(bounding_sphere(spheres, ctx, nb), q, l_lo, l_hi, radius)))
      break;
    walker = nb;
  }
  if (!start_near) return a;
  // Then every triangle near the ray, breadth-first, in the order found (`seen`). The flood's
  // table (FloodTable) remembers both the triangles taken and those found away from the ray,
  // so a triangle on the flood's border is tested once, not once from each neighbour taken.
  std::array<uint32_t, REFINE_MAX_TRIANGLES> seen;  // only [0, count) is read
  FloodTable& table = flood_table();
  size_t count = 0, next = 0;
  seen[count++] = start;
  table.mark(start, FloodTable::TAKEN);
  bool overflow = false;
  while (next < count) {
    const uint32_t tri = seen[next++];
    const double l = exact_crossing(ctx, q, tri);
    ++a.tested;
    if (l < a.l) {
      a.l = l;
      a.triangle = tri;
      if (tri == start) break;  // the ray crosses the start triangle itself
    }
    for (int k = 0; k < 3; ++k) {
      const uint32_t nb = ctx.neighbour(tri, k);
      if (nb == SearchContext::NO_NEIGHBOUR) continue;
      uint8_t* state = table.find(nb);
      if (*state == FloodTable::TAKEN || *state == FloodTable::AWAY) continue;
      if (!near_ray(bounding_sphere(spheres, ctx, nb), q, l_lo, l_hi, radius)) {
        *state = FloodTable::AWAY;
        continue;
      }
      if (count == seen.size()) {  // not taken; met again, it would only say this again
        overflow = true;
        *state = FloodTable::AWAY;
        continue;
      }
      seen[count++] = nb;
      *state = FloodTable::TAKEN;
    }
  }
  table.clear();
  if (a.l < INF)
    a.result = Refined::hit;
  else
    a.result = overflow ? Refined::unknown : Refined::miss;
  return a;
}

}  // namespace detail

bool mesh_crossing(const SearchContext& ctx, const glm::dvec3& w, const glm::dvec3& dir, uint32_t triangle,
                   double l_near, double radius, uint32_t* crossed, double* l) {
  using namespace detail;
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

}  // namespace abcube
