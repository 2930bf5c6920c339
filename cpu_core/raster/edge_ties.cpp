#include "raster/edge_ties.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

#include "raster/raster.hpp"
#include "base/samples.hpp"
#include "scene/camera.hpp"

namespace abcube {

namespace {

struct EdgeTies {
  int64_t grid_w = 0, grid_h = 0;  // samples
  double eps = 0;
  const std::function<void(int64_t, int64_t)>* visit = nullptr;

  // Samples (major, minor(major)) of the segment from a to b (sample units), major the axis
  // it spans more of: each whose minor coordinate comes within eps of its centre is visited.
  void edge(glm::dvec2 a, glm::dvec2 b) {
    const bool along_x = std::abs(b.x - a.x) >= std::abs(b.y - a.y);
    if (!along_x) {
      std::swap(a.x, a.y);
      std::swap(b.x, b.y);
    }
    const int64_t major_n = along_x ? grid_w : grid_h, minor_n = along_x ? grid_h : grid_w;
    if (!(b.x != a.x)) return;  // a point (or NaN)
    if (b.x < a.x) std::swap(a, b);
    const double slope = (b.y - a.y) / (b.x - a.x);
    const double first = std::max(std::ceil(a.x - 0.5), 0.0),
                 last = std::min(std::floor(b.x - 0.5), double(major_n - 1));
    // From the end nearer the screen (an end cut at the near depth lies far outside it).
    const glm::dvec2 o = std::abs(a.x) <= std::abs(b.x) ? a : b;
    for (double k = first; k <= last; k += 1.0) {
      const double u = o.y + (k + 0.5 - o.x) * slope - 0.5;
      const double j = std::round(u);
      if (!(std::abs(u - j) < eps) || j < 0.0 || j >= double(minor_n)) continue;
      const int64_t sx = along_x ? int64_t(k) : int64_t(j), sy = along_x ? int64_t(j) : int64_t(k);
      (*visit)(sx, sy);
    }
  }
};

}  // namespace

void visit_edge_ties(const RasterView& view, int columns, int rows, const TriangleSoup& soup, double eps,
                     const std::function<void(int64_t, int64_t)>& visit) {
  EdgeTies ties;
  ties.grid_w = int64_t{view.width} * columns;
  ties.grid_h = int64_t{view.height} * rows;
  ties.eps = eps;
  ties.visit = &visit;
  // A point r = P - centre with depth w = row_w . r > 0 on the sample grid.
  auto to_samples = [&](const glm::dvec3& r) {
    const double w = glm::dot(view.row_w, r);
    return glm::dvec2(columns * glm::dot(view.row_x, r) / w, rows * glm::dot(view.row_y, r) / w);
  };
  const std::vector<glm::vec3>& positions = soup.positions;
  std::vector<glm::dvec3> r(3);
  std::vector<double> w(3);
  double reach = 0;
  for (const glm::vec3& p : positions) reach = std::max(reach, glm::length(glm::dvec3(p) - view.centre));
  const double near = 1e-6 * std::max(reach, 1e-300);
  for (size_t t = 0; 3 * t + 2 < positions.size(); ++t) {
    for (size_t k = 0; k < 3; ++k) {
      r[k] = glm::dvec3(positions[3 * t + k]) - view.centre;
      w[k] = glm::dot(view.row_w, r[k]);
    }
    for (size_t k = 0; k < 3; ++k) {
      glm::dvec3 a = r[k], b = r[(k + 1) % 3];
      const double wa = w[k], wb = w[(k + 1) % 3];
      if (wa < near && wb < near) continue;
      // The part in front of the eye: cut where depth = near (the line is unchanged).
      if (wa < near) a = a + (b - a) * ((near - wa) / (wb - wa));
      if (wb < near) b = b + (a - b) * ((near - wb) / (wa - wb));
      ties.edge(to_samples(a), to_samples(b));
    }
  }
}

void visit_edge_ties(const SceneData& scene, double eps, const std::function<void(int64_t, int64_t)>& visit) {
  const double unused_near = 1e-4;  // the walk cuts edges at its own near depth
  visit_edge_ties(camera_view(make_camera_frame(scene.camera), unused_near), MASK_COLUMNS, MASK_ROWS, *scene.triangles,
                  eps, visit);
}

std::vector<uint8_t> edge_tie_pixels(const SceneData& scene, double eps) {
  const int width = scene.camera.width;
  std::vector<uint8_t> marks(static_cast<size_t>(width) * static_cast<size_t>(scene.camera.height), 0);
  visit_edge_ties(scene, eps, [&](int64_t sx, int64_t sy) {
    marks[static_cast<size_t>((sy / MASK_ROWS) * width + sx / MASK_COLUMNS)] = 1;
  });
  return marks;
}

std::vector<uint8_t> edge_tie_samples(const SceneData& scene, double eps) {
  const int64_t grid_w = int64_t{scene.camera.width} * MASK_COLUMNS;
  std::vector<uint8_t> marks(static_cast<size_t>(grid_w * scene.camera.height * MASK_ROWS), 0);
  visit_edge_ties(scene, eps, [&](int64_t sx, int64_t sy) { marks[static_cast<size_t>(sy * grid_w + sx)] = 1; });
  return marks;
}

}  // namespace abcube
