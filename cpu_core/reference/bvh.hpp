// Exact ray queries over a TriangleSoup: Embree 3 (Wald et al. 2014) builds and traverses
// the bounding volume hierarchy over user primitives whose float boxes are widened by
// BOX_PAD, and every hit is decided in double precision by the watertight test of
// triangle_test.hpp: Embree's float arithmetic never decides whether a triangle is hit, so
// a query's hits are exactly the triangles the double test accepts, whatever instruction
// set, thread count or traversal order. Over BUILD_CHUNK triangles the tree is built a chunk
// at a time (the build's peak is one chunk's). Queries are const and thread safe.
// docs/design/bvh.md has the whole argument: why not Embree's float triangles, the bound.
#pragma once
#include <cstdint>
#include <type_traits>
#include <vector>

#include "reference/triangle_test.hpp"
#include "scene/scene_data.hpp"

struct RTCSceneTy;  // <embree3/rtcore.h>: RTCScene is RTCSceneTy*

namespace abcube {

class Bvh {
 public:
  // Builds Embree's tree over `soup`, which is read by every query, never copied: it must
  // outlive the Bvh and not change. Throws RuntimeFailure when Embree fails (std::bad_alloc
  // when out of memory). `build_chunk`: the triangles built over at once (docs/design/bvh.md
  // "Memory"; tests set it small).
  explicit Bvh(const TriangleSoup& soup, uint32_t build_chunk = BUILD_CHUNK);
  // The same over the soup's triangles `triangles` only (hits name them by their index in
  // the soup; the searches' side structure).
  Bvh(const TriangleSoup& soup, std::vector<uint32_t> triangles, uint32_t build_chunk = BUILD_CHUNK);
  ~Bvh();
  Bvh(const Bvh&) = delete;
  Bvh& operator=(const Bvh&) = delete;

  // The VISIBLE hit with 0 < t < tmax (t in units of |dir|) by THE TIE RULE
  // (scene/tie_rule.hpp): of the hits at the same distance as the nearest one (the nearest:
  // smallest t, then ranking above), the one ranking highest (later object, then higher
  // triangle). Same answer as that rule applied to a loop over every triangle: one
  // traversal culling at the nearest hit's tie window (tie_bound over the whole soup
  // divided by |n . dir|), keeping the hits inside it; when the window of a new nearest hit
  // reaches past what was culled before, or more than a few hits share it, a second
  // traversal collects that window again.
  bool visible_hit(const RayQuery& ray, double tmax, TriangleHit* hit) const;

  // Calls visit(const TriangleHit&) for every hit with 0 < t < tmax, once each, in no
  // particular order (Embree's traversal order: callers that need one sort), until visit
  // returns false.
  template <class Visit>
  void for_each_hit(const RayQuery& ray, double tmax, Visit&& visit) const {
    using V = std::remove_reference_t<Visit>;
    visit_hits(
        ray, tmax, [](void* state, const TriangleHit& h) { return static_cast<bool>((*static_cast<V*>(state))(h)); },
        const_cast<void*>(static_cast<const void*>(&visit)));
  }

  // TIE_RELATIVE times the largest absolute vertex coordinate of its triangles
  // (tie_rule.hpp): no two of them are at the same distance beyond this separation along
  // their normals.
  double tie_bound_max() const { return tie_bound_max_; }
  size_t triangle_count() const { return all_ ? soup_->triangle_count() : triangles_.size(); }
  // Its k-th triangle's index in the soup.
  uint32_t triangle(uint32_t k) const { return all_ ? k : triangles_[k]; }
  // The soup's triangles it was built over (the second constructor), ascending as given;
  // empty for the whole soup.
  const std::vector<uint32_t>& subset() const { return triangles_; }
  const TriangleSoup& soup() const { return *soup_; }
  // The largest absolute vertex coordinate, M.
  double magnitude() const { return magnitude_; }

  // Widening of every primitive box, relative to the largest absolute vertex coordinate.
  static constexpr double BOX_PAD = 0x1p-16;
  // Triangles a tree is built over at once (docs/design/bvh.md "Memory").
  static constexpr uint32_t BUILD_CHUNK = uint32_t{1} << 18;
  // A run of its triangles, Embree's user data for their geometry: primitive k of it is
  // triangle(first + k).
  struct Chunk {
    const Bvh* bvh;
    uint32_t first;
  };

 private:
  using VisitFn = bool (*)(void* state, const TriangleHit& hit);
  void visit_hits(const RayQuery& ray, double tmax, VisitFn visit, void* state) const;
  void build(uint32_t build_chunk);

  const TriangleSoup* soup_;
  bool all_ = true;  // every triangle of the soup, else triangles_
  std::vector<uint32_t> triangles_;
  std::vector<Chunk> chunks_;
  RTCSceneTy* scene_ = nullptr;  // null when there is nothing to hit
  double magnitude_ = 0;         // the largest absolute vertex coordinate, M
  double unit_ = 1;              // Embree's units: 2^-ilogb(M) (docs/design/bvh.md "Exactness")
  double tie_bound_max_ = 0;     // TIE_RELATIVE * M
};

}  // namespace abcube
