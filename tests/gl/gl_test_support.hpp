// Shared by the GL tests: one context per process, chosen by ABCUBE_TEST_GL
// (egl, osmesa, ...; ctest runs every GL test once per API), and hand-built scenes.
#pragma once
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

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

// In the checked builds (ABCUBE_CHECKED_BUILD, tools/sanitize.sh) the same code runs on the
// repository's scenes alone, from their cameras: the sanitizers check code, not scenes.
inline bool checked_build() {
  const char* v = std::getenv("ABCUBE_CHECKED_BUILD");
  return v != nullptr && std::string(v) == "1";
}

// The repository's scenes and, but in the checked builds, the kept hard cases and crosscheck
// regressions, sorted.
inline std::vector<std::string> scene_files() {
  std::vector<std::string> files;
  std::vector<const char*> dirs{"/scenes"};
  if (!checked_build()) dirs.insert(dirs.end(), {"/tests/hard/regressions", "/tests/cli/crosscheck_regressions"});
  for (const char* dir : dirs) {
    for (const auto& e : std::filesystem::directory_iterator(std::string(ABCUBE_SOURCE_DIR) + dir)) {
      if (e.path().extension() == ".json") files.push_back(e.path().string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

// The cubes a GL test builds for a kept scene: from its camera at N = 24 and, but in the checked
// builds, from a point off it at N = 41 (a centre no vertex is aligned with).
inline std::vector<std::pair<glm::dvec3, int>> cube_views(const SceneData& scene) {
  const glm::dvec3 eye = scene.camera.position;
  const glm::dvec3 off = eye + 0.37 * (scene.camera.look_at - eye) + glm::dvec3(0.01, -0.02, 0.03);
  std::vector<std::pair<glm::dvec3, int>> views{{eye, 24}, {off, 41}};
  if (checked_build()) views.pop_back();
  return views;
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
