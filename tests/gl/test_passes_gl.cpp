// The GL passes against known answers: prepass distances inside a box, a Z-buffer image
// of a quad, and the GLSL Phong mirror against cpu_core/material/shading.hpp.
#include <cmath>

#include <glad/gl.h>
#include <gtest/gtest.h>

#include "scene/camera.hpp"
#include "scene/scene_load.hpp"
#include "raster/cube_map.hpp"
#include "gl/gl_passes.hpp"
#include "gl_test_support.hpp"
#include "material/shading.hpp"

namespace abcube {
namespace {

// Distance from c along unit u to the inside of the box [lo, hi] that contains c.
double box_exit_distance(glm::dvec3 c, glm::dvec3 u, glm::dvec3 lo, glm::dvec3 hi) {
  double t = INFINITY;
  for (int a = 0; a < 3; ++a) {
    if (u[a] > 0) t = std::min(t, (hi[a] - c[a]) / u[a]);
    if (u[a] < 0) t = std::min(t, (lo[a] - c[a]) / u[a]);
  }
  return t;
}

void expect_box_distances(glm::dvec3 center, glm::dvec3 lo, glm::dvec3 hi, int n) {
  SceneData s;
  test::add_box(s, lo, hi);
  GlScene gl(s);
  CubeImage dist;
  gl.cube_distance(center, n, &dist, nullptr);
  double worst = 0;
  for (int face = 0; face < CUBE_FACES; ++face) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const glm::dvec3 u = glm::normalize(texel_center_direction(face, i, j, n));
        const double expected = box_exit_distance(center, u, lo, hi);
        const double got = dist.faces[face].at(i, j)[0];
        worst = std::max(worst, std::abs(got - expected) / expected);
      }
    }
  }
  EXPECT_LT(worst, 1e-5) << "worst relative distance error over " << 6 * n * n << " texels";
}

// Centred in a box of half-size 1: texel distance = 1 / max(|x|,|y|,|z|) of the unit
// texel-centre direction (design.md).
TEST(PrepassGl, DistanceInsideUnitBox) {
  test::test_context();
  expect_box_distances(glm::dvec3(0), glm::dvec3(-1), glm::dvec3(1), 64);
}

// Off-centre, so a flipped face or axis would put the wrong wall in a texel.
TEST(PrepassGl, DistanceOffCentre) {
  test::test_context();
  expect_box_distances(glm::dvec3(0.3, -0.2, 0.45), glm::dvec3(-1, -0.7, -1.2), glm::dvec3(1.5, 1, 0.8), 32);
}

// Nothing beyond the near plane is clipped, however far: a wall 1e6 away is in the map.
TEST(PrepassGl, NoFarClipping) {
  test::test_context();
  SceneData s;
  test::add_box(s, glm::dvec3(-1e6), glm::dvec3(1e6));
  GlScene gl(s);
  CubeImage dist;
  gl.cube_distance(glm::dvec3(0), 8, &dist, nullptr);
  for (int face = 0; face < CUBE_FACES; ++face) {
    for (float d : dist.faces[face].data) EXPECT_GE(d, 1e6f * 0.999f);
  }
}

// A quad covering a known rectangle of the view: pixels whose centre is inside get the
// material colour (ambient only), the rest the background; exact but for the edge rows.
TEST(ZbufferGl, QuadCoversKnownRectangle) {
  test::test_context();
  SceneData s;
  s.ambient = glm::dvec3(1);
  s.background = glm::dvec3(0.0, 0.0, 1.0);
  s.camera.position = glm::dvec3(0);
  s.camera.look_at = glm::dvec3(0, 0, -1);
  s.camera.up = glm::dvec3(0, 1, 0);
  s.camera.fov_y_deg = 90;
  s.camera.width = 80;
  s.camera.height = 60;
  const uint32_t red = test::add_material(s, glm::dvec3(1, 0, 0));
  // At z = -1 the view spans x in [-4/3, 4/3], y in [-1, 1].
  const double x0 = -0.5, x1 = 0.7, y0 = -0.3, y1 = 0.55;
  test::add_quad(s, {x0, y0, -1}, {x1, y0, -1}, {x1, y1, -1}, {x0, y1, -1}, red);
  GlScene gl(s);
  const Image img = gl.camera_color(s.camera);
  const CameraFrame f = make_camera_frame(s.camera);
  int mismatches = 0, edge = 0;
  for (int y = 0; y < s.camera.height; ++y) {
    for (int x = 0; x < s.camera.width; ++x) {
      const glm::dvec3 d = f.direction(x + 0.5, y + 0.5);
      const double px = d.x / -d.z, py = d.y / -d.z;
      const bool inside = px > x0 && px < x1 && py > y0 && py < y1;
      // Within one pixel of an edge either answer is allowed.
      const double pix = 2.0 * f.tan_half_fov_y / s.camera.height;
      const bool near_edge =
          std::min({std::abs(px - x0), std::abs(px - x1), std::abs(py - y0), std::abs(py - y1)}) < pix;
      const glm::vec3 c = img.rgb(x, y);
      const bool red_here = c.r > 0.99f && c.b < 0.01f;
      const bool bg_here = c.b > 0.99f && c.r < 0.01f;
      if (near_edge) {
        edge += red_here || bg_here ? 0 : 1;
      } else if (inside ? !red_here : !bg_here) {
        ++mismatches;
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(edge, 0) << "edge pixels must be one colour or the other";
}

// The GLSL Phong (common_shading.glsl) equals cpu_core phong_local at pixel centres.
TEST(ZbufferGl, PhongMatchesCpuShading) {
  test::test_context();
  SceneData s;
  s.ambient = glm::dvec3(0.1, 0.15, 0.2);
  s.background = glm::dvec3(0);
  s.camera.position = glm::dvec3(0, 1, 3);
  s.camera.look_at = glm::dvec3(0, 0, 0);
  s.camera.width = 64;
  s.camera.height = 48;
  s.lights.push_back({glm::dvec3(2, 3, 1), glm::dvec3(0.9, 0.8, 0.7), true});
  s.lights.push_back({glm::dvec3(-3, 1, -1), glm::dvec3(0.3, 0.3, 0.5), true});
  const uint32_t m = test::add_material(s, glm::dvec3(0.7, 0.5, 0.3), 0.8);
  s.materials[m].specular = 0.6;
  s.materials[m].shininess = 20;
  test::add_quad(s, {-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, m);  // floor y = 0
  GlScene gl(s);
  const Image img = gl.camera_color(s.camera);
  const CameraFrame f = make_camera_frame(s.camera);
  double worst = 0;
  int checked = 0;
  for (int y = 0; y < s.camera.height; ++y) {
    for (int x = 0; x < s.camera.width; ++x) {
      const glm::dvec3 d = f.direction(x + 0.5, y + 0.5);
      if (d.y >= -1e-3) continue;
      const double t = -f.eye.y / d.y;
      const glm::dvec3 p = f.eye + t * d;
      if (std::abs(p.x) > 2.9 || std::abs(p.z) > 2.9) continue;
      const glm::dvec3 expected = phong_local(s.materials[m], p, glm::dvec3(0, 1, 0), f.eye, s.ambient, s.lights);
      const glm::vec3 got = img.rgb(x, y);
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(got[c] - expected[c]));
      ++checked;
    }
  }
  EXPECT_GT(checked, 500);
  EXPECT_LT(worst, 2e-3);
}

}  // namespace
}  // namespace abcube

namespace abcube {
namespace {

// Thesis figures 11.1-11.2, the Z-buffer half: a white triangle on black through the GPU
// raster has no intermediate edge values, every pixel is 0 or 1 (the A-buffer half, with
// intermediate values matching the covered area, is in tests/core).
TEST(ZbufferGl, WhiteTriangleEdgesAreAliased) {
  test::test_context();
  uint32_t white = 0;
  SceneData s = test::white_on_black_scene(64, 64, &white);
  test::add_triangle(s, {-1, -0.8, 0}, {1.1, -0.5, 0}, {-0.2, 1, 0}, white);
  GlScene gl(s);
  const Image img = gl.camera_color(s.camera);
  int white_pixels = 0, other = 0;
  for (float v : img.data) {
    white_pixels += v == 1.f;
    other += v != 0.f && v != 1.f;
  }
  EXPECT_EQ(other, 0);
  EXPECT_GT(white_pixels, 3 * 500);
}

}  // namespace
}  // namespace abcube

namespace abcube {
namespace {

// The six-face Z-buffer colour pass: at every texel centre, the Phong colour cpu_core
// computes for the exact point of a box wall seen from the centre.
TEST(ZbufferGl, CubeColourMatchesCpuShading) {
  test::test_context();
  SceneData s;
  s.ambient = glm::dvec3(0.2);
  s.lights.push_back({glm::dvec3(0.3, 0.5, -0.2), glm::dvec3(0.8, 0.7, 0.6), true});
  const uint32_t m = test::add_material(s, glm::dvec3(0.3, 0.6, 0.9), 0.7);
  s.materials[m].specular = 0.3;
  s.materials[m].shininess = 8;
  // Walls at unequal distances, so that no texel-centre ray meets a box edge exactly.
  const glm::dvec3 lo(-1.0, -0.8, -1.3), hi(1.2, 1.0, 0.9), center(0.1, -0.13, 0.05);
  test::add_box(s, lo, hi, m);
  GlScene gl(s);
  const int n = 24;
  const CubeImage img = gl.cube_color(center, n);
  double worst = 0;
  for (int face = 0; face < CUBE_FACES; ++face) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const glm::dvec3 u = glm::normalize(texel_center_direction(face, i, j, n));
        double t = INFINITY;
        int axis = 0;
        for (int a = 0; a < 3; ++a) {
          const double ta = u[a] > 0 ? (hi[a] - center[a]) / u[a] : u[a] < 0 ? (lo[a] - center[a]) / u[a] : INFINITY;
          if (ta < t) t = ta, axis = a;
        }
        glm::dvec3 normal(0);
        normal[axis] = 1;
        const glm::dvec3 expected = phong_local(s.materials[m], center + t * u, normal, center, s.ambient, s.lights);
        const glm::vec3 got = img.faces[face].rgb(i, j);
        for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(got[c] - expected[c]));
      }
    }
  }
  EXPECT_LT(worst, 2e-3);
}

}  // namespace
}  // namespace abcube

namespace abcube {
namespace {

// Base-colour textures on the GPU (common_scene.glsl diffuse_color) against the CPU's rule
// (scene/texture.hpp diffuse_color_at) at pixel centres, on the tile mesh (vt 0..2: the
// wrap is crossed): with the textures at level 0 (the CPU's point sample, as `abcube
// crosscheck` samples them) every pixel agrees; with GL's trilinear mipmaps (the `gpu`
// method) the far part, where a pixel spans more than a texel, is filtered: close on
// average, not per pixel.
TEST(ZbufferGl, TexturedFloorMatchesCpuShading) {
  test::test_context();
  const std::string text = R"({"version": 1, "camera": {"position": [0, 1.2, 1.6], "look_at": [0, 0, -0.2], "fov_y": 50,
      "width": 96, "height": 72}, "ambient": [0.2, 0.2, 0.2], "lights": [{"type": "point", "position": [1, 2, 1]}],
      "materials": {"t": {"color": [1, 0.8, 0.9], "texture": "textures/checker.png", "specular": 0.2}},
      "objects": [{"type": "mesh", "file": "meshes/tile.obj", "material": "t"}]})";
  const SceneData s = load_scene_text(text, "floor.json", std::string(ABCUBE_SOURCE_DIR) + "/scenes");
  ASSERT_TRUE(s.textures);
  GlScene gl(s);
  const Image trilinear = gl.camera_color(s.camera);
  gl.set_texture_level0(true);
  const Image img = gl.camera_color(s.camera);
  const CameraFrame f = make_camera_frame(s.camera);
  double worst = 0, spread = 0, trilinear_sum = 0, trilinear_worst = 0;
  int checked = 0;
  glm::dvec3 lo(1e9), hi(-1e9);
  for (int y = 0; y < s.camera.height; ++y) {
    for (int x = 0; x < s.camera.width; ++x) {
      const glm::dvec3 d = f.direction(x + 0.5, y + 0.5);
      if (d.y >= -1e-3) continue;
      const glm::dvec3 p = f.eye + (-f.eye.y / d.y) * d;
      if (std::abs(p.x) > 0.97 || std::abs(p.z) > 0.97) continue;  // the tile's floor face, away from its edges
      // Its two triangles: the one under p.
      uint32_t tri = 0;
      for (uint32_t t = 0; t < 2; ++t) {
        const glm::dvec3 w = barycentric_weights(*s.triangles, t, p);
        if (w.x >= -1e-9 && w.y >= -1e-9 && w.z >= -1e-9) tri = t;
      }
      const glm::dvec3 od = diffuse_color_at(s, tri, p);
      const glm::dvec3 expected = phong_local(s.materials[0], p, glm::dvec3(0, 1, 0), f.eye, s.ambient, s.lights, od);
      const glm::vec3 got = img.rgb(x, y);
      for (int c = 0; c < 3; ++c) {
        worst = std::max(worst, std::abs(got[c] - expected[c]));
        const double d = std::abs(trilinear.rgb(x, y)[c] - expected[c]);
        trilinear_sum += d;
        trilinear_worst = std::max(trilinear_worst, d);
      }
      lo = glm::min(lo, od);
      hi = glm::max(hi, od);
      ++checked;
    }
  }
  spread = hi.r - lo.r;
  EXPECT_GT(checked, 2000);
  EXPECT_GT(spread, 0.3) << "the texture varies over the floor";
  EXPECT_LT(worst, 4e-3);
  EXPECT_LT(trilinear_sum / (3.0 * checked), 0.02);
  EXPECT_GT(trilinear_worst, worst) << "the mipmaps are used";
}

// The scene's arrays as the GL gets them (GlSceneOptions): over the soup's own memory
// (GL_AMD_pinned_memory, where the GL offers it) or copied, each triangle's ids read by the
// vertex stage or carried by every vertex. All draw exactly the same: every pass that reads
// them (the vertex stage; the exact camera pass's storage buffers of positions, normals,
// materials, texture coordinates; the shadow volumes' caps, drawn from the scene's arrays),
// on a textured scene with a mirror and shadow volumes, and on the Cornell box.
TEST(ZbufferGl, PinnedSoupDrawsAsCopiedSoup) {
  GlContext& ctx = test::test_context();
  for (const char* name : {"textured.json", "cornell.json"}) {
    SceneData s = load_scene(std::string(ABCUBE_SOURCE_DIR) + "/scenes/" + name);
    s.camera.width = 80;
    s.camera.height = 60;
    ExactCameraOptions exact;
    exact.planar_mirrors = true;
    exact.shadow_volumes = true;
    exact.max_depth = 2;
    exact.always = true;
    struct Result {
      Image zbuffer, exact;
      std::vector<uint32_t> objects;
    };
    std::vector<Result> results;
    const GlSceneOptions ways[] = {{true, true}, {false, true}, {false, false}};
    for (const GlSceneOptions& way : ways) {
      GlScene gl(s, way);
      EXPECT_EQ(gl.soup_pinned(), way.pin_soup && GLAD_GL_AMD_pinned_memory) << name << " on " << ctx.info().api;
      if (!way.triangle_ids) EXPECT_FALSE(gl.triangle_ids());
      gl.build_shadow_maps(64);
      gl.build_environment(s.camera.position, 64);
      Result r;
      r.zbuffer = gl.camera_color(s.camera, CameraSamples::pixel_centre);
      gl.set_exact_camera(exact);
      r.exact = gl.camera_color(s.camera, CameraSamples::mask_4x8);
      EXPECT_TRUE(gl.exact_camera_stats().volumes) << name << ": " << gl.exact_camera_stats().volumes_why;
      r.objects = gl.camera_objects(s.camera);
      results.push_back(std::move(r));
    }
    for (size_t k = 1; k < results.size(); ++k) {
      for (const bool exact_pass : {false, true}) {
        const Image& a = exact_pass ? results[0].exact : results[0].zbuffer;
        const Image& b = exact_pass ? results[k].exact : results[k].zbuffer;
        ASSERT_EQ(a.data.size(), b.data.size());
        size_t differ = 0;
        for (size_t i = 0; i < a.data.size(); ++i) differ += a.data[i] != b.data[i];
        EXPECT_EQ(differ, 0u) << name << ", way " << k << (exact_pass ? ", exact pass" : ", Z-buffer pass")
                              << ": values that differ";
      }
      EXPECT_EQ(results[0].objects, results[k].objects) << name << ", way " << k;
    }
  }
}

}  // namespace
}  // namespace abcube
