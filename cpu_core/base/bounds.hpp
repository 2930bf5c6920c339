// An axis-aligned bounding box: the scene's extent, the BVH's nodes and SAH bins.
#pragma once
#include <cfloat>

#include <glm/glm.hpp>

namespace abcube {

struct Bounds {
  glm::dvec3 lo{DBL_MAX}, hi{-DBL_MAX};  // empty: lo > hi
  bool empty() const { return lo.x > hi.x; }
  void extend(const glm::dvec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void extend(const Bounds& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  // Surface area (the SAH's cost weight, Wald 2007); 0 when empty.
  double area() const {
    if (empty()) return 0.0;
    const glm::dvec3 e = hi - lo;
    return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
  }
};

}  // namespace abcube
