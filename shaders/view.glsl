// A raster view on the GPU (cpu_core/raster/raster.hpp RasterView) and the 4x8 sample grid
// (base/samples.hpp), in double precision as the CPU rounds them: the A-buffer passes and the
// resolve plan read the same definitions. GpuView (host/gl/gl_view.hpp) is View's layout.

// A view (RasterView: a cube face, or the camera): pixel (x, y) looks along to_dir * (x, y, 1).
struct View {
  dvec4 to_dir[3];  // the columns of to_direction
  dvec4 row_x, row_y, row_w;
  double near_distance;
  int width, first_pixel;  // pixels a row, and the view's first pixel in the build's pixel order
};

double sample_dx(int k) { return (double(k % MASK_COLUMNS) + 0.5lf) / double(MASK_COLUMNS); }
double sample_dy(int k) { return (double(k / MASK_COLUMNS) + 0.5lf) / double(MASK_ROWS); }

// Unnormalised direction through pixel point (x, y): glm's mat3 * vec3, row by row.
dvec3 view_direction(View v, double x, double y) {
  precise dvec3 d;
  d.x = v.to_dir[0].x * x + v.to_dir[1].x * y + v.to_dir[2].x * 1.0lf;
  d.y = v.to_dir[0].y * x + v.to_dir[1].y * y + v.to_dir[2].y * 1.0lf;
  d.z = v.to_dir[0].z * x + v.to_dir[1].z * y + v.to_dir[2].z * 1.0lf;
  return d;
}
