#include "raster/cube_map.hpp"

#include <algorithm>
#include <cmath>

namespace abcube {

namespace {
// GL 4.5 core spec table 8.19: (forward, sc axis, tc axis) per face.
const std::array<CubeFaceBasis, CUBE_FACES> BASES = {{
    {{+1, 0, 0}, {0, 0, -1}, {0, -1, 0}},  // +X: sc = -rz, tc = -ry
    {{-1, 0, 0}, {0, 0, +1}, {0, -1, 0}},  // -X: sc = +rz, tc = -ry
    {{0, +1, 0}, {+1, 0, 0}, {0, 0, +1}},  // +Y: sc = +rx, tc = +rz
    {{0, -1, 0}, {+1, 0, 0}, {0, 0, -1}},  // -Y: sc = +rx, tc = -rz
    {{0, 0, +1}, {+1, 0, 0}, {0, -1, 0}},  // +Z: sc = +rx, tc = -ry
    {{0, 0, -1}, {-1, 0, 0}, {0, -1, 0}},  // -Z: sc = -rx, tc = -ry
}};
constexpr const char* FACE_NAMES[] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};
}  // namespace

const char* cube_face_name(int face) { return FACE_NAMES[face]; }

const CubeFaceBasis& cube_face_basis(int face) { return BASES[static_cast<size_t>(face)]; }

CubeCoord direction_to_cube(const glm::dvec3& r) {
  const double ax = std::abs(r.x), ay = std::abs(r.y), az = std::abs(r.z);
  int face;
  if (ax >= ay && ax >= az) {
    face = r.x >= 0 ? POS_X : NEG_X;
  } else if (ay >= az) {
    face = r.y >= 0 ? POS_Y : NEG_Y;
  } else {
    face = r.z >= 0 ? POS_Z : NEG_Z;
  }
  const CubeFaceBasis& b = BASES[static_cast<size_t>(face)];
  const double ma = glm::dot(b.forward, r);
  return {face, 0.5 * (glm::dot(b.s_axis, r) / ma + 1.0), 0.5 * (glm::dot(b.t_axis, r) / ma + 1.0)};
}

glm::dvec3 cube_to_direction(int face, double s, double t) {
  const CubeFaceBasis& b = BASES[static_cast<size_t>(face)];
  return b.forward + (2.0 * s - 1.0) * b.s_axis + (2.0 * t - 1.0) * b.t_axis;
}

glm::dvec3 texel_center_direction(int face, int i, int j, int n) {
  return cube_to_direction(face, (i + 0.5) / n, (j + 0.5) / n);
}

CubeTexel direction_to_texel(const glm::dvec3& r, int n) {
  const CubeCoord c = direction_to_cube(r);
  const int i = std::clamp(static_cast<int>(std::floor(c.s * n)), 0, n - 1);
  const int j = std::clamp(static_cast<int>(std::floor(c.t * n)), 0, n - 1);
  return {c.face, i, j};
}

namespace {
// Rows (sx, ty, forward) of a view basis and a translation by -center; clip z = near.
glm::mat4 reversed_infinite(const glm::dvec3& row_x, const glm::dvec3& row_y, const glm::dvec3& row_w,
                            const glm::dvec3& center, double near) {
  glm::dmat4 m(0.0);  // m[col][row]
  for (int c = 0; c < 3; ++c) {
    m[c][0] = row_x[c];
    m[c][1] = row_y[c];
    m[c][3] = row_w[c];
  }
  m[3][0] = -glm::dot(row_x, center);
  m[3][1] = -glm::dot(row_y, center);
  m[3][2] = near;
  m[3][3] = -glm::dot(row_w, center);
  return glm::mat4(m);
}
}  // namespace

glm::mat4 face_clip_matrix(int face, const glm::dvec3& center, double near_distance) {
  const CubeFaceBasis& b = BASES[static_cast<size_t>(face)];
  return reversed_infinite(b.s_axis, b.t_axis, b.forward, center, near_distance);
}

glm::mat4 camera_clip_matrix(const glm::dvec3& eye, const glm::dvec3& look_at, const glm::dvec3& up, double fov_y,
                             double aspect, double near_distance) {
  const glm::dvec3 f = glm::normalize(look_at - eye);
  const glm::dvec3 r = glm::normalize(glm::cross(f, up));
  const glm::dvec3 u = glm::cross(r, f);
  const double ty = std::tan(0.5 * fov_y);
  return reversed_infinite(r / (ty * aspect), u / ty, f, eye, near_distance);
}

double default_near_distance(double scene_radius) { return std::max(1e-4, 1e-5 * scene_radius); }

}  // namespace abcube
