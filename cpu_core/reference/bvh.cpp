#include "reference/bvh.hpp"

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <utility>

#include "base/error.hpp"

namespace abcube {

namespace {

constexpr int SAH_BINS = 16;
constexpr uint32_t MAX_LEAF = 8;          // largest leaf the SAH may choose
constexpr int SAH_DEPTH_LIMIT = 64;       // past this depth: median splits only
constexpr double TRAVERSAL_COST = 1.0;    // relative to one triangle test

// pbrt-v3 gamma(n) = n u / (1 - n u), u the unit roundoff of double (Higham 2002).
constexpr double gamma_n(int n) {
  const double u = DBL_EPSILON * 0.5;
  return n * u / (1.0 - n * u);
}
constexpr double BOX_FAR_SCALE = 1.0 + 2.0 * gamma_n(3);  // Ize 2013, pbrt-v3 3.9.2

}  // namespace

RayQuery::RayQuery(const glm::dvec3& o, const glm::dvec3& d) : origin(o), dir(d) {
  // Woop et al. 2013, section 3: permute so that z is the largest direction component,
  // swap x and y when that component is negative (keeps the winding), then shear.
  const glm::dvec3 a = glm::abs(d);
  kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
  kx = (kz + 1) % 3;
  ky = (kx + 1) % 3;
  if (d[kz] < 0.0) std::swap(kx, ky);
  sx = d[kx] / d[kz];
  sy = d[ky] / d[kz];
  sz = 1.0 / d[kz];
  inv_dir = glm::dvec3(1.0) / d;
}

namespace {

// A triangle during construction is its index (4 bytes): its bounds are read from the
// soup's float vertices when needed (float holds them exactly), its centroid in double.
struct BuildBoxes {
  const glm::vec3* positions;
  Bounds box(uint32_t t) const {
    const glm::vec3* v = positions + 3 * static_cast<size_t>(t);
    Bounds b;
    b.lo = glm::dvec3(glm::min(v[0], glm::min(v[1], v[2])));
    b.hi = glm::dvec3(glm::max(v[0], glm::max(v[1], v[2])));
    return b;
  }
  glm::dvec3 centroid(uint32_t t) const {
    const Bounds b = box(t);
    return 0.5 * (b.lo + b.hi);
  }
};

}  // namespace

namespace {

struct SahSplit {
  int axis = -1;  // -1: no usable split
  int bin = 0;    // items in bins < bin go left
  double cost = DBL_MAX;
};

int sah_bin(const BuildBoxes& boxes, uint32_t it, int axis, const Bounds& centroids) {
  const double scale = SAH_BINS / (centroids.hi[axis] - centroids.lo[axis]);
  return std::min(static_cast<int>((boxes.centroid(it)[axis] - centroids.lo[axis]) * scale), SAH_BINS - 1);
}

// The cheapest binned-SAH split of items[begin, end) over the three axes (Wald 2007):
// cost = TRAVERSAL_COST + (A_left N_left + A_right N_right) / A, in triangle tests.
SahSplit best_sah_split(const BuildBoxes& boxes, const std::vector<uint32_t>& items, uint32_t begin, uint32_t end, const Bounds& box,
                        const Bounds& centroids) {
  SahSplit best;
  for (int axis = 0; axis < 3; ++axis) {
    if (!(centroids.hi[axis] - centroids.lo[axis] > 0.0)) continue;
    std::array<Bounds, SAH_BINS> bins;
    std::array<uint32_t, SAH_BINS> counts{};
    for (uint32_t i = begin; i < end; ++i) {
      const int b = sah_bin(boxes, items[i], axis, centroids);
      bins[b].extend(boxes.box(items[i]));
      ++counts[b];
    }
    // Sweep from the right for the right-hand areas, then from the left.
    std::array<double, SAH_BINS> right_area{};
    std::array<uint32_t, SAH_BINS> right_count{};
    Bounds acc;
    uint32_t acc_n = 0;
    for (int b = SAH_BINS - 1; b > 0; --b) {
      acc.extend(bins[b]);
      acc_n += counts[b];
      right_area[b] = acc.area();
      right_count[b] = acc_n;
    }
    Bounds left;
    uint32_t left_n = 0;
    for (int b = 1; b < SAH_BINS; ++b) {
      left.extend(bins[b - 1]);
      left_n += counts[b - 1];
      if (left_n == 0 || right_count[b] == 0) continue;
      const double cost = TRAVERSAL_COST + (left.area() * left_n + right_area[b] * right_count[b]) / box.area();
      if (cost < best.cost) best = {axis, b, cost};
    }
  }
  return best;
}

// Splits items[begin, end) at their median along `axis` (ties broken by triangle index).
uint32_t median_split(const BuildBoxes& boxes, std::vector<uint32_t>& items, uint32_t begin, uint32_t end, int axis) {
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(items.begin() + begin, items.begin() + mid, items.begin() + end,
                   [&boxes, axis](uint32_t a, uint32_t b) {
                     const double ca = boxes.centroid(a)[axis], cb = boxes.centroid(b)[axis];
                     if (ca != cb) return ca < cb;
                     return a < b;
                   });
  return mid;
}

}  // namespace

Bvh::Bvh(const TriangleSoup& soup, const std::vector<uint32_t>& subset) : soup_(&soup) {
  const size_t all = soup.triangle_count();
  ABCUBE_CHECK(soup.positions.size() == 3 * all, "positions must hold 3 vertices per triangle");
  ABCUBE_CHECK(all < UINT32_MAX / 3, "too many triangles for 32-bit indices");
  const bool whole = subset.empty();
  const size_t n = whole ? all : subset.size();
  if (n == 0) return;
  // The leaves take the items in order, so the items once built are the leaf order.
  std::vector<uint32_t> items(n);
  for (size_t i = 0; i < n; ++i) {
    const uint32_t t = whole ? static_cast<uint32_t>(i) : subset[i];
    ABCUBE_CHECK(t < all && (i == 0 || whole || subset[i - 1] < t), "subset must be ascending soup triangles");
    items[i] = t;
  }
  nodes_.reserve(2 * n);  // untouched room costs no memory
  build(items, 0, static_cast<uint32_t>(n), 0);
  order_ = std::move(items);
}

// Builds the subtree over items[begin, end) and returns its node index (depth first).
uint32_t Bvh::build(std::vector<uint32_t>& items, uint32_t begin, uint32_t end, int depth) {
  const BuildBoxes boxes{soup_->positions.data()};
  const uint32_t index = static_cast<uint32_t>(nodes_.size());
  nodes_.emplace_back();
  depth_ = std::max(depth_, depth + 1);
  Bounds box, centroids;
  for (uint32_t i = begin; i < end; ++i) {
    box.extend(boxes.box(items[i]));
    centroids.extend(boxes.centroid(items[i]));
  }
  nodes_[index].lo = glm::vec3(box.lo);  // exact: float coordinates
  nodes_[index].hi = glm::vec3(box.hi);
  const uint32_t count = end - begin;
  const glm::dvec3 extent = centroids.hi - centroids.lo;
  const int widest = extent.x > extent.y ? (extent.x > extent.z ? 0 : 2) : (extent.y > extent.z ? 1 : 2);
  const SahSplit split = depth < SAH_DEPTH_LIMIT && count > 2 ? best_sah_split(boxes, items, begin, end, box, centroids)
                                                              : SahSplit{};
  const bool leaf_is_cheaper = split.axis >= 0 && split.cost >= static_cast<double>(count);
  const bool cannot_split = !(extent[widest] > 0.0);  // coincident centroids
  if (count <= 2 || (count <= MAX_LEAF && (leaf_is_cheaper || cannot_split))) {
    nodes_[index].offset = begin;  // leaves come left to right: slots [begin, end)
    nodes_[index].count = static_cast<uint16_t>(count);
    return index;
  }
  uint32_t mid = begin;
  if (split.axis >= 0) {
    auto goes_left = [&](uint32_t it) { return sah_bin(boxes, it, split.axis, centroids) < split.bin; };
    mid = static_cast<uint32_t>(std::stable_partition(items.begin() + begin, items.begin() + end, goes_left) -
                                items.begin());
  }
  if (mid == begin || mid == end) mid = median_split(boxes, items, begin, end, widest);  // no SAH split, or too deep
  nodes_[index].axis = static_cast<uint16_t>(split.axis >= 0 ? split.axis : widest);
  build(items, begin, mid, depth + 1);
  const uint32_t second = build(items, mid, end, depth + 1);
  nodes_[index].offset = second;
  nodes_[index].count = 0;
  return index;
}

// Robust slab test (Ize 2013; pbrt-v3 Bounds3::IntersectP). NaN from 0 * inf leaves the
// interval unchanged, which is the right answer for a ray in a slab's boundary plane.
bool Bvh::hits_box(const RayQuery& ray, const BvhNode& node, double tmax) {
  double t0 = 0.0, t1 = tmax;
  for (int a = 0; a < 3; ++a) {
    double tn = (static_cast<double>(node.lo[a]) - ray.origin[a]) * ray.inv_dir[a];
    double tf = (static_cast<double>(node.hi[a]) - ray.origin[a]) * ray.inv_dir[a];
    if (tn > tf) std::swap(tn, tf);
    tf *= BOX_FAR_SCALE;
    t0 = tn > t0 ? tn : t0;
    t1 = tf < t1 ? tf : t1;
    if (t0 > t1) return false;
  }
  return true;
}

// Woop, Benthin, Wald 2013, "Watertight ray/triangle intersection", figure 10,
// without back-face culling, in double precision.
bool Bvh::intersect_triangle(const RayQuery& ray, uint32_t triangle, double tmax, TriangleHit* hit) const {
  ABCUBE_CHECK(triangle < soup_->triangle_count(), "triangle index out of range");
  return intersect(ray, triangle, tmax, hit);
}

bool Bvh::intersect(const RayQuery& ray, uint32_t triangle, double tmax, TriangleHit* hit) const {
  const glm::vec3* v = &soup_->positions[3 * static_cast<size_t>(triangle)];
  const glm::dvec3 a = glm::dvec3(v[0]) - ray.origin;
  const glm::dvec3 b = glm::dvec3(v[1]) - ray.origin;
  const glm::dvec3 c = glm::dvec3(v[2]) - ray.origin;
  const double ax = a[ray.kx] - ray.sx * a[ray.kz], ay = a[ray.ky] - ray.sy * a[ray.kz];
  const double bx = b[ray.kx] - ray.sx * b[ray.kz], by = b[ray.ky] - ray.sy * b[ray.kz];
  const double cx = c[ray.kx] - ray.sx * c[ray.kz], cy = c[ray.ky] - ray.sy * c[ray.kz];
  const double u = cx * by - cy * bx;
  const double v_ = ax * cy - ay * cx;
  const double w = bx * ay - by * ax;
  if ((u < 0.0 || v_ < 0.0 || w < 0.0) && (u > 0.0 || v_ > 0.0 || w > 0.0)) return false;
  const double det = u + v_ + w;
  if (det == 0.0) return false;
  const double t_scaled = ray.sz * (u * a[ray.kz] + v_ * b[ray.kz] + w * c[ray.kz]);
  if (det > 0.0 ? (t_scaled <= 0.0 || t_scaled >= tmax * det)
                : (t_scaled >= 0.0 || t_scaled <= tmax * det)) {
    return false;
  }
  const double inv_det = 1.0 / det;
  hit->t = t_scaled * inv_det;
  hit->triangle = triangle;
  hit->b0 = u * inv_det;
  hit->b1 = v_ * inv_det;
  hit->b2 = w * inv_det;
  return true;
}

bool Bvh::closest_hit(const RayQuery& ray, double tmax, TriangleHit* hit) const {
  if (nodes_.empty()) return false;
  bool found = false;
  uint32_t stack[BVH_MAX_STACK];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const uint32_t index = stack[--top];
    const BvhNode& node = nodes_[index];
    if (!hits_box(ray, node, tmax)) continue;
    if (node.count > 0) {
      for (uint32_t s = node.offset; s < node.offset + node.count; ++s) {
        if (intersect_slot(ray, s, tmax, hit)) {
          tmax = hit->t;
          found = true;
        }
      }
      continue;
    }
    // Visit the child on the ray's near side first: push it last.
    if (ray.dir[static_cast<int>(node.axis)] < 0.0) {
      stack[top++] = index + 1;
      stack[top++] = node.offset;
    } else {
      stack[top++] = node.offset;
      stack[top++] = index + 1;
    }
  }
  return found;
}

}  // namespace abcube
