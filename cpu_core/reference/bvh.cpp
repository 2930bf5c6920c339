#include "reference/bvh.hpp"

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <limits>
#include <utility>

#include "base/error.hpp"
#include "scene/tie_rule.hpp"

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

// A triangle during construction: its bounds and centroid.
struct BvhBuildItem {
  Bounds box;
  glm::dvec3 centroid{0.0};
  uint32_t triangle = 0;
};

namespace {

struct SahSplit {
  int axis = -1;  // -1: no usable split
  int bin = 0;    // items in bins < bin go left
  double cost = DBL_MAX;
};

int sah_bin(const BvhBuildItem& it, int axis, const Bounds& centroids) {
  const double scale = SAH_BINS / (centroids.hi[axis] - centroids.lo[axis]);
  return std::min(static_cast<int>((it.centroid[axis] - centroids.lo[axis]) * scale), SAH_BINS - 1);
}

// The cheapest binned-SAH split of items[begin, end) over the three axes (Wald 2007):
// cost = TRAVERSAL_COST + (A_left N_left + A_right N_right) / A, in triangle tests.
SahSplit best_sah_split(const std::vector<BvhBuildItem>& items, uint32_t begin, uint32_t end, const Bounds& box,
                        const Bounds& centroids) {
  SahSplit best;
  for (int axis = 0; axis < 3; ++axis) {
    if (!(centroids.hi[axis] - centroids.lo[axis] > 0.0)) continue;
    std::array<Bounds, SAH_BINS> bins;
    std::array<uint32_t, SAH_BINS> counts{};
    for (uint32_t i = begin; i < end; ++i) {
      const int b = sah_bin(items[i], axis, centroids);
      bins[b].extend(items[i].box);
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
uint32_t median_split(std::vector<BvhBuildItem>& items, uint32_t begin, uint32_t end, int axis) {
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(items.begin() + begin, items.begin() + mid, items.begin() + end,
                   [axis](const BvhBuildItem& a, const BvhBuildItem& b) {
                     if (a.centroid[axis] != b.centroid[axis]) return a.centroid[axis] < b.centroid[axis];
                     return a.triangle < b.triangle;
                   });
  return mid;
}

}  // namespace

Bvh::Bvh(const TriangleSoup& soup) {
  const size_t n = soup.triangle_count();
  ABCUBE_CHECK(soup.positions.size() == 3 * n, "positions must hold 3 vertices per triangle");
  ABCUBE_CHECK(n < UINT32_MAX / 3, "too many triangles for 32-bit indices");
  if (n == 0) return;
  std::vector<BvhBuildItem> items(n);
  for (size_t i = 0; i < n; ++i) {
    Bounds b;
    for (int k = 0; k < 3; ++k) b.extend(glm::dvec3(soup.positions[3 * i + k]));
    items[i] = {b, 0.5 * (b.lo + b.hi), static_cast<uint32_t>(i)};
  }
  nodes_.reserve(2 * n);
  order_.reserve(n);
  build(items, 0, static_cast<uint32_t>(n), 0);
  vertices_.resize(3 * n);
  slot_of_.assign(n, 0);
  double magnitude = 0.0;
  for (uint32_t t = 0; t < n; ++t) magnitude = std::max(magnitude, triangle_magnitude(soup, t));
  tie_bound_max_ = TIE_RELATIVE * magnitude;
  for (uint32_t s = 0; s < n; ++s) {
    slot_of_[order_[s]] = s;
    for (int k = 0; k < 3; ++k) vertices_[3 * s + k] = glm::dvec3(soup.positions[3 * order_[s] + k]);
  }
}

// Builds the subtree over items[begin, end) and returns its node index (depth first).
uint32_t Bvh::build(std::vector<BvhBuildItem>& items, uint32_t begin, uint32_t end, int depth) {
  const uint32_t index = static_cast<uint32_t>(nodes_.size());
  nodes_.emplace_back();
  depth_ = std::max(depth_, depth + 1);
  Bounds box, centroids;
  for (uint32_t i = begin; i < end; ++i) {
    box.extend(items[i].box);
    centroids.extend(items[i].centroid);
  }
  nodes_[index].lo = box.lo;
  nodes_[index].hi = box.hi;
  const uint32_t count = end - begin;
  const glm::dvec3 extent = centroids.hi - centroids.lo;
  const int widest = extent.x > extent.y ? (extent.x > extent.z ? 0 : 2) : (extent.y > extent.z ? 1 : 2);
  const SahSplit split = depth < SAH_DEPTH_LIMIT && count > 2 ? best_sah_split(items, begin, end, box, centroids)
                                                              : SahSplit{};
  const bool leaf_is_cheaper = split.axis >= 0 && split.cost >= static_cast<double>(count);
  const bool cannot_split = !(extent[widest] > 0.0);  // coincident centroids
  if (count <= 2 || (count <= MAX_LEAF && (leaf_is_cheaper || cannot_split))) {
    nodes_[index].offset = static_cast<uint32_t>(order_.size());
    nodes_[index].count = count;
    for (uint32_t i = begin; i < end; ++i) order_.push_back(items[i].triangle);
    return index;
  }
  uint32_t mid = begin;
  if (split.axis >= 0) {
    auto goes_left = [&](const BvhBuildItem& it) { return sah_bin(it, split.axis, centroids) < split.bin; };
    mid = static_cast<uint32_t>(std::stable_partition(items.begin() + begin, items.begin() + end, goes_left) -
                                items.begin());
  }
  if (mid == begin || mid == end) mid = median_split(items, begin, end, widest);  // no SAH split, or too deep
  nodes_[index].axis = static_cast<uint32_t>(split.axis >= 0 ? split.axis : widest);
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
    double tn = (node.lo[a] - ray.origin[a]) * ray.inv_dir[a];
    double tf = (node.hi[a] - ray.origin[a]) * ray.inv_dir[a];
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
bool Bvh::intersect_slot(const RayQuery& ray, uint32_t slot, double tmax, TriangleHit* hit) const {
  const glm::dvec3 a = vertices_[3 * slot] - ray.origin;
  const glm::dvec3 b = vertices_[3 * slot + 1] - ray.origin;
  const glm::dvec3 c = vertices_[3 * slot + 2] - ray.origin;
  const double ax = a[ray.kx] - ray.sx * a[ray.kz], ay = a[ray.ky] - ray.sy * a[ray.kz];
  const double bx = b[ray.kx] - ray.sx * b[ray.kz], by = b[ray.ky] - ray.sy * b[ray.kz];
  const double cx = c[ray.kx] - ray.sx * c[ray.kz], cy = c[ray.ky] - ray.sy * c[ray.kz];
  const double u = cx * by - cy * bx;
  const double v = ax * cy - ay * cx;
  const double w = bx * ay - by * ax;
  if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) return false;
  const double det = u + v + w;
  if (det == 0.0) return false;
  const double t_scaled = ray.sz * (u * a[ray.kz] + v * b[ray.kz] + w * c[ray.kz]);
  if (det > 0.0 ? (t_scaled <= 0.0 || t_scaled >= tmax * det)
                : (t_scaled >= 0.0 || t_scaled <= tmax * det)) {
    return false;
  }
  const double inv_det = 1.0 / det;
  hit->t = t_scaled * inv_det;
  hit->triangle = order_[slot];
  hit->b0 = u * inv_det;
  hit->b1 = v * inv_det;
  hit->b2 = w * inv_det;
  return true;
}

bool Bvh::intersect_triangle(const RayQuery& ray, uint32_t triangle, double tmax,
                             TriangleHit* hit) const {
  ABCUBE_CHECK(triangle < slot_of_.size(), "triangle index out of range");
  return intersect_slot(ray, slot_of_[triangle], tmax, hit);
}

// Front-to-back traversal: on_hit(const TriangleHit&) for every hit with t < cull, `cull`
// re-read after each (the caller's callback narrows it).
template <class OnHit>
void Bvh::traverse_near_first(const RayQuery& ray, const double& cull, OnHit&& on_hit) const {
  uint32_t stack[BVH_MAX_STACK];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const uint32_t index = stack[--top];
    const BvhNode& node = nodes_[index];
    if (!hits_box(ray, node, cull)) continue;
    if (node.count > 0) {
      for (uint32_t s = node.offset; s < node.offset + node.count; ++s) {
        TriangleHit h;
        if (intersect_slot(ray, s, cull, &h)) on_hit(static_cast<const TriangleHit&>(h));
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
}

bool Bvh::closest_hit(const RayQuery& ray, double tmax, TriangleHit* hit) const {
  if (nodes_.empty()) return false;
  bool found = false;
  traverse_near_first(ray, tmax, [&](const TriangleHit& h) {
    *hit = h;
    tmax = h.t;
    found = true;
  });
  return found;
}

bool Bvh::visible_hit(const RayQuery& ray, double tmax, const TriangleSoup& soup, TriangleHit* hit) const {
  if (nodes_.empty()) return false;
  constexpr double INF = std::numeric_limits<double>::infinity();
  constexpr int KEEP = 8;
  std::array<TriangleHit, KEEP> kept;
  int n_kept = 0;
  bool incomplete = false, found = false;
  TriangleHit nearest;
  double cull = tmax;  // every hit with t < cull is found
  // The end of the tie window of a hit: no surface beyond it can be at its distance.
  const auto window_end = [&](const TriangleHit& h) {
    const double c = std::fabs(glm::dot(tie_normal(soup, h.triangle), ray.dir));
    const double end = c > 0.0 ? std::nextafter(h.t + tie_bound_max_ / c, INF) : INF;
    return std::min(tmax, end);
  };
  const auto add = [&](const TriangleHit& h) {
    if (!found || h.t < nearest.t || (h.t == nearest.t && ranks_above(soup, h.triangle, nearest.triangle))) {
      const double end = window_end(h);
      if (found && end > cull) incomplete = true;  // hits culled before may lie in the new window
      nearest = h;
      found = true;
      cull = end;
      int w = 0;
      for (int i = 0; i < n_kept; ++i) {
        if (kept[static_cast<size_t>(i)].t < cull) kept[static_cast<size_t>(w++)] = kept[static_cast<size_t>(i)];
      }
      n_kept = w;
    }
    if (n_kept < KEEP) {
      kept[static_cast<size_t>(n_kept++)] = h;
    } else {
      incomplete = true;
    }
  };
  traverse_near_first(ray, cull, add);
  if (!found) return false;
  const SurfaceAt near_at{nearest.triangle, nearest.t};
  TriangleHit best = nearest;
  const auto consider = [&](const TriangleHit& h) {
    if (ranks_above(soup, h.triangle, best.triangle) && same_distance(soup, ray.dir, near_at, {h.triangle, h.t})) best = h;
    return true;
  };
  if (incomplete) {
    for_each_hit(ray, cull, consider);  // the nearest hit's whole window, again
  } else {
    for (int i = 0; i < n_kept; ++i) consider(kept[static_cast<size_t>(i)]);
  }
  *hit = best;
  return true;
}

}  // namespace abcube
