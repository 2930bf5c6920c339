// The `gpu` method's lookups against the exact tracer: cube shadow maps per point light,
// and Blinn-Newell reflection from the environment cube texture.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "scene/camera.hpp"
#include "gl/gl_passes.hpp"
#include "gl_test_support.hpp"
#include "base/samples.hpp"
#include "reference/raytrace.hpp"
#include "material/shading.hpp"

namespace abcube {
namespace {

// A 96 x 72 view from `eye` of an 8 x 8 white floor at y = 0 lit by one shadow-casting light.
SceneData floor_scene(glm::dvec3 eye, glm::dvec3 light, double ambient, uint32_t* white, uint32_t* floor) {
  SceneData s;
  s.ambient = glm::dvec3(ambient);
  s.camera.position = eye;
  s.camera.look_at = {0, 0, 0};
  s.camera.width = 96;
  s.camera.height = 72;
  s.lights.push_back({light, glm::dvec3(1.0), true});
  *white = test::add_material(s, glm::dvec3(0.8));
  *floor = test::add_quad(s, {-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, *white);
  return s;
}

// A floor under a floating box and a point light: where the exact tracer says a floor
// pixel centre is shadowed, the GPU pixel is ambient only; where lit, it is brighter.
// Only pixels whose 3x3 neighbourhood agrees in the exact image (away from the shadow's
// edge, where a shadow-map texel straddles it) are counted.
TEST(GpuLookupsGl, CubeShadowMapMatchesExactShadows) {
  test::test_context();
  uint32_t white = 0, floor = 0;
  SceneData s = floor_scene({0, 3, 4}, {1.0, 4.0, -0.5}, 0.2, &white, &floor);
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

// The CPU's rule "shadows" on the GPU: S_l is the product of blocker_transmittance over
// every surface between the point and the light. A tinted glass box (two crossings: kt Od
// squared), a half-opaque veil across part of its shadow (1 - op more) and an opaque
// plate beside them, over a floor: at every floor pixel away from a shadow edge the GPU
// colour is ambient + S_l * lit with S_l from the exact tracer, per channel. Before the
// translucent layers every shadow was black (S_l = 0 under the glass).
TEST(GpuLookupsGl, ShadowMapsMultiplyTransmittances) {
  test::test_context();
  uint32_t white = 0, floor = 0;
  SceneData s = floor_scene({0, 4, 3}, {0.2, 5.0, 0.3}, 0.1, &white, &floor);
  const uint32_t glass = test::add_material(s, glm::dvec3(1.0, 0.6, 0.3));
  s.materials[glass].diffuse = 0;
  s.materials[glass].transmit = 0.9;
  s.materials[glass].ior = 1.5;
  const uint32_t veil = test::add_material(s, glm::dvec3(0.2, 0.4, 1.0));
  s.materials[veil].opacity = 0.5;
  test::add_box(s, {-0.9, 1.0, -0.6}, {0.3, 1.6, 0.6}, glass);
  test::add_quad(s, {-0.3, 2.2, -1.2}, {-0.3, 2.2, 1.2}, {1.5, 2.2, 1.2}, {1.5, 2.2, -1.2}, veil);
  test::add_quad(s, {-1.9, 1.0, -0.6}, {-1.9, 1.0, 0.6}, {-1.2, 1.0, 0.6}, {-1.2, 1.0, -0.6}, white);
  GlScene gl(s);
  ASSERT_EQ(gl.build_shadow_maps(512), 1);
  EXPECT_EQ(gl.shadow_peels(), 3);  // box top, box bottom, veil (the most along one ray)
  EXPECT_FALSE(gl.shadow_peels_capped());
  const Image img = gl.camera_color(s.camera);

  const RayTracer rt(s);
  const CameraFrame f = make_camera_frame(s.camera);
  std::vector<glm::dvec3> visibility(static_cast<size_t>(s.camera.width * s.camera.height), glm::dvec3(-1.0));
  std::vector<glm::dvec3> expected(visibility.size());
  for (int y = 0; y < s.camera.height; ++y) {
    for (int x = 0; x < s.camera.width; ++x) {
      Hit h;
      if (!rt.intersect(f.eye, f.direction(x + 0.5, y + 0.5), &h) || h.object_id != floor) continue;
      const size_t k = static_cast<size_t>(y * s.camera.width + x);
      visibility[k] = rt.light_visibility(h, s.lights[0], nullptr);
      const glm::dvec3 v = glm::normalize(f.eye - h.point);
      expected[k] = phong_ambient(s.materials[white], s.ambient) +
                    visibility[k] * phong_light(s.materials[white], glm::dvec3(0, 1, 0), v,
                                                glm::normalize(s.lights[0].position - h.point), s.lights[0].color);
    }
  }
  std::map<std::string, int> kinds;  // pixels counted per kind of shadow
  double worst = 0;
  for (int y = 1; y + 1 < s.camera.height; ++y) {
    for (int x = 1; x + 1 < s.camera.width; ++x) {
      const glm::dvec3 st = visibility[static_cast<size_t>(y * s.camera.width + x)];
      bool uniform = st.x >= 0;
      for (int dy = -1; dy <= 1 && uniform; ++dy)
        for (int dx = -1; dx <= 1 && uniform; ++dx)
          uniform = glm::length(visibility[static_cast<size_t>((y + dy) * s.camera.width + x + dx)] - st) < 1e-9;
      if (!uniform) continue;
      const glm::dvec3 glass_twice = 0.81 * s.materials[glass].color * s.materials[glass].color;
      const char* kind = st == glm::dvec3(1.0)                        ? "lit"
                         : st == glm::dvec3(0.0)                      ? "opaque"
                         : glm::length(st - glass_twice) < 1e-9       ? "glass"
                         : glm::length(st - 0.5 * glass_twice) < 1e-9 ? "glass and veil"
                                                                      : "other";
      ++kinds[kind];
      const glm::vec3 got = img.rgb(x, y);
      const glm::dvec3 want = expected[static_cast<size_t>(y * s.camera.width + x)];
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(double(got[c]) - want[c]));
    }
  }
  for (const char* kind : {"lit", "opaque", "glass", "glass and veil"})
    EXPECT_GT(kinds[kind], 40) << kind << ": " << kinds["other"] << " other";
  EXPECT_LT(worst, 2e-3);
}

// The camera pass at the A-buffer's 4x8 sample positions: a white triangle on black has,
// in every pixel, the share of the 32 samples (samples.hpp) whose exact ray meets it; a
// view 8 x 300 = 2400 samples wide is rendered in two tiles.
TEST(GpuLookupsGl, CameraSamplesAreTheMaskPositions) {
  test::test_context();
  uint32_t white = 0;
  SceneData s = test::white_on_black_scene(300, 80, &white);
  s.camera.fov_y_deg = 30;
  test::add_triangle(s, {-2.1, -0.7, 0}, {2.3, -0.45, 0}, {-0.2, 0.75, 0}, white);
  GlScene gl(s);
  const Image img = gl.camera_color(s.camera, CameraSamples::mask_4x8);
  const RayTracer rt(s);
  const CameraFrame f = make_camera_frame(s.camera);
  int exact = 0, partial = 0, off = 0;
  for (int y = 0; y < s.camera.height; ++y) {
    for (int x = 0; x < s.camera.width; ++x) {
      int covered = 0;
      for (int k = 0; k < MASK_SAMPLES; ++k) {
        Hit h;
        covered += rt.intersect(f.eye, f.direction(x + sample_dx(k), y + sample_dy(k)), &h);
      }
      const double got = img.rgb(x, y).r * MASK_SAMPLES;
      if (std::abs(got - covered) < 1e-3) {
        ++exact;
        partial += covered > 0 && covered < MASK_SAMPLES;
      } else {
        off += std::abs(got - covered) > 1.001 ? 100 : 1;  // one sample on an edge may round either way
      }
    }
  }
  EXPECT_GT(partial, 300);
  EXPECT_LE(off, 5) << exact << " pixels exact";
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
