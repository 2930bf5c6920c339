// Lens approximation of refraction (Patow-Delrieux, "Algoritmos Scan-Line para Computar
// Refracciones"): a closed transparent object is replaced by a spherical lens fitted to its
// vertices (THE FIT: principal plane, one sphere per surface by Levenberg-Marquardt), and a
// ray through it leaves along the paraxial thick lens (eq. 14) or thin lens (eq. 16), with no
// search for the exit point (THE TRANSFER; SIGNS for the curvature conventions). Cheaper than
// the search, less exact, and valid only near the fitted axis: a mode to compare speed and
// error, not the default. docs/design/lens.md has the whole argument and its ACCURACY.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene_data.hpp"

namespace abcube {

// How a transparent object refracts: exact search for the exit point (the default), or
// one of the paraxial lens approximations below.
enum class RefractionMode { search, thick_lens, thin_lens };
const char* refraction_mode_name(RefractionMode m);
// Parses "search", "thick_lens" or "thin_lens" (--refraction); false for anything else.
bool parse_refraction_mode(const std::string& s, RefractionMode* out);

// Which points fit which surface (docs/design/lens.md, "Surfaces").
enum class LensSplit { facing, side_of_plane };

struct LensFitOptions {
  LensSplit split = LensSplit::facing;
};

// One object fitted as a spherical lens (docs/design/lens.md). Lengths in world units, heights
// along `axis` from the centroid.
struct LensFit {
  glm::dvec3 centroid{0.0};
  glm::dvec3 axis{0, 0, 1};    // unit normal of the principal plane (the optical axis)
  glm::dvec3 u_axis{1, 0, 0};  // in the plane: direction of largest spread
  glm::dvec3 v_axis{0, 1, 0};  // cross(axis, u_axis)
  double rho1 = 0;             // surface above P, for light travelling along -axis
  double rho2 = 0;             // surface below P, same convention
  double thickness = 0;        // d = vertex1 - vertex2
  double nu = 1;               // index of refraction (the material's ior), air outside
  double rms_residual1 = 0;    // sqrt(mean F^2) of surface 1's points (a length)
  double rms_residual2 = 0;
  double vertex1 = 0;      // height of surface 1's vertex (its fitted z0)
  double vertex2 = 0;      // height of surface 2's vertex
  double radius = 0;       // largest distance of a vertex from the axis
  glm::dvec3 spread{0.0};  // variance of the points along axis, v_axis, u_axis
  uint32_t points1 = 0;    // points fitted for surface 1
  uint32_t points2 = 0;
  uint32_t object = 0;  // index into SceneData::objects
  bool valid = false;
  std::string why_invalid;  // empty when valid
};

// Fits object `object` of the scene (all its triangles; the index of refraction is its
// material's ior). Invalid, with the reason, for an open object, too few points, a
// degenerate spread, a surface without enough points, a fit that fails, or vertices in the
// wrong order. Throws nothing for bad geometry; `object` must be in range (checked).
LensFit fit_lens(const SceneData& scene, uint32_t object, const LensFitOptions& options = {});

// One fit per object whose material (SceneObject::material) has transmit > 0, in object
// order, valid or not.
std::vector<LensFit> fit_lenses(const SceneData& scene, const LensFitOptions& options = {});

// The Gaussian transfer of eq. 12 from the entry reference plane to the exit one.
// alpha delta - beta gamma = 1 (the text's Property 2 prints "+", a slip: the product of
// the refraction and transfer matrices, each of determinant 1, has determinant 1).
struct LensMatrix {
  double alpha = 1, beta = 0, gamma = 0, delta = 1;
};

// Patow-Delrieux eq. 13-14: entry curvature rho1, exit curvature rho2, thickness d, index nu.
LensMatrix thick_lens_matrix(double rho1, double rho2, double d, double nu);
// Patow-Delrieux eq. 16: alpha = delta = 1, beta = 0, gamma = (1 - nu)(rho1 - rho2).
LensMatrix thin_lens_matrix(double rho1, double rho2, double nu);

// The matrix a ray travelling along +axis (along_axis) or -axis meets: for -axis the fit's
// (rho1, rho2), for +axis the mirrored lens (-rho2, -rho1). `mode` is thick_lens or
// thin_lens (checked).
LensMatrix lens_matrix(const LensFit& lens, RefractionMode mode, bool along_axis);

// A ray leaving the lens: a point on its line in the exit reference plane, unit direction.
struct LensRay {
  glm::dvec3 point{0.0};
  glm::dvec3 dir{0.0};
};

// The emerging ray for the incident line origin + t dir (dir non-zero, normalised here),
// by eq. 14 (thick_lens) or eq. 16 (thin_lens); `mode` must not be search (checked).
// False, and *out untouched, when the lens is invalid, the ray runs parallel to the
// principal plane, or |S'| >= 1 (no emerging direction: the paraxial model has left its
// domain). Allocation-free; the caller decides whether the ray hit the object at all.
bool lens_transfer(const LensFit& lens, RefractionMode mode, const glm::dvec3& origin, const glm::dvec3& dir,
                   LensRay* out);

}  // namespace abcube
