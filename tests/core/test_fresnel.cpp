// The Schlick Fresnel option (shading.hpp secondary_weights): off is the thesis's model.
#include <gtest/gtest.h>

#include <cmath>

#include "reference/raytrace.hpp"
#include "material/shading.hpp"

namespace abcube {
namespace {

Material glass() {
  Material m;
  m.reflect = 0.1;
  m.transmit = 0.8;
  m.ior = 1.5;
  return m;
}

TEST(Fresnel, OffKeepsTheMaterialWeights) {
  const glm::dvec3 n(0, 0, 1), d = glm::normalize(glm::dvec3(0.3, 0, -1));
  const SecondaryWeights w = secondary_weights(glass(), false, d, transmission(d, n, n, 1.5), n);
  EXPECT_EQ(w.reflect, 0.1);
  EXPECT_EQ(w.transmit, 0.8);
}

// Normal incidence: F = F0 = ((1.5-1)/(1.5+1))^2 = 0.04 (Schlick 1994).
TEST(Fresnel, NormalIncidenceGivesF0) {
  const glm::dvec3 n(0, 0, 1), d(0, 0, -1);
  const SecondaryWeights w = secondary_weights(glass(), true, d, transmission(d, n, n, 1.5), n);
  EXPECT_NEAR(w.reflect, 0.1 + 0.04 * 0.8, 1e-12);
  EXPECT_NEAR(w.transmit, 0.96 * 0.8, 1e-12);
  EXPECT_NEAR(w.reflect + w.transmit, 0.9, 1e-12);  // energy moved, not made
}

// Grazing entry sends nearly all of kt to the mirror; leaving uses the outer (transmitted)
// angle, so the same pair of directions gives the same F both ways.
TEST(Fresnel, GrazingAndReciprocity) {
  const glm::dvec3 n(0, 0, 1);
  const glm::dvec3 grazing = glm::normalize(glm::dvec3(1, 0, -1e-4));
  const SecondaryWeights g = secondary_weights(glass(), true, grazing, transmission(grazing, n, n, 1.5), n);
  EXPECT_GT(g.reflect, 0.1 + 0.99 * 0.8);
  const glm::dvec3 in = glm::normalize(glm::dvec3(0.6, 0, -0.8));
  const Transmission t_in = transmission(in, n, n, 1.5);
  const SecondaryWeights a = secondary_weights(glass(), true, in, t_in, n);
  const glm::dvec3 back = -t_in.dir;  // the refracted ray reversed, leaving the glass
  const SecondaryWeights b = secondary_weights(glass(), true, back, transmission(back, n, n, 1.5), n);
  EXPECT_NEAR(a.reflect, b.reflect, 1e-12);
}

// The tracer follows the option: through a glass sheet (y = 0) the transmitted ray sees the
// red background, the reflected one a green ceiling (y = 5, ambient only). Off: no green.
// On: green = F kt, red = (1 - F) kt, with F from Schlick at the incidence angle.
void add_quad(SceneData& s, float y, uint32_t material, bool facing_down) {
  SceneObject o;
  o.type = "quad";
  o.first_triangle = static_cast<uint32_t>(s.triangles->triangle_count());
  o.triangle_count = 2;
  s.objects.push_back(o);
  const glm::vec3 q[4] = {{-50, y, -50}, {50, y, -50}, {50, y, 50}, {-50, y, 50}};
  const int tris[2][3] = {{0, 2, 1}, {0, 3, 2}};
  for (const auto& t : tris) {
    for (int k = 0; k < 3; ++k) {
      s.triangles.edit().positions.push_back(q[facing_down ? t[2 - k] : t[k]]);
      s.triangles.edit().normals.push_back({0, facing_down ? -1.f : 1.f, 0});
    }
    s.triangles.edit().object_id.push_back(static_cast<uint32_t>(s.objects.size() - 1));
    s.triangles.edit().material_id.push_back(material);
  }
}

TEST(Fresnel, TracerUsesTheWeights) {
  SceneData s;
  s.background = glm::dvec3(1, 0, 0);
  s.ambient = glm::dvec3(1);
  Material g = glass();
  g.reflect = 0;
  g.diffuse = 0;
  g.ambient = 0;
  s.materials.push_back(g);
  Material ceiling;
  ceiling.color = glm::dvec3(0, 1, 0);
  ceiling.diffuse = 0;
  s.materials.push_back(ceiling);
  add_quad(s, 0.f, 0, false);
  add_quad(s, 5.f, 1, true);
  const glm::dvec3 origin(0, 1, 0), d = glm::normalize(glm::dvec3(1, -0.3, 0));
  const glm::dvec3 c_off = RayTracer(s).trace(origin, d, 0);
  SceneData s2 = s;
  s2.render.fresnel = true;
  const glm::dvec3 c_on = RayTracer(s2).trace(origin, d, 0);
  const double cos_i = 0.3 / std::sqrt(1.09), f0 = 0.04;
  const double f = f0 + (1 - f0) * std::pow(1 - cos_i, 5);
  EXPECT_NEAR(c_off.r, 0.8, 1e-9);
  EXPECT_NEAR(c_off.g, 0.0, 1e-12);
  EXPECT_NEAR(c_on.g, f * 0.8, 1e-9);
  EXPECT_NEAR(c_on.r, (1 - f) * 0.8, 1e-9);
}

}  // namespace
}  // namespace abcube
