// The rasterizer: one triangle -> per-pixel 4x8 coverage masks and fragment geometry, for a
// cube face or the camera view (thesis 5.2), one implementation for both: a RasterView is
// three basis rows, a centre and a pixel grid. THE RULES: homogeneous coverage (Olano &
// Greer 1997) with D3D's top-left TIE RULE for samples on an edge, watertight in floating
// point (the two sides of a shared edge get exactly negated edge planes); a fourth edge
// function cuts the near plane, so no vertex is moved by clipping; degenerate and edge-on
// triangles are counted and dropped; zmin and zmax bound the exact 3D polygon in the pixel.
// docs/design/raster.md has the whole argument.
#pragma once
#include <array>
#include <cstdint>

#include <glm/glm.hpp>

#include "scene/camera.hpp"
#include "base/samples.hpp"
#include "scene/scene_data.hpp"

namespace abcube {

// Margin for the trivial accept/reject of a pixel, relative to the terms of the edge
// function: far above the rounding of a x + b y + c (a few 1e-16), far below any real gap.
// Public because the GPU A-buffer (shaders/abuffer_common.glsl) takes it as a uniform.
constexpr double RASTER_TRIVIAL_REL = 1e-12;

struct RasterView {
  glm::dvec3 centre{0.0};
  glm::dvec3 row_x{1, 0, 0}, row_y{0, 1, 0}, row_w{0, 0, 1};  // row_w unit
  glm::dmat3 to_direction{1.0};                               // inverse of the rows: (x, y, 1) -> unnormalised r
  int width = 1, height = 1;
  double near_distance = 1e-4;

  // Unnormalised direction from the centre through pixel point (x, y).
  glm::dvec3 direction(double x, double y) const { return to_direction * glm::dvec3(x, y, 1.0); }
  // Pixel coordinates of r = P - centre (w must be > 0).
  glm::dvec2 project(const glm::dvec3& r) const {
    const double w = glm::dot(row_w, r);
    return {glm::dot(row_x, r) / w, glm::dot(row_y, r) / w};
  }
  size_t pixel_count() const { return static_cast<size_t>(width) * static_cast<size_t>(height); }
};

// Face `face` (cube_map.hpp order and frames) of an n x n cube centred at `centre`.
RasterView cube_face_view(int face, const glm::dvec3& centre, int n, double near_distance);
// The camera image (camera.hpp: x right, y down), centred at the eye.
RasterView camera_view(const CameraFrame& frame, double near_distance);

enum class SetupResult { visible, culled, degenerate, edge_on };

// One triangle prepared for one view: edge functions in pixel coordinates, its plane,
// its part in front of the near plane, and the pixel rows and columns it may cover.
struct TriangleSetup {
  uint32_t triangle = 0;
  std::array<glm::dvec3, 3> r{};        // vertices minus the view centre
  std::array<glm::dvec3, 3> normal{};   // vertex normals
  std::array<glm::dvec3, 4> edge{};     // (a, b, c) per edge (edge k: r_k -> r_k+1), then near
  std::array<glm::dvec3, 4> edge_3d{};  // the same edges as inward plane normals (through the centre)
  std::array<bool, 4> owns_ties{};      // tie rule per edge
  int edge_count = 3;                   // 4 when the near plane cuts the triangle
  std::array<glm::dvec3, 4> polygon{};  // the triangle clipped to w >= near (3D, minus centre)
  int polygon_size = 0;
  glm::dvec3 plane_normal{0.0};        // cross(r1 - r0, r2 - r0), the geometric normal
  double plane_offset = 0;             // dot(plane_normal, r0): < 0 front face, > 0 back face
  double plane_distance = 0;           // |plane_offset| / |plane_normal|
  int foot_x = -1, foot_y = -1;        // pixel holding the foot of the perpendicular, if covered
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // pixel bounds [x0, x1) x [y0, y1), clamped to the view
  bool back_face() const { return plane_offset > 0; }
  bool near_clipped() const { return edge_count == 4; }
};

// Prepares triangle `index` of `soup` for `view`; `setup` is valid only for `visible`.
SetupResult setup_triangle(const RasterView& view, const TriangleSoup& soup, uint32_t index, TriangleSetup* setup);

// What setup_triangle answers for triangle `index` before it looks at a view's direction:
// degenerate (not finite, or no area), edge_on (its plane through `centre`, by the raster's
// rule), or visible (the view decides). The same for every view of one centre.
SetupResult triangle_shape(const glm::dvec3& centre, const TriangleSoup& soup, uint32_t index);

// The cube faces (bit f for face f of cube_face_basis) a triangle's samples may lie in, seen
// from `centre`: one face (or the faces sharing a seam) when its three corners lie in that
// face's closed pyramid, which holds the whole triangle (the pyramid is convex), else all six.
// Every sample of a face lies strictly inside its pyramid, so a face left out would cover none.
uint8_t cube_faces_of(const glm::dvec3& centre, const TriangleSoup& soup, uint32_t index);

// Columns [*x_begin, *x_end) of row y that may hold covered samples (a conservative span
// inside the setup's bounds); empty when *x_begin >= *x_end.
void row_span(const TriangleSetup& setup, int y, int* x_begin, int* x_end);

// The samples of pixel (x, y) that the triangle covers (THE RULES).
CoverageMask pixel_mask(const TriangleSetup& setup, int x, int y);

// Calls visit(x, y, mask) for every pixel of rows [y_begin, y_end) with a non-empty mask,
// row by row, left to right.
template <class Visit>
void rasterize_rows(const TriangleSetup& setup, int y_begin, int y_end, Visit&& visit) {
  const int yb = y_begin > setup.y0 ? y_begin : setup.y0;
  const int ye = y_end < setup.y1 ? y_end : setup.y1;
  for (int y = yb; y < ye; ++y) {
    int xb = 0, xe = 0;
    row_span(setup, y, &xb, &xe);
    for (int x = xb; x < xe; ++x) {
      const CoverageMask m = pixel_mask(setup, x, y);
      if (m != 0) visit(x, y, m);
    }
  }
}

// Offsets (dx, dy) from the pixel corner of the centroid of the samples in `mask`
// (the pixel centre (0.5, 0.5) for an empty mask).
glm::dvec2 mask_centroid(CoverageMask mask);

struct FragmentGeometry {
  double zmin = 0, zmax = 0;  // Euclidean distance from the centre over the clipped polygon
  glm::dvec3 normal{0.0};     // unit interpolated vertex normal at the covered samples' centroid
};

// The geometry of the triangle's fragment in pixel (x, y) with coverage `mask` (non-empty).
FragmentGeometry fragment_geometry(const RasterView& view, const TriangleSetup& setup, int x, int y, CoverageMask mask);

// The point of triangle `index`'s plane seen from the view centre along pixel point (x, y)
// (world space); the centre itself if that ray is parallel to the plane.
glm::dvec3 point_on_triangle_plane(const RasterView& view, const TriangleSoup& soup, uint32_t index, double x,
                                   double y);

}  // namespace abcube
