// The shading model, written once for every method (thesis ch. 6, Whitted 1980).
//
//   C = ka * Ia * Od
//     + sum over lights l:  S_l * I_l * ( kd * Od * max(0, N.L) + ks * max(0, R.V)^n )
//     + kr * C_reflected + kt * C_transmitted
//
// Od = material colour times its base-colour texture at the point's uv (diffuse_color in
// scene/texture.hpp; the functions below take it as `od`, m.color when not given),
// Ia = scene ambient, I_l = light colour (no distance attenuation), L, V unit vectors to the
// light and the viewer, R = reflect(-L, N), N the shading normal turned to face the viewer
// (two-sided lighting). S_l in [0, 1] is the light's visibility: the product over the
// blockers of blocker_transmittance (shadow rays are not refracted).
// shaders/common_shading.glsl mirrors phong_local for the GPU passes. The secondary-ray
// rules are at the end of this file; raytrace.hpp composes all of them.
#pragma once
#include <cmath>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene_data.hpp"
#include "scene/texture.hpp"
#include "scene/tie_rule.hpp"

namespace abcube {

// The normal turned to the viewer's side: N if N.V >= 0, else -N.
inline glm::dvec3 face_forward(const glm::dvec3& n, const glm::dvec3& v) { return glm::dot(n, v) >= 0.0 ? n : -n; }

// Ambient term alone: ka * Ia * Od.
inline glm::dvec3 phong_ambient(const Material& m, const glm::dvec3& ambient, const glm::dvec3& od) {
  return m.ambient * ambient * od;
}
inline glm::dvec3 phong_ambient(const Material& m, const glm::dvec3& ambient) {
  return phong_ambient(m, ambient, m.color);
}

// One light's diffuse + specular contribution before visibility (S_l = 1).
// n must already face the viewer (face_forward), all vectors unit.
inline glm::dvec3 phong_light(const Material& m, const glm::dvec3& n, const glm::dvec3& v, const glm::dvec3& to_light,
                              const glm::dvec3& light_color, const glm::dvec3& od) {
  const double ndotl = glm::dot(n, to_light);
  if (ndotl <= 0.0) return glm::dvec3(0.0);
  glm::dvec3 c = m.diffuse * ndotl * od;
  if (m.specular > 0.0) {
    const glm::dvec3 r = 2.0 * ndotl * n - to_light;  // reflect(-L, N)
    const double rdotv = glm::dot(r, v);
    if (rdotv > 0.0) c += glm::dvec3(m.specular * std::pow(rdotv, m.shininess));
  }
  return light_color * c;
}
inline glm::dvec3 phong_light(const Material& m, const glm::dvec3& n, const glm::dvec3& v, const glm::dvec3& to_light,
                              const glm::dvec3& light_color) {
  return phong_light(m, n, v, to_light, light_color, m.color);
}

// The local Phong colour at p with geometric/shading normal n seen from `eye`,
// every light fully visible (no shadows): what the GPU Z-buffer pass computes.
inline glm::dvec3 phong_local(const Material& m, const glm::dvec3& p, const glm::dvec3& n_in, const glm::dvec3& eye,
                              const glm::dvec3& ambient, const std::vector<PointLight>& lights, const glm::dvec3& od) {
  const glm::dvec3 v = glm::normalize(eye - p);
  const glm::dvec3 n = face_forward(glm::normalize(n_in), v);
  glm::dvec3 c = phong_ambient(m, ambient, od);
  for (const PointLight& l : lights) {
    c += phong_light(m, n, v, glm::normalize(l.position - p), l.color, od);
  }
  return c;
}
inline glm::dvec3 phong_local(const Material& m, const glm::dvec3& p, const glm::dvec3& n_in, const glm::dvec3& eye,
                              const glm::dvec3& ambient, const std::vector<PointLight>& lights) {
  return phong_local(m, p, n_in, eye, ambient, lights, m.color);
}

// Mirror direction of incident direction i about unit normal n: i - 2 (n.i) n.
inline glm::dvec3 reflect_dir(const glm::dvec3& i, const glm::dvec3& n) { return i - 2.0 * glm::dot(n, i) * n; }

// Snell refraction of unit incident i through unit normal n (n against i) with
// eta = n1/n2: T = eta I + (eta c1 - c2) N, c1 = -N.I, c2 = sqrt(1 - eta^2 (1 - c1^2)).
// Returns false on total internal reflection (negative radicand).
inline bool refract_dir(const glm::dvec3& i, const glm::dvec3& n, double eta, glm::dvec3* t) {
  const double c1 = -glm::dot(n, i);
  const double k = 1.0 - eta * eta * (1.0 - c1 * c1);
  if (k < 0.0) return false;
  *t = eta * i + (eta * c1 - std::sqrt(k)) * n;
  return true;
}

// ---------------------------------------------------------------------------------------
// The secondary-ray rules, written once for every method (raytrace.hpp shows how the exact
// tracer composes them; the A-buffer searches follow the same rules).
// ---------------------------------------------------------------------------------------

// Self-intersection (rule "offset"): a secondary ray leaving surface point p starts at p
// moved by eps along the unit geometric normal, to the side the new ray travels into, with
//   eps = SELF_INTERSECTION_REL * (max(|p.x|, |p.y|, |p.z|) + scene_scale).
// The offset scales with the magnitude of the coordinates, so it stays many orders above
// the rounding of a double-precision hit point (about 1e-16 of that magnitude) whatever
// the angle of the ray: a ray that leaves a plane cannot hit that plane again, grazing or
// not. scene_scale is the largest absolute coordinate of the scene's vertices plus the
// diagonal of their bounds (RayTracer::scene_scale).
constexpr double SELF_INTERSECTION_REL = 1e-9;

inline double self_intersection_offset(const glm::dvec3& p, double scene_scale) {
  const double m = std::fmax(std::fabs(p.x), std::fmax(std::fabs(p.y), std::fabs(p.z)));
  return SELF_INTERSECTION_REL * (m + scene_scale);
}

inline glm::dvec3 offset_origin(const glm::dvec3& p, const glm::dvec3& geometric_normal, const glm::dvec3& dir,
                                double eps) {
  return glm::dot(geometric_normal, dir) >= 0.0 ? p + eps * geometric_normal : p - eps * geometric_normal;
}

// Refraction at an interface (rule "refraction", Whitted 1980 with Snell's law):
// - the ray passes from a medium of index n_from into one of index n_to, eta = n_from / n_to.
//   Which media those are is media.hpp's rule (a stack of nested media, Schmidt & Budge
//   2002); for a single object in air: entering iff the ray runs against the unit geometric
//   normal cross(b-a, c-a) (outward for closed objects), dot(N_g, d) < 0, eta = 1/ior
//   entering and ior leaving (transmission(d, N_g, N_s, ior)).
// - the ray bends about the shading normal flipped to the incoming ray's side of the
//   geometric normal; if that normal still faces along the ray (interpolated normals can),
//   the geometric normal is used instead.
// - total internal reflection (negative radicand in refract_dir) sends the transmitted
//   weight along the mirror direction about the same normal.
struct Transmission {
  glm::dvec3 dir{0.0};  // unit when d is unit
  double eta = 1.0;     // n1 / n2
  double n1 = 1.0, n2 = 1.0;
  bool entering = true;  // against the geometric normal
  bool total_internal_reflection = false;
};

inline Transmission transmission_between(const glm::dvec3& d, const glm::dvec3& geometric_normal,
                                         const glm::dvec3& shading_normal, double n_from, double n_to) {
  Transmission r;
  r.entering = glm::dot(geometric_normal, d) < 0.0;
  r.n1 = n_from;
  r.n2 = n_to;
  r.eta = n_from / n_to;
  const glm::dvec3 n_against = r.entering ? geometric_normal : -geometric_normal;
  glm::dvec3 n = glm::dot(shading_normal, n_against) >= 0.0 ? shading_normal : -shading_normal;
  if (glm::dot(n, d) >= 0.0) n = n_against;
  r.total_internal_reflection = !refract_dir(d, n, r.eta, &r.dir);
  if (r.total_internal_reflection) r.dir = reflect_dir(d, n);
  return r;
}

// One object in air: 1 -> ior entering, ior -> 1 leaving.
inline Transmission transmission(const glm::dvec3& d, const glm::dvec3& geometric_normal,
                                 const glm::dvec3& shading_normal, double ior) {
  const bool entering = glm::dot(geometric_normal, d) < 0.0;
  return transmission_between(d, geometric_normal, shading_normal, entering ? 1.0 : ior, entering ? ior : 1.0);
}

// The weights of the reflected and transmitted terms (rule "fresnel"). Off (the thesis's
// model, the default): kr and kt as the material says. On (--fresnel): for a material with
// kt > 0, Schlick 1994's reflectance F = F0 + (1 - F0)(1 - cos)^5, F0 = ((n1-n2)/(n1+n2))^2
// for the interface's two indices (tr.n1, tr.n2; 1 and ior for an object in air), cos the
// angle in the medium of lower index (the incident one when n1 <= n2, else the transmitted
// one), moves the share F of kt to the mirror term: kr' = kr + F kt, kt' = (1 - F) kt.
// Under total internal reflection kt already follows the mirror direction (transmission).
struct SecondaryWeights {
  double reflect = 0, transmit = 0;
};
inline SecondaryWeights secondary_weights(const Material& m, bool fresnel, const glm::dvec3& d, const Transmission& tr,
                                          const glm::dvec3& geometric_normal) {
  SecondaryWeights w{m.reflect, m.transmit};
  if (!fresnel || m.transmit <= 0.0 || tr.total_internal_reflection) return w;
  const double cos_d = std::abs(glm::dot(d, geometric_normal));
  const double cos_t = std::abs(glm::dot(tr.dir, geometric_normal)) / std::max(glm::length(tr.dir), 1e-300);
  const double c = tr.n1 <= tr.n2 ? cos_d : cos_t;
  const double r0 = (tr.n1 - tr.n2) / (tr.n1 + tr.n2);
  const double f0 = r0 * r0;
  const double f = f0 + (1.0 - f0) * std::pow(1.0 - std::min(c, 1.0), 5.0);
  w.reflect = m.reflect + f * m.transmit;
  w.transmit = (1.0 - f) * m.transmit;
  return w;
}

// Light let through by one surface crossing the shadow segment P..L (rule "shadows";
// shadow rays are not refracted):  (1 - op) + op * kt * Od, component-wise. Od is the
// material colour here, untextured, on every path alike (a known limit: a translucent
// textured caster's shadow takes its material colour).
// An opaque blocker (kt = 0, op = 1) gives 0; a refractive one (op = 1) gives kt * Od;
// a coverage-transparent one (kt = 0) gives 1 - op. S_l is the product over every
// crossing, so a closed glass object between P and L counts twice (entry and exit).
inline glm::dvec3 blocker_transmittance(const Material& m) {
  return glm::dvec3(1.0 - m.opacity) + (m.opacity * m.transmit) * m.color;
}

// Lights on surfaces (rule "shadows"): a triangle whose plane passes through the light L,
// at the same distance by THE TIE RULE's bound (scene/tie_rule.hpp: within TIE_RELATIVE of
// its largest vertex coordinate, the float rounding of its vertices; L itself is double),
// is not a blocker of L. A segment P..L meets that plane only at L itself (or lies in it,
// where N . L = 0 lights nothing), so "blocked" would be decided by rounding: the tracer
// and the map would both speckle, each differently (hard suite light_on_surface, a point
// light lying on the floor). The tracer and every shadow search ask this one test. A
// degenerate triangle has no plane and is never skipped here.
inline bool plane_holds_light(const TriangleSoup& soup, uint32_t triangle, const glm::dvec3& light) {
  const size_t i = 3 * static_cast<size_t>(triangle);
  const glm::dvec3 a(soup.positions[i]), b(soup.positions[i + 1]), c(soup.positions[i + 2]);
  const glm::dvec3 n = glm::cross(b - a, c - a);
  const double len = glm::length(n);
  if (!(len > 0.0)) return false;
  return std::fabs(glm::dot(n, light - a)) <= TIE_RELATIVE * triangle_magnitude(soup, triangle) * len;
}

// Coverage transparency (rule "opacity"; thesis 5.2.1, Pack_Under_Mask blend):
// C = op * C_surface + (1 - op) * C_behind, C_behind from the ray continued straight on.
inline glm::dvec3 blend_coverage(double opacity, const glm::dvec3& c_surface, const glm::dvec3& c_behind) {
  return opacity * c_surface + (1.0 - opacity) * c_behind;
}

}  // namespace abcube
