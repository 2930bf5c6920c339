// Helpers shared by the raster, A-buffer and resolve tests.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "raster/abuffer.hpp"
#include "scene/scene_data.hpp"

// Scene builders, defined in test_raytrace.cpp.
namespace abcube::testkit {
SceneData empty_scene(const glm::dvec3& eye, const glm::dvec3& look_at, double fov_y_deg, int width, int height);
uint32_t add_material(SceneData& s, const Material& m);
Material emissive(const glm::dvec3& color);
uint32_t begin_object(SceneData& s, const std::string& type, uint32_t material, bool closed);
void add_triangle(SceneData& s, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& na,
                  const glm::dvec3& nb, const glm::dvec3& nc);
void add_flat_triangle(SceneData& s, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);
uint32_t add_quad(SceneData& s, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d,
                  uint32_t material);
uint32_t add_box(SceneData& s, const glm::dvec3& lo, const glm::dvec3& hi, uint32_t material);
uint32_t add_sphere(SceneData& s, const glm::dvec3& center, double radius, int segments, uint32_t material);
}  // namespace abcube::testkit

namespace abcube::abtest {

// How many fragments of a pixel's list cover each of its 32 samples.
inline std::array<int, MASK_SAMPLES> sample_cover_counts(FragmentList list) {
  std::array<int, MASK_SAMPLES> n{};
  for (const Fragment& f : list) {
    for (int k = 0; k < MASK_SAMPLES; ++k) n[static_cast<size_t>(k)] += (f.mask >> k) & 1u;
  }
  return n;
}

// Every raster of a cube A-buffer, for loops over faces.
inline std::vector<const ABuffer*> rasters(const CubeABuffer& cube) {
  std::vector<const ABuffer*> out;
  for (const ABuffer& b : cube.faces) out.push_back(&b);
  return out;
}

// Options for tests: two threads, every triangle's fragment kept apart unless asked.
inline ABufferOptions test_options(bool merge = false, int threads = 2) {
  ABufferOptions o;
  o.threads = threads;
  o.merge = merge;
  return o;
}

// Exact area of the part of the projected triangle inside pixel (x, y) (2D clipping).
inline double pixel_area(const std::vector<glm::dvec2>& tri, int x, int y) {
  std::vector<glm::dvec2> poly = tri;
  const auto clip = [&](int axis, double bound, double sign) {
    std::vector<glm::dvec2> out;
    for (size_t i = 0; i < poly.size(); ++i) {
      const glm::dvec2 a = poly[i], b = poly[(i + 1) % poly.size()];
      const double fa = sign * (a[axis] - bound), fb = sign * (b[axis] - bound);
      if (fa >= 0) out.push_back(a);
      if ((fa >= 0) != (fb >= 0)) out.push_back(a + (fa / (fa - fb)) * (b - a));
    }
    poly = out;
  };
  clip(0, x, 1);
  clip(0, x + 1, -1);
  clip(1, y, 1);
  clip(1, y + 1, -1);
  double a = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec2 p = poly[i], q = poly[(i + 1) % poly.size()];
    a += p.x * q.y - q.x * p.y;
  }
  return std::fabs(0.5 * a);
}

}  // namespace abcube::abtest
