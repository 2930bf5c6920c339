// Shared by the GL tests: one context per process, chosen by ABCUBE_TEST_GL
// (egl, osmesa, ...; ctest runs every GL test once per API), and hand-built scenes.
#pragma once
#include <cstdlib>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "gl/gl_context.hpp"
#include "scene/scene_data.hpp"

namespace abcube::test {

// The context for this test process; a forced API that fails is a test failure.
inline GlContext& test_context() {
  static std::unique_ptr<GlContext> ctx = [] {
    const char* env = std::getenv("ABCUBE_TEST_GL");
    GlChoice choice = GlChoice::automatic;
    if (env && *env && !parse_gl_choice(env, &choice)) ADD_FAILURE() << "bad ABCUBE_TEST_GL " << env;
    std::string log;
    auto c = open_gl_context(choice, -1, &log);
    if (!c) throw std::runtime_error("no GL context: " + log);
    return c;
  }();
  return *ctx;
}

inline uint32_t add_material(SceneData& s, glm::dvec3 color, double ambient = 1.0) {
  Material m;
  m.name = "m" + std::to_string(s.materials.size());
  m.color = color;
  m.ambient = ambient;
  s.materials.push_back(m);
  return static_cast<uint32_t>(s.materials.size() - 1);
}

inline uint32_t new_object(SceneData& s, const char* type, uint32_t material = 0) {
  if (s.materials.empty()) add_material(s, glm::dvec3(0.8));
  SceneObject o;
  o.type = type;
  o.material = material;
  o.first_triangle = static_cast<uint32_t>(s.triangles->triangle_count());
  s.objects.push_back(o);
  return static_cast<uint32_t>(s.objects.size() - 1);
}

// Appends one flat triangle to object `object` (the last one created).
inline void push_triangle(SceneData& s, uint32_t object, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  const glm::vec3 n = glm::normalize(glm::cross(glm::vec3(b - a), glm::vec3(c - a)));
  for (const glm::dvec3& p : {a, b, c}) {
    s.triangles.edit().positions.push_back(glm::vec3(p));
    s.triangles.edit().normals.push_back(n);
  }
  s.triangles.edit().object_id.push_back(object);
  s.triangles.edit().material_id.push_back(s.objects[object].material);
  s.objects[object].triangle_count++;
}

inline uint32_t add_triangle(SceneData& s, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, uint32_t material = 0) {
  const uint32_t id = new_object(s, "triangle", material);
  push_triangle(s, id, a, b, c);
  return id;
}

inline uint32_t add_quad(SceneData& s, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d, uint32_t material = 0) {
  const uint32_t id = new_object(s, "quad", material);
  push_triangle(s, id, a, b, c);
  push_triangle(s, id, a, c, d);
  return id;
}

// Axis-aligned box [lo, hi] as 12 triangles (6 quads).
inline void add_box(SceneData& s, glm::dvec3 lo, glm::dvec3 hi, uint32_t material = 0) {
  auto p = [&](int x, int y, int z) { return glm::dvec3(x ? hi.x : lo.x, y ? hi.y : lo.y, z ? hi.z : lo.z); };
  add_quad(s, p(0, 0, 0), p(0, 1, 0), p(1, 1, 0), p(1, 0, 0), material);
  add_quad(s, p(0, 0, 1), p(1, 0, 1), p(1, 1, 1), p(0, 1, 1), material);
  add_quad(s, p(0, 0, 0), p(0, 0, 1), p(0, 1, 1), p(0, 1, 0), material);
  add_quad(s, p(1, 0, 0), p(1, 1, 0), p(1, 1, 1), p(1, 0, 1), material);
  add_quad(s, p(0, 0, 0), p(1, 0, 0), p(1, 0, 1), p(0, 0, 1), material);
  add_quad(s, p(0, 1, 0), p(0, 1, 1), p(1, 1, 1), p(1, 1, 0), material);
}

// Thesis figures 11.1-11.2: a white material lit by ambient 1 alone, a black background,
// the camera at (0, 0, 3) looking at the origin. The caller adds the white triangle.
inline SceneData white_on_black_scene(int width, int height, uint32_t* white) {
  SceneData s;
  s.ambient = glm::dvec3(1);
  s.background = glm::dvec3(0);
  s.camera.position = glm::dvec3(0, 0, 3);
  s.camera.look_at = glm::dvec3(0);
  s.camera.width = width;
  s.camera.height = height;
  *white = add_material(s, glm::dvec3(1));
  return s;
}

}  // namespace abcube::test
