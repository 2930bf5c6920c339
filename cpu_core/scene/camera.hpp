// The pinhole camera's frame, shared by every method that shoots camera rays.
#pragma once
#include <glm/glm.hpp>

#include "scene/scene_data.hpp"

namespace abcube {

// Image coordinates: x to the right, y down, pixel (px, py) covers [px, px+1) x [py, py+1),
// row 0 at the top of the written image. The GL camera pass (camera_clip_matrix) maps the
// same point to the same pixel: GL's window y is flipped on readback.
struct CameraFrame {
  glm::dvec3 eye, forward, right, up;
  double tan_half_fov_y = 0, aspect = 1;
  int width = 1, height = 1;

  // Unnormalised direction through image point (x, y) in pixel units.
  glm::dvec3 direction(double x, double y) const {
    const double nx = 2.0 * x / width - 1.0;
    const double ny = 1.0 - 2.0 * y / height;
    return forward + (nx * tan_half_fov_y * aspect) * right + (ny * tan_half_fov_y) * up;
  }
};

CameraFrame make_camera_frame(const Camera& camera);

}  // namespace abcube
