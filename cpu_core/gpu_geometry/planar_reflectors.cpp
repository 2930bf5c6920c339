#include "gpu_geometry/planar_reflectors.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace abcube {

namespace {

// Whether material m reflects as a plain mirror: kr > 0, no refraction, opaque.
bool mirror_material(const Material& m) { return m.reflect > 0.0 && m.transmit == 0.0 && m.opacity == 1.0; }

// Faceted objects, then the smallest reflectors past MAX_REFLECTORS, are left to the cube
// maps; ids are given to the ones kept.
void keep_largest(const TriangleSoup& soup, PlanarReflectors* found) {
  PlanarReflectors& out = *found;
  std::map<uint32_t, size_t> planes_of_object;
  for (const PlanarReflector& p : out.reflectors) ++planes_of_object[p.object];
  std::vector<std::pair<double, size_t>> by_area;
  for (size_t r = 0; r < out.reflectors.size(); ++r) {
    double area = 0;
    for (const uint32_t t : out.reflectors[r].triangles) {
      const size_t v = 3 * static_cast<size_t>(t);
      const glm::dvec3 a(soup.positions[v]), b(soup.positions[v + 1]), c(soup.positions[v + 2]);
      area += 0.5 * glm::length(glm::cross(b - a, c - a));
    }
    if (planes_of_object[out.reflectors[r].object] <= MAX_PLANES_PER_OBJECT) by_area.emplace_back(-area, r);
  }
  std::stable_sort(by_area.begin(), by_area.end());
  std::vector<bool> keep(out.reflectors.size(), false);
  for (size_t k = 0; k < by_area.size() && k < MAX_REFLECTORS; ++k) keep[by_area[k].second] = true;
  std::vector<PlanarReflector> kept;
  for (size_t r = 0; r < out.reflectors.size(); ++r) {
    if (!keep[r]) {
      out.curved_triangles += out.reflectors[r].triangles.size();
      continue;
    }
    for (const uint32_t t : out.reflectors[r].triangles)
      out.reflector_of_triangle[t] = static_cast<uint32_t>(kept.size() + 1);
    kept.push_back(std::move(out.reflectors[r]));
  }
  out.reflectors = std::move(kept);
}

}  // namespace

PlanarReflectors find_planar_reflectors(const SceneData& scene) {
  const TriangleSoup& soup = *scene.triangles;
  PlanarReflectors out;
  out.reflector_of_triangle.assign(soup.triangle_count(), 0);
  // The reflectors of the object being read (the soup keeps an object's triangles together,
  // and every object's triangles are searched among its own reflectors only).
  size_t object_first = 0;
  uint32_t object = UINT32_MAX;
  for (uint32_t t = 0; t < soup.triangle_count(); ++t) {
    const Material& m = scene.materials[soup.material_id[t]];
    if (!mirror_material(m)) continue;
    if (soup.object_id[t] != object) {
      object = soup.object_id[t];
      object_first = out.reflectors.size();
    }
    const size_t v = 3 * static_cast<size_t>(t);
    const glm::dvec3 a(soup.positions[v]), b(soup.positions[v + 1]), c(soup.positions[v + 2]);
    const glm::dvec3 cross = glm::cross(b - a, c - a);
    const double length = glm::length(cross);
    if (!(length > 0.0) || !std::isfinite(length)) continue;  // no plane: draws nothing
    const glm::dvec3 n = cross / length;
    bool flat = true;
    for (size_t k = 0; k < 3 && flat; ++k) {
      const glm::dvec3 s(soup.normals[v + k]);
      flat = 1.0 - std::fabs(glm::dot(glm::normalize(s), n)) <= FLAT_COSINE_TOLERANCE;
    }
    if (!flat) {
      ++out.curved_triangles;
      continue;
    }
    const double magnitude = std::fmax(std::fmax(std::fabs(a.x), std::fabs(a.y)), std::fabs(a.z)) + 1e-300;
    const double offset = -glm::dot(n, a);
    size_t r = object_first;
    for (; r < out.reflectors.size(); ++r) {
      const PlanarReflector& p = out.reflectors[r];
      if (p.material != soup.material_id[t]) continue;
      const double cosine = glm::dot(p.normal, n);
      if (1.0 - std::fabs(cosine) > FLAT_COSINE_TOLERANCE) continue;
      const double o = cosine > 0 ? offset : -offset;
      if (std::fabs(o - p.offset) <= PLANE_RELATIVE * magnitude) break;
    }
    if (r == out.reflectors.size()) {
      PlanarReflector p;
      p.normal = n;
      p.offset = offset;
      p.object = object;
      p.material = soup.material_id[t];
      out.reflectors.push_back(p);
    }
    out.reflectors[r].triangles.push_back(t);
  }
  keep_largest(soup, &out);
  return out;
}

}  // namespace abcube
