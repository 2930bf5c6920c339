#include "scene/framing.hpp"

#include <algorithm>
#include <cmath>

#include "base/constants.hpp"

namespace abcube {

namespace {

struct Sphere {
  glm::dvec3 centre{0.0};
  double radius = 1.0;
};

Sphere bounding_sphere(const Bounds& b) {
  if (b.empty()) return {};
  Sphere s{0.5 * (b.lo + b.hi), 0.5 * glm::length(b.hi - b.lo)};
  if (!(s.radius > 0)) s.radius = std::max(1e-3 * glm::length(s.centre), 1e-3);  // a single point
  return s;
}

constexpr double MARGIN = 1.05;

}  // namespace

Camera frame_camera(const Bounds& bounds, const glm::dvec3& direction, Camera camera) {
  const Sphere s = bounding_sphere(bounds);
  const glm::dvec3 f = glm::normalize(direction);
  if (!(glm::length(glm::cross(f, glm::normalize(camera.up))) > 1e-6)) {
    camera.up = f.y < 0 ? glm::dvec3(0, 0, -1) : glm::dvec3(0, 0, 1);
  }
  const glm::dvec3 right = glm::normalize(glm::cross(f, camera.up));
  const glm::dvec3 up = glm::cross(right, f);
  const double tan_y = std::tan(0.5 * camera.fov_y_deg * PI / 180.0) / MARGIN;
  const double tan_x = tan_y * camera.width / camera.height;
  // Corner q (relative to the centre) is at depth distance + q.f in front of the camera and
  // must satisfy |q.right| <= tan_x depth and |q.up| <= tan_y depth.
  glm::dvec3 lo = s.centre - glm::dvec3(s.radius), hi = s.centre + glm::dvec3(s.radius);
  if (!bounds.empty() && glm::length(bounds.hi - bounds.lo) > 0) lo = bounds.lo, hi = bounds.hi;
  double distance = 0;
  for (int k = 0; k < 8; ++k) {
    const glm::dvec3 q = glm::dvec3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z) - s.centre;
    const double z = glm::dot(q, f);
    distance = std::max(
        {distance, std::fabs(glm::dot(q, right)) / tan_x - z, std::fabs(glm::dot(q, up)) / tan_y - z, MARGIN * -z});
  }
  camera.look_at = s.centre;
  camera.position = s.centre - distance * f;
  return camera;
}

std::vector<PointLight> frame_lights(const Bounds& bounds, const Camera& camera) {
  const Sphere s = bounding_sphere(bounds);
  const glm::dvec3 back = camera.position - s.centre;  // towards the camera
  const double distance = glm::length(back);
  const glm::dvec3 b = back / distance;
  const glm::dvec3 right = glm::normalize(glm::cross(-b, camera.up));
  const glm::dvec3 up = glm::cross(right, -b);
  PointLight key, fill;
  key.position = s.centre + 2.0 * distance * glm::normalize(b + 0.9 * up - 0.6 * right);
  key.color = glm::dvec3(0.8);
  fill.position = s.centre + 2.0 * distance * glm::normalize(b + 0.2 * up + 0.9 * right);
  fill.color = glm::dvec3(0.25);
  fill.cast_shadows = false;
  return {key, fill};
}

}  // namespace abcube
