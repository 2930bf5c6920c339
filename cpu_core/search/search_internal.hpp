// Internal to the search stage (search.hpp): what its files share. The walk's counts, one fragment's answer (a
// candidate), the mesh refinement's answer, and the functions one file defines for the others. Not part of the stage's
// API.
#pragma once
#include <array>
#include <cstdint>
#include <limits>
#include <memory>

#include <glm/glm.hpp>

#include "raster/abuffer.hpp"
#include "search/cube_walk.hpp"
#include "search/search.hpp"

namespace abcube::detail {

constexpr double INF = std::numeric_limits<double>::infinity();

// MEMO. The refinement asks for the same triangles' geometry again and again: neighbouring
// rays refine on the same patch, and a flood meets each triangle from up to three sides, so
// nearly every ask is for a triangle among the last few thousand its own thread asked for.
// Each thread keeps the values it computed last, for one context at a time
// (SearchContext::memo_id, never reused), in 4096 slots by a hash of the triangle: the
// values are the functions' own, so every answer is the same bit for bit, for any thread
// count. The slots are a fixed cost a thread that searches, whatever the scene's size.
// Inline: a flood asks several times a triangle it tests.
template <class Value>
class Memo {
 public:
  // This thread's memo of Values for ctx's triangles.
  static Memo& of(const SearchContext& ctx) {
    thread_local std::unique_ptr<Memo> memo;
    if (!memo) memo = std::make_unique<Memo>();
    if (memo->context_ != ctx.memo_id()) {
      memo->context_ = ctx.memo_id();
      for (Slot& slot : memo->slots_) slot.triangle = NONE;
    }
    return *memo;
  }
  // The value of `triangle`, compute() where the slot holds another's. It stays in its slot
  // until this thread's next ask.
  template <class Compute>
  const Value& get(uint32_t triangle, Compute&& compute) {
    Slot& slot = slots_[(triangle * 2654435761u) >> (32 - BITS)];  // Knuth's multiplicative hash
    if (slot.triangle != triangle) {
      slot.value = compute();
      slot.triangle = triangle;
    }
    return slot.value;
  }

 private:
  static constexpr int BITS = 12;
  static constexpr uint32_t NONE = 0xffffffffu;
  // A slot's triangle beside its value: one look-up reads one place, not two arrays.
  struct Slot {
    uint32_t triangle;
    Value value;
  };
  uint64_t context_ = 0;
  std::array<Slot, size_t{1} << BITS> slots_;
};

// A triangle's edge planes and bounding sphere (SearchContext::compute_edge_planes,
// compute_bounding_sphere) from this thread's MEMO.
inline const SearchContext::EdgePlanes& edge_planes(const SearchContext& ctx, uint32_t tri) {
  return Memo<SearchContext::EdgePlanes>::of(ctx).get(tri, [&] { return ctx.compute_edge_planes(tri); });
}
inline const SearchContext::Sphere& bounding_sphere(Memo<SearchContext::Sphere>& spheres, const SearchContext& ctx,
                                                    uint32_t tri) {
  return spheres.get(tri, [&] { return ctx.compute_bounding_sphere(tri); });
}

// May a surface of `object` answer this ray? Any, unless it is a refraction exit from inside
// q.object: then that object's own surfaces and those of the objects whose bounding boxes
// meet its (media.hpp): every surface the exact ray can cross before leaving q.object.
inline bool allowed(const SearchContext& ctx, const SearchRay& q, uint32_t object) {
  return !q.restrict_object || object == q.object || ctx.media().bounds_meet(object, q.object);
}

// What the walk over the map saw of one ray.
struct ScanCounts {
  uint32_t texels = 0, fragments = 0, candidates = 0;
  uint32_t mesh_triangles = 0;  // MESH REFINEMENT's crossing tests (counted by the search)
  uint32_t nodes = 0;           // pyramid nodes stepped over (HIERARCHICAL SKIP)
  bool aborted = false;
};

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
  uint32_t mesh_triangles = 0;  // MESH REFINEMENT's crossing tests for it
};

// Where the ray meets triangle `tri`'s plane: l (INF when parallel or degenerate) and the
// edge whose line the point lies furthest outside of, in the plane, by more than
// ON_TRIANGLE_TEXELS (-1: on the triangle; near a corner this admits up to the tolerance
// times 1/sin(corner angle / 2)).
struct PlaneCrossing {
  double l = INF;
  // -1: on the triangle (within ON_TRIANGLE_TEXELS); 0 to 2: the edge it lies furthest
  // outside of; NOT_TESTED: l outside the range asked, the edges not looked at.
  int outside_edge = -1;
  static constexpr int NOT_TESTED = 3;
};

// The crossing of the ray with triangle `tri`'s plane (search_refine.cpp); where it is on
// the triangle only when l lies in [l_lo, l_hi].
PlaneCrossing plane_crossing(const SearchContext& ctx, const SearchRay& q, uint32_t tri, double l_lo = -INF,
                             double l_hi = INF);

// MESH REFINEMENT (crossing mode; docs/design/search.md). The answer of the mesh around a
// fragment's triangle when the ray does not cross that triangle itself.
enum class Refined { hit, miss, unknown };
struct MeshAnswer {
  Refined result = Refined::unknown;
  uint32_t triangle = 0;
  double l = INF;
  uint32_t tested = 0;  // triangles tested for a crossing (the walk's steps and the flood's)
};

// MESH REFINEMENT: the crossing of the ray with the mesh around `start` (search_refine.cpp).
MeshAnswer refine_on_mesh(const SearchContext& ctx, const SearchRay& q, uint32_t start, double l_lo, double l_hi,
                          double radius);

// A fragment's candidate in crossing mode (MODE crossing, docs/design/search.md) and in thesis
// mode (thesis 7.4.1, 9.3.4) (search_candidates.cpp); `p` is its triangle's plane (the walk
// computed it for the own-surface test).
Candidate crossing_candidate(const SearchContext& ctx, const SearchRay& q, const SearchOptions& o, const WalkTexel& t,
                             const Fragment& f, const SearchContext::Plane& p);
Candidate thesis_candidate(const SearchRay& q, const WalkTexel& t, const Fragment& f, const glm::dvec3& v,
                           const SearchContext::Plane& p);

// Does the exact ray meet a triangle the map cannot hold before parameter l_end?
bool meets_zero_area(const SearchContext& ctx, const SearchRay& q, double l_end);

// A side triangle the ray crosses (THE SIDE STRUCTURE), and its facing (docs/design/search.md).
struct SideCrossing {
  uint32_t triangle = 0;
  double l = INF;
  bool back_face = false;
};

// Is the side crossing (tri, l) one the search takes? Past the self offset, not W's own
// surface, and in the object a refraction exit is restricted to.
bool side_crossing_counts(const SearchContext& ctx, const SearchRay& q, uint32_t tri, double l);

// Its facing: as the map gives it (seen from the centre), or, for a plane through the
// centre, the ray's direction against the geometric normal.
bool side_back_face(const SearchContext& ctx, const SearchRay& q, uint32_t tri);

// The nearest side crossing with l < l_end (l = INF when none or the option is off).
SideCrossing nearest_side_crossing(const SearchContext& ctx, const SearchRay& q, double l_end);

// The answer: the chosen candidate or a miss (`miss` unless the walk was aborted); a side
// triangle crossed before it answers instead (THE SIDE STRUCTURE); without the side
// structure, a zero-area surface met before it turns it into a zero-area miss.
SearchResult finish(const SearchContext& ctx, const SearchRay& q, const Candidate* best, MissReason miss,
                    const ScanCounts& counts);

}  // namespace abcube::detail
