// The `gpu` method's lookups against the exact tracer: cube shadow maps per point light,
// and Blinn-Newell reflection from the environment cube texture.
#include <gtest/gtest.h>

#include "scene/camera.hpp"
#include "gl/gl_passes.hpp"
#include "gl_test_support.hpp"
#include "reference/raytrace.hpp"

namespace abcube {
namespace {

// A floor under a floating box and a point light: where the exact tracer says a floor
// pixel centre is shadowed, the GPU pixel is ambient only; where lit, it is brighter.
// Only pixels whose 3x3 neighbourhood agrees in the exact image (away from the shadow's
// edge, where a shadow-map texel straddles it) are counted.
TEST(GpuLookupsGl, CubeShadowMapMatchesExactShadows) {
  test::test_context();
  SceneData s;
  s.ambient = glm::dvec3(0.2);
  s.camera.position = {0, 3, 4};
  s.camera.look_at = {0, 0, 0};
  s.camera.width = 96;
  s.camera.height = 72;
  s.lights.push_back({glm::dvec3(1.0, 4.0, -0.5), glm::dvec3(1.0), true});
  const uint32_t white = test::add_material(s, glm::dvec3(0.8));
  const uint32_t floor = test::add_quad(s, {-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, white);
  test::add_box(s, {-0.6, 0.8, -0.4}, {0.4, 1.5, 0.5}, white);
  GlScene gl(s);
  ASSERT_EQ(gl.build_shadow_maps(256), 1);
  const Image img = gl.camera_color(s.camera);

  const RayTracer rt(s);
  const CameraFrame f = make_camera_frame(s.camera);
  // -1: not the floor; 0: shadowed; 1: lit (exact, at the pixel centre).
  std::vector<int> state(static_cast<size_t>(s.camera.width * s.camera.height), -1);
  for (int y = 0; y < s.camera.height; ++y) {
    for (int x = 0; x < s.camera.width; ++x) {
      Hit h;
      if (!rt.intersect(f.eye, f.direction(x + 0.5, y + 0.5), &h) || h.object_id != floor) continue;
      state[static_cast<size_t>(y * s.camera.width + x)] = rt.light_visibility(h, s.lights[0], nullptr).x > 0.5;
    }
  }
  int counted = 0, wrong = 0, shadowed = 0;
  for (int y = 1; y + 1 < s.camera.height; ++y) {
    for (int x = 1; x + 1 < s.camera.width; ++x) {
      const int st = state[static_cast<size_t>(y * s.camera.width + x)];
      bool uniform = st >= 0;
      for (int dy = -1; dy <= 1 && uniform; ++dy)
        for (int dx = -1; dx <= 1 && uniform; ++dx)
          uniform = state[static_cast<size_t>((y + dy) * s.camera.width + x + dx)] == st;
      if (!uniform) continue;
      ++counted;
      shadowed += st == 0;
      const float ambient_only = 0.2f * 0.8f;
      const bool gpu_lit = img.rgb(x, y).r > ambient_only + 0.01f;
      wrong += gpu_lit != (st == 1);
    }
  }
  EXPECT_GT(counted, 2000);
  EXPECT_GT(shadowed, 100);
  EXPECT_EQ(wrong, 0);
}

// A mirror in a large room of coloured walls: Blinn & Newell's lookup assumes the walls
// are at infinity; with walls 40 units away and the mirror 2 from the eye, the reflected
// colour is the exact one except within a texel or two of a wall's edge.
TEST(GpuLookupsGl, EnvironmentReflectionMatchesExactForFarWalls) {
  test::test_context();
  SceneData s;
  s.ambient = glm::dvec3(1);
  s.camera.position = {0, 0, 0};
  s.camera.look_at = {0, 0, -1};
  s.camera.width = 64;
  s.camera.height = 64;
  const double r = 40;
  const glm::dvec3 colours[] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {0, 1, 1}, {1, 0, 1}};
  std::vector<uint32_t> wall;
  for (const glm::dvec3& c : colours) wall.push_back(test::add_material(s, c));
  test::add_quad(s, {-r, -r, -r}, {-r, r, -r}, {-r, r, r}, {-r, -r, r}, wall[0]);
  test::add_quad(s, {r, -r, -r}, {r, -r, r}, {r, r, r}, {r, r, -r}, wall[1]);
  test::add_quad(s, {-r, -r, -r}, {-r, -r, r}, {r, -r, r}, {r, -r, -r}, wall[2]);
  test::add_quad(s, {-r, r, -r}, {r, r, -r}, {r, r, r}, {-r, r, r}, wall[3]);
  test::add_quad(s, {-r, -r, -r}, {r, -r, -r}, {r, r, -r}, {-r, r, -r}, wall[4]);
  test::add_quad(s, {-r, -r, r}, {-r, r, r}, {r, r, r}, {r, -r, r}, wall[5]);
  const uint32_t mirror = test::add_material(s, glm::dvec3(0), 0.0);
  s.materials[mirror].diffuse = 0;
  s.materials[mirror].reflect = 1;
  // A mirror 2 units ahead, turned 30 degrees about y, filling the view.
  const double c = std::cos(0.5236), sn = std::sin(0.5236);
  auto p = [&](double u, double v) { return glm::dvec3(u * c, v, -2.0 + u * sn); };
  test::add_quad(s, p(-3, -3), p(3, -3), p(3, 3), p(-3, 3), mirror);
  s.render.max_depth = 1;
  GlScene gl(s);
  gl.build_environment(s.camera.position, 256);
  const Image img = gl.camera_color(s.camera);
  const RayTracer rt(s);
  const CameraFrame f = make_camera_frame(s.camera);
  int close = 0, total = 0;
  for (int y = 0; y < s.camera.height; ++y) {
    for (int x = 0; x < s.camera.width; ++x) {
      const glm::dvec3 exact = rt.trace(f.eye, f.direction(x + 0.5, y + 0.5), 0);
      const glm::vec3 got = img.rgb(x, y);
      ++total;
      close += std::abs(got.r - exact.r) < 0.02 && std::abs(got.g - exact.g) < 0.02 && std::abs(got.b - exact.b) < 0.02;
    }
  }
  EXPECT_GT(close, total * 95 / 100) << close << " of " << total;
}

}  // namespace
}  // namespace abcube
