// Lens approximation of refraction: the fit and the paraxial transfer (lens.hpp).
#include "search/lens.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "base/enum_names.hpp"
#include "base/error.hpp"

namespace abcube {

namespace {

constexpr EnumName<RefractionMode> REFRACTION_MODE_NAMES[] = {{RefractionMode::search, "search"},
                                                              {RefractionMode::thick_lens, "thick_lens"},
                                                              {RefractionMode::thin_lens, "thin_lens"}};

// Fewest points a surface fit accepts: two parameters, and a third point to overdetermine.
constexpr size_t MIN_SURFACE_POINTS = 3;

// A triangle faces neither surface when |cos(normal, axis)| is below this (a rim band
// parallel to the axis).
constexpr double FACING_EPS = 1e-6;

// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations (Golub-Van Loan
// 8.5.2): values ascending, vectors[i] the unit eigenvector of values[i].
void symmetric_eigen(const double a_in[3][3], double values[3], glm::dvec3 vectors[3]) {
  double a[3][3], v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) a[i][j] = a_in[i][j];
  for (int sweep = 0; sweep < 64; ++sweep) {
    const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    const double diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
    if (off <= 1e-32 * diag || off == 0.0) break;
    for (int p = 0; p < 2; ++p) {
      for (int q = p + 1; q < 3; ++q) {
        if (a[p][q] == 0.0) continue;
        // Rotation zeroing a[p][q] (Numerical Recipes 11.1 convention: A' = J^T A J).
        const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
        const double t = (theta >= 0 ? 1.0 : -1.0) / (std::fabs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        for (int k = 0; k < 3; ++k) {  // columns p, q of A J
          const double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {  // rows p, q of J^T (A J)
          const double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {  // V J
          const double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - s * vkq;
          v[k][q] = s * vkp + c * vkq;
        }
      }
    }
  }
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int i, int j) { return a[i][i] < a[j][j]; });
  for (int i = 0; i < 3; ++i) {
    const int k = order[i];
    values[i] = a[k][k];
    vectors[i] = glm::normalize(glm::dvec3(v[0][k], v[1][k], v[2][k]));
  }
}

// The sign that makes the largest-magnitude component positive (ties: x, then y, then z).
glm::dvec3 canonical_sign(const glm::dvec3& d) {
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (std::fabs(d[i]) > std::fabs(d[k])) k = i;
  return d[k] < 0 ? -d : d;
}

void sort_unique(std::vector<glm::dvec3>* points) {
  auto less = [](const glm::dvec3& a, const glm::dvec3& b) {
    if (a.x != b.x) return a.x < b.x;
    if (a.y != b.y) return a.y < b.y;
    return a.z < b.z;
  };
  std::sort(points->begin(), points->end(), less);
  points->erase(std::unique(points->begin(), points->end()), points->end());
}

// One surface's points in the lens frame: u = (x^2 + y^2) / 2 and the height z.
struct LensSurfacePoint {
  double u, z;
};

struct SurfaceFit {
  double rho = 0, z0 = 0, rms = 0;
  bool ok = false;
};

// Sum of F^2 and the Gauss-Newton normal equations at (rho, z0), for
// F = (z - z0) - rho (u + (z - z0)^2 / 2)  (Patow-Delrieux sec. 2).
struct NormalEquations {
  double cost = 0, jtj[2][2] = {{0, 0}, {0, 0}}, jtr[2] = {0, 0};
};

NormalEquations normal_equations(const std::vector<LensSurfacePoint>& pts, double rho, double z0) {
  NormalEquations ne;
  for (const LensSurfacePoint& p : pts) {
    const double w = p.z - z0, q = p.u + 0.5 * w * w;
    const double f = w - rho * q;
    const double j0 = -q, j1 = -1.0 + rho * w;  // dF/drho, dF/dz0
    ne.cost += f * f;
    ne.jtj[0][0] += j0 * j0;
    ne.jtj[0][1] += j0 * j1;
    ne.jtj[1][1] += j1 * j1;
    ne.jtr[0] += j0 * f;
    ne.jtr[1] += j1 * f;
  }
  ne.jtj[1][0] = ne.jtj[0][1];
  return ne;
}

// Least squares of F over (rho, z0) by Levenberg-Marquardt (Marquardt 1963), in units where
// the object's size is 1, from z0 = z_start and the linear least-squares rho for it.
SurfaceFit fit_surface(const std::vector<LensSurfacePoint>& pts_world, double z_start, double scale) {
  SurfaceFit fit;
  if (pts_world.size() < MIN_SURFACE_POINTS) return fit;
  std::vector<LensSurfacePoint> pts(pts_world.size());
  for (size_t i = 0; i < pts.size(); ++i) {
    pts[i] = {pts_world[i].u / (scale * scale), pts_world[i].z / scale};
  }
  double z0 = z_start / scale;
  // Linear least squares in rho for fixed z0: (z - z0) = rho q.
  double sqw = 0, sqq = 0;
  for (const LensSurfacePoint& p : pts) {
    const double w = p.z - z0, q = p.u + 0.5 * w * w;
    sqw += q * w;
    sqq += q * q;
  }
  if (!(sqq > 0)) return fit;
  double rho = sqw / sqq;
  NormalEquations ne = normal_equations(pts, rho, z0);
  double lambda = 1e-3;
  for (int iter = 0; iter < 200; ++iter) {
    const double a00 = ne.jtj[0][0] * (1 + lambda), a11 = ne.jtj[1][1] * (1 + lambda);
    const double a01 = ne.jtj[0][1];
    const double det = a00 * a11 - a01 * a01;
    if (!(det > 0)) return fit;  // singular: the points do not pin down both parameters
    const double d_rho = -(a11 * ne.jtr[0] - a01 * ne.jtr[1]) / det;
    const double d_z0 = -(a00 * ne.jtr[1] - a01 * ne.jtr[0]) / det;
    const NormalEquations trial = normal_equations(pts, rho + d_rho, z0 + d_z0);
    if (trial.cost <= ne.cost) {
      rho += d_rho;
      z0 += d_z0;
      const bool converged = std::fabs(d_rho) + std::fabs(d_z0) < 1e-13 || trial.cost == ne.cost;
      ne = trial;
      lambda = std::max(lambda * 0.1, 1e-12);
      if (converged || ne.cost == 0.0) break;
    } else {
      lambda *= 10.0;
      if (lambda > 1e12) break;  // no step lowers the cost: a minimum to rounding
    }
  }
  if (!std::isfinite(rho) || !std::isfinite(z0)) return fit;
  fit.rho = rho / scale;
  fit.z0 = z0 * scale;
  fit.rms = std::sqrt(ne.cost / static_cast<double>(pts.size())) * scale;
  fit.ok = true;
  return fit;
}

// The object's deduplicated vertices and those of each surface (docs/design/lens.md, "Surfaces").
struct LensPoints {
  std::vector<glm::dvec3> all, upper, lower;
};

LensPoints surface_points(const SceneData& scene, const SceneObject& obj, const LensFit& frame, LensSplit split,
                          const std::vector<glm::dvec3>& all) {
  LensPoints pts;
  if (split == LensSplit::side_of_plane) {
    for (const glm::dvec3& p : all) {
      const double z = glm::dot(p - frame.centroid, frame.axis);
      if (z >= 0) pts.upper.push_back(p);
      if (z <= 0) pts.lower.push_back(p);
    }
    return pts;
  }
  const TriangleSoup& soup = *scene.triangles;
  for (uint32_t t = obj.first_triangle; t < obj.first_triangle + obj.triangle_count; ++t) {
    const glm::dvec3 a(soup.positions[3 * t]), b(soup.positions[3 * t + 1]), c(soup.positions[3 * t + 2]);
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double len = glm::length(n);
    if (!(len > 0)) continue;
    const double cos_axis = glm::dot(n, frame.axis) / len;
    if (std::fabs(cos_axis) < FACING_EPS) continue;
    std::vector<glm::dvec3>& side = cos_axis > 0 ? pts.upper : pts.lower;
    side.insert(side.end(), {a, b, c});
  }
  sort_unique(&pts.upper);
  sort_unique(&pts.lower);
  return pts;
}

std::vector<LensSurfacePoint> in_lens_frame(const std::vector<glm::dvec3>& pts, const LensFit& f) {
  std::vector<LensSurfacePoint> out;
  out.reserve(pts.size());
  for (const glm::dvec3& p : pts) {
    const glm::dvec3 r = p - f.centroid;
    const double x = glm::dot(r, f.u_axis), y = glm::dot(r, f.v_axis);
    out.push_back({0.5 * (x * x + y * y), glm::dot(r, f.axis)});
  }
  return out;
}

LensFit invalid(LensFit f, const std::string& why) {
  f.valid = false;
  f.why_invalid = why;
  return f;
}

// Principal plane of the points (docs/design/lens.md, "Principal plane P"); false when
// they do not span a plane.
bool fit_principal_plane(const std::vector<glm::dvec3>& all, LensFit* f) {
  glm::dvec3 centroid(0.0);
  for (const glm::dvec3& p : all) centroid += p;
  centroid /= static_cast<double>(all.size());
  double cov[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  for (const glm::dvec3& p : all) {
    const glm::dvec3 r = p - centroid;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) cov[i][j] += r[i] * r[j];
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) cov[i][j] /= static_cast<double>(all.size());
  double values[3];
  glm::dvec3 vectors[3];
  symmetric_eigen(cov, values, vectors);
  f->centroid = centroid;
  f->spread = glm::dvec3(values[0], values[1], values[2]);
  // The plane of least squared distances has the smallest-variance direction as normal.
  f->axis = canonical_sign(vectors[0]);
  f->u_axis = canonical_sign(vectors[2]);
  f->v_axis = glm::cross(f->axis, f->u_axis);
  return values[1] > 1e-12 * values[2] && values[2] > 0;
}

}  // namespace

const char* refraction_mode_name(RefractionMode m) { return enum_name(REFRACTION_MODE_NAMES, m); }

bool parse_refraction_mode(const std::string& s, RefractionMode* out) {
  return parse_enum(REFRACTION_MODE_NAMES, s, out);
}

LensFit fit_lens(const SceneData& scene, uint32_t object, const LensFitOptions& options) {
  ABCUBE_CHECK(object < scene.objects.size(),
               "object " + std::to_string(object) + " of " + std::to_string(scene.objects.size()));
  const SceneObject& obj = scene.objects[object];
  LensFit f;
  f.object = object;
  ABCUBE_CHECK(obj.material < scene.materials.size(), obj.path);
  f.nu = scene.materials[obj.material].ior;
  if (!obj.closed) return invalid(f, obj.path + ": not a closed object (a lens needs an inside)");
  if (!(f.nu > 0) || !std::isfinite(f.nu)) return invalid(f, obj.path + ": index of refraction not > 0");

  std::vector<glm::dvec3> all;
  all.reserve(3 * size_t{obj.triangle_count});
  for (uint32_t t = obj.first_triangle; t < obj.first_triangle + obj.triangle_count; ++t) {
    for (int k = 0; k < 3; ++k) all.emplace_back(scene.triangles->positions[3 * size_t{t} + k]);
  }
  sort_unique(&all);
  if (all.size() < 4) return invalid(f, obj.path + ": fewer than 4 distinct vertices");
  if (!fit_principal_plane(all, &f)) return invalid(f, obj.path + ": vertices do not span a plane");

  double scale = 0;
  for (const LensSurfacePoint& p : in_lens_frame(all, f)) {
    f.radius = std::max(f.radius, std::sqrt(2.0 * p.u));
    scale = std::max(scale, std::sqrt(2.0 * p.u + p.z * p.z));
  }

  // Curvature of each surface (Patow-Delrieux sec. 2, F(u, z) over rho and z0).
  const LensPoints pts = surface_points(scene, obj, f, options.split, all);
  const std::vector<LensSurfacePoint> upper = in_lens_frame(pts.upper, f);
  const std::vector<LensSurfacePoint> lower = in_lens_frame(pts.lower, f);
  f.points1 = static_cast<uint32_t>(upper.size());
  f.points2 = static_cast<uint32_t>(lower.size());
  if (upper.size() < MIN_SURFACE_POINTS || lower.size() < MIN_SURFACE_POINTS) {
    return invalid(f, obj.path + ": a surface has fewer than 3 points (" + std::to_string(upper.size()) + " above, " +
                          std::to_string(lower.size()) + " below the principal plane)");
  }
  double top = -std::numeric_limits<double>::infinity(), bottom = std::numeric_limits<double>::infinity();
  for (const LensSurfacePoint& p : upper) top = std::max(top, p.z);
  for (const LensSurfacePoint& p : lower) bottom = std::min(bottom, p.z);
  const SurfaceFit s1 = fit_surface(upper, top, scale);
  const SurfaceFit s2 = fit_surface(lower, bottom, scale);
  if (!s1.ok || !s2.ok) return invalid(f, obj.path + ": the curvature fit failed (degenerate points)");

  // z runs along +axis; light from the +axis side travels along -axis, so the Cartesian
  // curvature along its travel is -rho of F (docs/design/lens.md, "Signs").
  f.rho1 = -s1.rho;
  f.rho2 = -s2.rho;
  f.vertex1 = s1.z0;
  f.vertex2 = s2.z0;
  f.thickness = s1.z0 - s2.z0;
  f.rms_residual1 = s1.rms;
  f.rms_residual2 = s2.rms;
  if (!(f.thickness > 0)) {
    return invalid(
        f, obj.path + ": the fitted vertices are in the wrong order (thickness " + std::to_string(f.thickness) + ")");
  }
  f.valid = true;
  return f;
}

std::vector<LensFit> fit_lenses(const SceneData& scene, const LensFitOptions& options) {
  std::vector<LensFit> fits;
  for (uint32_t i = 0; i < scene.objects.size(); ++i) {
    const uint32_t m = scene.objects[i].material;
    if (m < scene.materials.size() && scene.materials[m].transmit > 0) fits.push_back(fit_lens(scene, i, options));
  }
  return fits;
}

LensMatrix thick_lens_matrix(double rho1, double rho2, double d, double nu) {
  // Patow-Delrieux eq. 13: beta_1 = d / nu, gamma_1 = (1 - nu) rho1, gamma_2 = (nu - 1) rho2;
  // eq. 12 composes them, which is eq. 14.
  const double beta1 = d / nu, gamma1 = (1.0 - nu) * rho1, gamma2 = (nu - 1.0) * rho2;
  LensMatrix m;
  m.alpha = beta1 * gamma1 + 1.0;
  m.beta = beta1;
  m.gamma = gamma1 * beta1 * gamma2 + gamma1 + gamma2;
  m.delta = beta1 * gamma2 + 1.0;
  return m;
}

LensMatrix thin_lens_matrix(double rho1, double rho2, double nu) {
  // Patow-Delrieux eq. 16: S' = (1 - nu)(rho1 - rho2) A + S, and A' = A (d -> 0).
  LensMatrix m;
  m.gamma = (1.0 - nu) * (rho1 - rho2);
  return m;
}

LensMatrix lens_matrix(const LensFit& lens, RefractionMode mode, bool along_axis) {
  ABCUBE_CHECK(mode != RefractionMode::search, "lens_matrix needs thick_lens or thin_lens");
  // Travelling along +axis the ray meets surface 2 first: the mirrored lens
  // (docs/design/lens.md, "Signs").
  const double entry = along_axis ? -lens.rho2 : lens.rho1;
  const double exit = along_axis ? -lens.rho1 : lens.rho2;
  return mode == RefractionMode::thick_lens ? thick_lens_matrix(entry, exit, lens.thickness, lens.nu)
                                            : thin_lens_matrix(entry, exit, lens.nu);
}

bool lens_transfer(const LensFit& lens, RefractionMode mode, const glm::dvec3& origin, const glm::dvec3& dir,
                   LensRay* out) {
  ABCUBE_CHECK(mode != RefractionMode::search, "lens_transfer needs thick_lens or thin_lens");
  if (!lens.valid) return false;
  const glm::dvec3 d = glm::normalize(dir);
  const double along = glm::dot(d, lens.axis);
  if (!(std::fabs(along) > 1e-12)) return false;
  const bool along_axis = along > 0;
  // Reference planes: the vertex planes in the order met (thick), the principal plane (thin).
  double z_in = 0, z_out = 0;
  if (mode == RefractionMode::thick_lens) {
    z_in = along_axis ? lens.vertex2 : lens.vertex1;
    z_out = along_axis ? lens.vertex1 : lens.vertex2;
  }
  // A: where the incident line crosses the entry plane; S: its direction's transverse part.
  const glm::dvec3 r = origin - lens.centroid;
  const glm::dvec3 p = r + ((z_in - glm::dot(r, lens.axis)) / along) * d;
  const glm::dvec2 a(glm::dot(p, lens.u_axis), glm::dot(p, lens.v_axis));
  const glm::dvec2 s(glm::dot(d, lens.u_axis), glm::dot(d, lens.v_axis));
  // Patow-Delrieux eq. 12 with eq. 14 or 16, per transverse coordinate.
  const LensMatrix m = lens_matrix(lens, mode, along_axis);
  const glm::dvec2 a_out = m.alpha * a + m.beta * s;
  const glm::dvec2 s_out = m.gamma * a + m.delta * s;
  const double s2 = glm::dot(s_out, s_out);
  if (!(s2 < 1.0)) return false;
  // Eq. 9: the axial component from unit length, along the direction of travel.
  const double zeta = std::sqrt(1.0 - s2) * (along_axis ? 1.0 : -1.0);
  out->point = lens.centroid + a_out.x * lens.u_axis + a_out.y * lens.v_axis + z_out * lens.axis;
  out->dir = s_out.x * lens.u_axis + s_out.y * lens.v_axis + zeta * lens.axis;
  return true;
}

}  // namespace abcube
