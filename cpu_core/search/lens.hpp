// Lens approximation of refraction (Patow-Delrieux, "Algoritmos Scan-Line para Computar
// Refracciones", seeds/scanline-refraction-lens.es.txt; design.md "Lens approximation of
// refraction"). A closed transparent object is replaced by a spherical lens fitted to its
// vertices; a ray through it leaves along the paraxial (Gaussian) thick lens (eq. 14) or
// thin lens (eq. 16), with no search for the exit point. Cheaper than the search, less
// exact: a mode to compare speed and error, not the default.
//
// THE FIT (fit_lens; text sec. 2, last three paragraphs)
//
// Points: the object's vertices, deduplicated by exact position.
// Principal plane P: the plane a x + b y + c z + d = 0, a^2 + b^2 + c^2 = 1, of least
//   squared distances to the points. It passes through their centroid and its normal is
//   the eigenvector of the smallest eigenvalue of their covariance, so P holds the two
//   directions of largest spread ("los ejes de mayor dispersion"). `axis` is that normal,
//   signed so that its largest-magnitude world component is positive (ties: x before y
//   before z); `u_axis` is the eigenvector of largest spread signed the same way;
//   v_axis = cross(axis, u_axis). The lens frame is (u_axis, v_axis, axis) at the centroid;
//   z below means the height along `axis` in that frame, 2u = x^2 + y^2 its squared
//   distance from the axis.
// Surfaces: the points are split into the surface above P (rho1) and the one below (rho2).
//   LensSplit::facing (default) takes the corners of the triangles whose outward geometric
//   normal has a positive (surface 1) or negative (surface 2) component along `axis`;
//   LensSplit::side_of_plane takes z >= 0 and z <= 0, the text's words read literally.
//   They agree when P holds the rim (a symmetric lens, a sphere); for a plano-convex lens
//   the centroid lies above the rim and side_of_plane puts the rim of the curved face into
//   the flat one's fit (R1 = 2, a = 1.2: rho2 = -0.054 instead of 0, rms residual 0.028
//   instead of 2e-8; LensFit.PlanoConvexHasFlatBack).
// Curvature: for each surface, least squares of the text's form
//     F(u, z) = (z - z0) - rho (u + (z - z0)^2 / 2)
//   over both parameters rho and z0 ("F es biparametrica"): minimise sum F_i^2, nonlinear in
//   z0, by Levenberg-Marquardt from z0 = the extreme height of the surface's points and rho
//   = the linear least-squares value for that z0. F = 0 is the sphere of radius 1/|rho|
//   through the vertex (0, 0, z0) with centre (0, 0, z0 + 1/rho) (a plane for rho = 0), and
//   |grad F| = 1 on it, so F is the distance to the fitted sphere to first order: the rms
//   residuals are lengths.
// Vertices and thickness: z0 of each surface is its vertex v_i (text: "z0 es un vertice de
//   la lente"); the thickness is the distance between the vertices (sec. 2, "el grosor de
//   la lente es la distancia d entre los vertices"): d = vertex1 - vertex2.
//
// SIGNS (text sec. 3, eq. 13-14, footnote 3)
//
// The text traces in a frame whose z runs along the ray (footnote 3) with the entry vertex
// at the origin, where surface i is z = rho_i (u + z^2 / 2): rho_i = 1/R_i, R_i the signed
// distance from the vertex to the sphere's centre along the direction of travel (Cartesian
// convention; the text's "positive if convex towards the incident ray" for the entry face).
// With gamma_1 = (1 - nu) rho1 and gamma_2 = (nu - 1) rho2 (eq. 13), a biconvex lens has
// rho1 > 0 > rho2 and power (nu - 1)(rho1 - rho2) > 0.
// LensFit::rho1, rho2 are given for light arriving from the +axis side (travelling along
// -axis), which meets surface 1 (above P) first: a biconvex lens has rho1 = 1/R1,
// rho2 = -1/R2; a sphere of radius r has rho1 = 1/r, rho2 = -1/r. Light travelling along
// +axis meets surface 2 first and sees the mirrored lens: entry curvature -rho2, exit
// curvature -rho1 (lens_matrix does the swap).
//
// THE TRANSFER (lens_transfer; text sec. 3-4)
//
// In the lens frame, A is the ray's transverse position (u, v) where its line crosses the
// entry reference plane and S the transverse part (u, v) of its unit direction (length
// nu_1 = 1 in air, Property 1). Thick lens: the reference planes are the entry and exit
// vertex planes, z = entry vertex and z = exit vertex (fig. 2b, eq. 5, 11); the emerging ray
// passes through A' in the exit vertex plane. Thin lens: both are the principal plane P
// (z = 0, d -> 0), so A' = A. In both,
//     A' = alpha A + beta S,   S' = gamma A + delta S                   (eq. 12)
// per transverse coordinate, and the emerging unit direction is S' plus
// sqrt(1 - |S'|^2) along the direction of travel (eq. 9, no reflection).
//
// ACCURACY (tests/core/test_lens.cpp, LensTransfer.AgainstExactTracer: the exact tracer on
// the same triangles, nu = 1.5, worst of both sides and four azimuths)
// The fit of a finely tessellated spherical lens is exact to ~1e-9. Thick lens mode, biconvex
// R1 = 2, R2 = 3, aperture a = 1.2, d = 0.65: emerging direction within 2e-7 rad at h = 0.01 a,
// 2.3e-5 rad for h <= 0.05 a with slopes up to 0.05; the error grows as h^3 (third-order
// spherical aberration, dropped by the Gaussian approximation): 1e-4 rad at 0.1 a, 1e-3 at
// 0.2 a, 2e-2 at 0.5 a, 0.12-0.25 rad at 0.9 a (deviations 0.05, 0.1, 0.26, 0.6-0.7 rad).
// Thin lens mode also drops the power term (nu-1)^2 rho1 rho2 d / nu (4.5 % of the
// deflection on that lens, 0.17 % on a d = 0.1 one) and the slope term (d/nu)(nu-1) rho2 S
// (Property 4's condition): 3.5e-3 rad for a 0.05 slope on the thick lens, 1.5e-4 on the
// thin one.
// One axis per object: the model holds for rays near the fitted axis. For a sphere, whose
// spread is isotropic, that axis is whichever diameter the tessellation favours (`spread`
// shows how well the axis is determined); a ray across it is far from paraxial.
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

// Which points fit which surface (header comment, "Surfaces").
enum class LensSplit { facing, side_of_plane };

struct LensFitOptions {
  LensSplit split = LensSplit::facing;
};

// One object fitted as a spherical lens (header comment). Lengths in world units, heights
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
  double vertex1 = 0;          // height of surface 1's vertex (its fitted z0)
  double vertex2 = 0;          // height of surface 2's vertex
  double radius = 0;           // largest distance of a vertex from the axis
  glm::dvec3 spread{0.0};      // variance of the points along axis, v_axis, u_axis
  uint32_t points1 = 0;        // points fitted for surface 1
  uint32_t points2 = 0;
  uint32_t object = 0;         // index into SceneData::objects
  bool valid = false;
  std::string why_invalid;     // empty when valid
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
bool lens_transfer(const LensFit& lens, RefractionMode mode, const glm::dvec3& origin,
                   const glm::dvec3& dir, LensRay* out);

}  // namespace abcube
