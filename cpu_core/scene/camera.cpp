#include "scene/camera.hpp"

#include <cmath>

namespace abcube {

CameraFrame make_camera_frame(const Camera& c) {
  CameraFrame f;
  f.eye = c.position;
  f.forward = glm::normalize(c.look_at - c.position);
  f.right = glm::normalize(glm::cross(f.forward, c.up));
  f.up = glm::cross(f.right, f.forward);
  f.tan_half_fov_y = std::tan(glm::radians(c.fov_y_deg) * 0.5);
  f.aspect = static_cast<double>(c.width) / c.height;
  f.width = c.width;
  f.height = c.height;
  return f;
}

}  // namespace abcube
