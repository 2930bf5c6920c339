// Exact ray-triangle queries over a TriangleSoup: a bounding volume hierarchy built with
// the binned surface area heuristic (Wald 2007, "On fast construction of SAH-based
// bounding volume hierarchies"), traversed and intersected in double precision.
//
// Memory: the BVH keeps no copy of the triangles. It reads the soup's float vertices
// (which must outlive it, unchanged) and converts them to double on each test; its nodes
// hold float boxes, exact because every bound is one of those float coordinates. About
// 4 bytes a triangle (the leaf order) plus 32 a node.
//
// Exactness: the float vertices are converted to double exactly; the ray-triangle test is
// the watertight one of Woop, Benthin and Wald 2013 ("Watertight ray/triangle
// intersection", JCGT 2(1)): a ray through a shared edge or vertex of a closed mesh hits at
// least one of the triangles around it, never slips through. The box test is the robust
// slab test (Ize 2013, "Robust BVH ray traversal"; pbrt-v3 Bounds3::IntersectP), whose far
// distance is enlarged by 2 gamma(3) so rounding never culls a box the ray touches.
// A query returns the same hit as a loop over every triangle would (tests check it).
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene_data.hpp"

namespace abcube {

// A ray prepared for the watertight test: the axis kz of the largest direction component,
// kx, ky the other two (swapped to keep the winding), and the shear (sx, sy, sz).
struct RayQuery {
  glm::dvec3 origin{0.0}, dir{0.0}, inv_dir{0.0};
  int kx = 0, ky = 1, kz = 2;
  double sx = 0, sy = 0, sz = 1;
  RayQuery(const glm::dvec3& o, const glm::dvec3& d);
};

// One ray-triangle intersection: origin + t * dir, t > 0, lies on the triangle at
// barycentric weights (b0, b1, b2) of its vertices 0, 1, 2 (sum 1, each >= 0).
struct TriangleHit {
  double t = 0;
  uint32_t triangle = 0;  // index into the TriangleSoup
  double b0 = 0, b1 = 0, b2 = 0;
};

// 32 bytes. The box is a union of float vertex coordinates: float holds it exactly.
struct BvhNode {
  glm::vec3 lo{0.0f}, hi{0.0f};
  uint32_t offset = 0;  // leaf: first slot in the leaf order; inner: index of the second child
  uint16_t count = 0;   // leaf: number of triangles (<= 8); inner: 0 (the first child is this + 1)
  uint16_t axis = 0;    // inner: split axis, to visit the nearer child first
};

class Bvh {
 public:
  // Over every triangle of `soup`, or only over `subset` (triangle indices, ascending) when
  // given. Hits name soup triangles either way. `soup` must outlive the BVH, unchanged.
  explicit Bvh(const TriangleSoup& soup, const std::vector<uint32_t>& subset = {});

  // The nearest hit with 0 < t < tmax (t in units of |dir|). Ties keep the first found.
  bool closest_hit(const RayQuery& ray, double tmax, TriangleHit* hit) const;

  // Calls visit(const TriangleHit&) for every hit with 0 < t < tmax, in no particular
  // (but deterministic) order, until visit returns false.
  template <class Visit>
  void for_each_hit(const RayQuery& ray, double tmax, Visit&& visit) const;

  size_t node_count() const { return nodes_.size(); }
  int depth() const { return depth_; }
  size_t triangle_count() const { return order_.size(); }

  // The watertight test against one soup triangle (Woop et al. 2013), exposed for tests.
  bool intersect_triangle(const RayQuery& ray, uint32_t triangle, double tmax,
                          TriangleHit* hit) const;

 private:
  uint32_t build(std::vector<uint32_t>& items, uint32_t begin, uint32_t end, int depth);
  bool intersect(const RayQuery& ray, uint32_t triangle, double tmax, TriangleHit* hit) const;
  bool intersect_slot(const RayQuery& ray, uint32_t slot, double tmax, TriangleHit* hit) const {
    return intersect(ray, order_[slot], tmax, hit);
  }
  static bool hits_box(const RayQuery& ray, const BvhNode& node, double tmax);

  const TriangleSoup* soup_;
  std::vector<uint32_t> order_;  // slot -> triangle index in the soup, in leaf order
  std::vector<BvhNode> nodes_;   // depth first; node 0 is the root
  int depth_ = 0;
};

// Deepest possible traversal stack: the build falls back to median splits past depth 64,
// so no tree is deeper than 64 + 32 levels.
constexpr int BVH_MAX_STACK = 128;

template <class Visit>
void Bvh::for_each_hit(const RayQuery& ray, double tmax, Visit&& visit) const {
  if (nodes_.empty()) return;
  uint32_t stack[BVH_MAX_STACK];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BvhNode& node = nodes_[stack[--top]];
    if (!hits_box(ray, node, tmax)) continue;
    if (node.count > 0) {
      for (uint32_t s = node.offset; s < node.offset + node.count; ++s) {
        TriangleHit h;
        if (intersect_slot(ray, s, tmax, &h) && !visit(static_cast<const TriangleHit&>(h))) return;
      }
      continue;
    }
    const uint32_t first = static_cast<uint32_t>(&node - nodes_.data()) + 1;
    stack[top++] = node.offset;
    stack[top++] = first;
  }
}

}  // namespace abcube
