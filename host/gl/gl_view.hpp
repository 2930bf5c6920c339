// A raster view as the GL compute passes read it: shaders/view.glsl's View in std430.
#pragma once
#include <cstddef>
#include <cstdint>

#include "raster/raster.hpp"

namespace abcube {

struct GpuView {
  double to_dir[3][4];
  double row_x[4], row_y[4], row_w[4];
  double near_distance;
  int32_t width, first_pixel;
  uint32_t pad[4];
};
static_assert(sizeof(GpuView) == 224 && offsetof(GpuView, width) == 200, "GpuView must match View");

// View `v`, its first pixel at `first_pixel` in the build's pixel order.
inline GpuView gpu_view(const RasterView& v, int first_pixel) {
  const auto put = [](double* out, const glm::dvec3& a) { out[0] = a.x, out[1] = a.y, out[2] = a.z, out[3] = 0.0; };
  GpuView g{};
  for (int c = 0; c < 3; ++c) put(g.to_dir[c], v.to_direction[c]);
  put(g.row_x, v.row_x);
  put(g.row_y, v.row_y);
  put(g.row_w, v.row_w);
  g.near_distance = v.near_distance;
  g.width = v.width;
  g.first_pixel = first_pixel;
  return g;
}

}  // namespace abcube
