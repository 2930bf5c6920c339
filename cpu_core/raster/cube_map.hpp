// The cube-map convention, defined once for the CPU and the GL passes alike.
//
// Faces in OpenGL order +X, -X, +Y, -Y, +Z, -Z. A direction r selects the face of its
// largest-magnitude component ma; the face coordinates are
//   s = (sc/|ma| + 1)/2,  t = (tc/|ma| + 1)/2
// with (sc, tc) from GL 4.5 core spec table 8.19 ("cube map texture selection").
// Texel (i, j) of an N x N face covers s in [i/N, (i+1)/N), t in [j/N, (j+1)/N): i is the
// column, j the row, and row j = 0 is t = 0. GL renders a face with window x along s and
// window y along t (face_clip_matrix), so glReadPixels row j is texel row j, unflipped.
// Texel centres are at s = (i + 0.5)/N, t = (j + 0.5)/N, GL's pixel centres.
#pragma once
#include <array>
#include <cstdint>

#include <glm/glm.hpp>

namespace abcube {

enum CubeFace : int { POS_X = 0, NEG_X, POS_Y, NEG_Y, POS_Z, NEG_Z };
constexpr int CUBE_FACES = 6;
const char* cube_face_name(int face);

// A face's frame: r = ma * forward + sc * s_axis + tc * t_axis for a direction r on
// that face, so sc = dot(s_axis, r), tc = dot(t_axis, r), ma = dot(forward, r) > 0.
struct CubeFaceBasis {
  glm::dvec3 forward;
  glm::dvec3 s_axis;
  glm::dvec3 t_axis;
};
const CubeFaceBasis& cube_face_basis(int face);

struct CubeCoord {
  int face;
  double s, t;  // in [0, 1]
};

// Face selection by the largest-magnitude component. GL leaves exact ties (seams, corners)
// to the implementation; ours go to the first of x, y, z, and a zero component counts as
// positive.
// r need not be unit; r must not be zero.
CubeCoord direction_to_cube(const glm::dvec3& r);

// Unnormalised direction through (face, s, t): forward + (2s-1) s_axis + (2t-1) t_axis.
glm::dvec3 cube_to_direction(int face, double s, double t);

// Unnormalised direction through the centre of texel (i, j) of an n x n face.
glm::dvec3 texel_center_direction(int face, int i, int j, int n);

struct CubeTexel {
  int face, i, j;
};
// The texel that contains direction r on n x n faces (s = 1 clamps to the last texel).
CubeTexel direction_to_texel(const glm::dvec3& r, int n);

// Column-major 4x4 matrix (GLM/GL layout) taking a world point x to clip space for
// face `face` of a cube centred at `center`: clip = (sc, tc, near, ma) of r = x - center.
// With glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE) this is an infinite reversed-Z
// projection: depth = near/ma (1 at the near plane, -> 0 at infinity; test GL_GREATER),
// so nothing beyond the near plane is ever clipped.
glm::mat4 face_clip_matrix(int face, const glm::dvec3& center, double near_distance);

// The same infinite reversed-Z projection for a pinhole camera (fov_y in radians).
glm::mat4 camera_clip_matrix(const glm::dvec3& eye, const glm::dvec3& look_at, const glm::dvec3& up, double fov_y,
                             double aspect, double near_distance);

// The default near distance used by every pass: small against the scene, never zero.
double default_near_distance(double scene_radius);

}  // namespace abcube
