// Exact ray queries over a TriangleSoup: Embree 3 (Wald et al. 2014, "Embree: a kernel
// framework for efficient CPU ray tracing") builds and traverses the bounding volume
// hierarchy, and every hit is decided in double precision by the watertight test of
// triangle_test.hpp. Embree's float arithmetic never decides whether a triangle is hit.
//
// How. Each triangle is an Embree user primitive (RTC_GEOMETRY_TYPE_USER) whose box is the
// triangle's float bounds widened by BOX_PAD below; leaves hold up to 4 primitives (device
// option object_accel_max_leaf_size), the scene is built with RTC_SCENE_FLAG_COMPACT and
// RTC_SCENE_FLAG_ROBUST (the latter is not read by Embree's user-geometry traversal, whose
// box test is the fast one: the padding below covers its rounding). Embree hands every
// triangle whose box the ray meets to a callback that runs the double test, and culls at
// the distance the callback sets. Nothing of the soup is copied: Embree holds its tree only.
//
// Why not Embree's float triangles (RTC_GEOMETRY_TYPE_TRIANGLE). Its robust float test is
// watertight, but where a ray passes within float rounding of an edge it can pick the
// other triangle of the edge, which the double test rejects, or, at an open border, none,
// where the double test hits: bench/bench_embree_float counts those rays on the
// repository scenes (README "Exact tracer on Embree"). Recovering them would take a second
// traversal per query for the tie window and neighbourhood queries, and still miss the
// open borders.
//
// Exactness. A query's hits are exactly the triangles the double test accepts (a loop over
// every triangle gives the same; tests check it), because no box that the double ray meets
// is culled. Embree works in units of 2^ilogb(M), M the largest absolute vertex coordinate,
// so that every vertex lies within 2 of the origin (no overflow of org/dir products in its
// box test, no denormals); below, distances are in units of M.
//  - Embree's ray is the double ray rounded to float: its origin is the query's origin
//    when that lies in the cube |x|inf <= 2M, else the ray's entry point into that cube
//    (no triangle lies before it), so |o_e| <= 2M; at any point x of a triangle (|x| <= M)
//    the float ray is within 2^-24 (|o_e| + |x - o_e|) <= 5 2^-24 per coordinate.
//  - Embree's box test, t = (lower - org) / dir computed as lower * rcp(dir) - org *
//    rcp(dir) in float, with rcp good to about 2^-22, errs by at most about
//    2^-24 |org| + 2^-22 |lower - org| <= 17 2^-24 per coordinate, along the ray.
//  - Every box is widened by BOX_PAD = 2^-16 = 256 2^-24, over ten times their sum, and
//    rounded outwards (tests/core/test_raytrace.cpp, rays aimed at edges: lost hits with
//    no widening and with 2^-24, none from 2^-21).
// So the answers do not depend on which instruction set Embree picks (SSE, AVX2, AVX-512),
// the threads that built the tree, or the order the tree is walked in.
//
// Memory. Embree holds, besides its tree, 32 bytes of primitive references a triangle and
// its builder's scratch while it builds (a peak of about 60 bytes a triangle above the
// tree, the map methods' largest, bench/memory.py). Over more than BUILD_CHUNK triangles the
// tree is built a chunk of consecutive triangles at a time, each chunk its own scene, held
// by an identity instance of the top scene (a transform exact in float): the build's peak
// is one chunk's. The answers are the same: every box the ray meets is still visited.
//
// Thread safety: queries are const and may run from any number of threads at once (one
// RTCScene, read only; a context per call).
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
  // when out of memory).
  // `build_chunk`: the triangles built over at once ("Memory" above; tests set it small).
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
    visit_hits(ray, tmax,
               [](void* state, const TriangleHit& h) { return static_cast<bool>((*static_cast<V*>(state))(h)); },
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
  // Triangles a tree is built over at once (bvh.hpp "Memory").
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
  bool all_ = true;                 // every triangle of the soup, else triangles_
  std::vector<uint32_t> triangles_;
  std::vector<Chunk> chunks_;
  RTCSceneTy* scene_ = nullptr;  // null when there is nothing to hit
  double magnitude_ = 0;         // the largest absolute vertex coordinate, M
  double unit_ = 1;              // Embree's units: 2^-ilogb(M) (bvh.hpp "Exactness")
  double tie_bound_max_ = 0;     // TIE_RELATIVE * M
};

}  // namespace abcube
