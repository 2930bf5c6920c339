// The shading model, written once for every method (thesis ch. 6, Whitted 1980).
//
//   C = ka * Ia * Od
//     + sum over lights l:  S_l * I_l * ( kd * Od * max(0, N.L) + ks * max(0, R.V)^n )
//     + kr * C_reflected + kt * C_transmitted
//
// Od = material colour, Ia = scene ambient, I_l = light colour (no distance attenuation),
// L = unit vector to the light, V = unit vector to the viewer, R = reflect(-L, N).
// N is the shading normal turned to face the viewer (two-sided lighting), so a surface
// seen from behind is lit like its front. S_l in [0, 1] is the light's visibility: 1 when
// unshadowed, 0 behind an opaque blocker, the product of (kt * Od) of transparent blockers
// otherwise (shadow rays are not refracted). shaders/common_shading.glsl mirrors
// phong_local for the GPU passes.
#pragma once
#include <cmath>
#include <vector>

#include <glm/glm.hpp>

#include "scene.hpp"

namespace abcube {

// The normal turned to the viewer's side: N if N.V >= 0, else -N.
inline glm::dvec3 face_forward(const glm::dvec3& n, const glm::dvec3& v) {
  return glm::dot(n, v) >= 0.0 ? n : -n;
}

// Ambient term alone: ka * Ia * Od.
inline glm::dvec3 phong_ambient(const Material& m, const glm::dvec3& ambient) {
  return m.ambient * ambient * m.color;
}

// One light's diffuse + specular contribution before visibility (S_l = 1).
// n must already face the viewer (face_forward), all vectors unit.
inline glm::dvec3 phong_light(const Material& m, const glm::dvec3& n, const glm::dvec3& v,
                              const glm::dvec3& to_light, const glm::dvec3& light_color) {
  const double ndotl = glm::dot(n, to_light);
  if (ndotl <= 0.0) return glm::dvec3(0.0);
  glm::dvec3 c = m.diffuse * ndotl * m.color;
  if (m.specular > 0.0) {
    const glm::dvec3 r = 2.0 * ndotl * n - to_light;  // reflect(-L, N)
    const double rdotv = glm::dot(r, v);
    if (rdotv > 0.0) c += glm::dvec3(m.specular * std::pow(rdotv, m.shininess));
  }
  return light_color * c;
}

// The local Phong colour at p with geometric/shading normal n seen from `eye`,
// every light fully visible (no shadows): what the GPU Z-buffer pass computes.
inline glm::dvec3 phong_local(const Material& m, const glm::dvec3& p, const glm::dvec3& n_in,
                              const glm::dvec3& eye, const glm::dvec3& ambient,
                              const std::vector<PointLight>& lights) {
  const glm::dvec3 v = glm::normalize(eye - p);
  const glm::dvec3 n = face_forward(glm::normalize(n_in), v);
  glm::dvec3 c = phong_ambient(m, ambient);
  for (const PointLight& l : lights) {
    c += phong_light(m, n, v, glm::normalize(l.position - p), l.color);
  }
  return c;
}

// Mirror direction of incident direction i about unit normal n: i - 2 (n.i) n.
inline glm::dvec3 reflect_dir(const glm::dvec3& i, const glm::dvec3& n) {
  return i - 2.0 * glm::dot(n, i) * n;
}

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

}  // namespace abcube
