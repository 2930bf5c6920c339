// THE TIE RULE for coincident surfaces (cpu_core/scene/tie_rule.hpp; issue 12 part 2): two
// coplanar overlapping quads of different colours, the green one listed after the red one.
// Every path must show green wherever both are: the exact tracer, the A-buffer (abuffer,
// zbuffer), the GL Z-buffer (gpu), and the map searches (the pair seen in a mirror).
// Flat colours (ambient only, no lights): a pixel's colour is the share of its samples on
// each surface, known from the planes alone, so the images are checked pixel by pixel.
#include <cmath>
#include <sstream>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include <abcube/renderer.hpp>

#include "base/samples.hpp"
#include "scene/camera.hpp"
#include "scene/scene_data.hpp"
#include "scene/tie_rule.hpp"

namespace abcube::test {
namespace {

constexpr const char* MATERIALS =
    R"("materials": {"red": {"color": [1, 0, 0], "diffuse": 0}, "green": {"color": [0, 1, 0], "diffuse": 0},
                     "mirror": {"color": [0, 0, 0], "ambient": 0, "diffuse": 0, "reflect": 1}})";

// A rectangle c + a u + b v, |a| <= ha, |b| <= hb (u, v orthonormal), as a JSON quad.
struct Rect {
  glm::dvec3 c, u, v;
  double ha, hb;
  std::string json(const std::string& material) const {
    std::ostringstream s;
    s.precision(17);
    const double sa[4] = {-1, 1, 1, -1}, sb[4] = {-1, -1, 1, 1};
    s << R"({"type": "quad", "material": ")" << material << R"(", "vertices": [)";
    for (int k = 0; k < 4; ++k) {
      const glm::dvec3 p = c + sa[k] * ha * u + sb[k] * hb * v;
      s << (k ? ", " : "") << "[" << p.x << ", " << p.y << ", " << p.z << "]";
    }
    s << "]}";
    return s.str();
  }
  // 0: outside, 1: inside; the ray o + t d meets the rectangle's plane at t > 0.
  bool hit(const glm::dvec3& o, const glm::dvec3& d, glm::dvec3* p = nullptr) const {
    const glm::dvec3 n = glm::cross(u, v);
    const double den = glm::dot(n, d);
    if (den == 0.0) return false;
    const double t = glm::dot(n, c - o) / den;
    if (!(t > 0.0)) return false;
    const glm::dvec3 q = o + t * d - c;
    if (p) *p = o + t * d;
    return std::fabs(glm::dot(q, u)) <= ha && std::fabs(glm::dot(q, v)) <= hb;
  }
};

// Red listed first, green second, both in one plane.
struct CoplanarPair {
  Rect red, green;
  // The colour a ray sees: green where the green quad is, else red, else the background.
  glm::dvec3 seen(const glm::dvec3& o, const glm::dvec3& d) const {
    if (green.hit(o, d)) return {0, 1, 0};
    if (red.hit(o, d)) return {1, 0, 0};
    return {0, 0, 1};
  }
};

std::string scene_json(const std::string& camera, const std::string& objects) {
  std::ostringstream s;
  s << R"({"version": 1, "camera": )" << camera << R"(, "background": [0, 0, 1], "ambient": [1, 1, 1],
    "lights": [], )"
    << MATERIALS << R"(, "objects": [)" << objects
    << R"(], "render": {"method": "abuffer", "cube_resolution": 128, "max_depth": 2}})";
  return s.str();
}

// A tilted plane (normal (0, 1, 0.35)): its vertices are rounded to float, so the two quads'
// triangles are coplanar only to float precision, as a user's would be.
CoplanarPair tilted_pair() {
  const glm::dvec3 n = glm::normalize(glm::dvec3(0.1, 1.0, 0.35));
  const glm::dvec3 u = glm::normalize(glm::cross(n, glm::dvec3(0.0, 0.0, 1.0)));
  const glm::dvec3 v = glm::cross(u, n);  // u x v = n: facing up
  const glm::dvec3 c(0.013, 0.31, -0.027);
  return {{c, u, v, 0.71, 0.53}, {c + 0.37 * u + 0.23 * v, u, v, 0.52, 0.44}};
}

CoplanarPair flat_pair() {
  const glm::dvec3 u(0, 0, 1), v(1, 0, 0);  // u x v = +y
  return {{{0.02, 0.0, -0.01}, u, v, 0.7, 0.55}, {{0.31, 0.0, 0.27}, u, v, 0.5, 0.45}};
}

// Every pixel of `image` against the colours `seen` gives at its 32 samples (every method,
// gpu too, samples them). Returns the pixels that differ by more than `samples_off` samples'
// worth (the GL raster may put a sample lying on an edge, to float rounding, on either
// side) plus 1e-5.
template <class Seen>
int wrong_pixels(const Image& image, const CameraFrame& frame, Seen&& seen, int* green_pixels, int samples_off = 0) {
  int wrong = 0;
  *green_pixels = 0;
  for (int y = 0; y < frame.height; ++y) {
    for (int x = 0; x < frame.width; ++x) {
      glm::dvec3 expected(0.0);
      for (int k = 0; k < MASK_SAMPLES; ++k)
        expected += seen(frame.eye, frame.direction(x + sample_dx(k), y + sample_dy(k)));
      expected /= double(MASK_SAMPLES);
      *green_pixels += expected == glm::dvec3(0, 1, 0);
      const glm::dvec3 got(image.rgb(x, y));
      const glm::dvec3 e = glm::abs(got - expected);
      if (std::max(e.x, std::max(e.y, e.z)) > 1e-5 + samples_off / double(MASK_SAMPLES)) {
        if (wrong < 5)
          ADD_FAILURE() << "pixel " << x << ", " << y << ": " << got.x << " " << got.y << " " << got.z << ", expected "
                        << expected.x << " " << expected.y << " " << expected.z;
        ++wrong;
      }
    }
  }
  return wrong;
}

// The pixels whose every sample (every method, gpu too, samples the 32) `seen` gives
// `colour`: how many, and how many of them `image` does not show in that colour (1e-5, plus
// `samples_off` samples' worth: the GL raster's depth at 3 degrees may lose one sample).
template <class Seen>
std::pair<int, int> uniform_pixels(const Image& image, const CameraFrame& frame, Seen&& seen, const glm::dvec3& colour,
                                   int samples_off = 0) {
  int checked = 0, wrong = 0;
  for (int y = 0; y < frame.height; ++y) {
    for (int x = 0; x < frame.width; ++x) {
      bool all = true;
      for (int k = 0; k < MASK_SAMPLES && all; ++k) {
        all = seen(frame.eye, frame.direction(x + sample_dx(k), y + sample_dy(k))) == colour;
      }
      if (!all) continue;
      ++checked;
      const glm::dvec3 e = glm::abs(glm::dvec3(image.rgb(x, y)) - colour);
      if (std::max(e.x, std::max(e.y, e.z)) > 1e-5 + samples_off / double(MASK_SAMPLES)) {
        if (wrong < 5) ADD_FAILURE() << "pixel " << x << ", " << y << " is not the colour of all its samples";
        ++wrong;
      }
    }
  }
  return {checked, wrong};
}

class CoplanarQuads : public ::testing::TestWithParam<std::string> {};

// The pair seen from above at 40 degrees: every method shows the later (green) quad
// wherever the two overlap, pixel for pixel.
TEST_P(CoplanarQuads, TheLaterObjectWinsOnEveryPath) {
  const std::string camera =
      R"({"position": [0.4, 1.9, 2.1], "look_at": [0.1, 0.1, 0.05], "fov_y": 45, "width": 64, "height": 48})";
  for (const bool tilted : {false, true}) {
    const CoplanarPair pair = tilted ? tilted_pair() : flat_pair();
    const Scene scene =
        Scene::from_json(scene_json(camera, pair.red.json("red") + ", " + pair.green.json("green")), "coplanar.json");
    Renderer renderer(RendererOptions{GetParam() == "gpu" ? "auto" : "none", -1, 0});
    RenderOptions o;
    o.method = GetParam();
    const Image image = renderer.render(scene, o).image;
    const CameraFrame frame = make_camera_frame(scene.data().camera);
    int green = 0;
    const int wrong = wrong_pixels(
        image, frame, [&](const glm::dvec3& eye, const glm::dvec3& d) { return pair.seen(eye, d); }, &green,
        GetParam() == "gpu" ? 1 : 0);
    EXPECT_EQ(wrong, 0) << GetParam() << (tilted ? ", tilted plane" : ", plane y = 0");
    EXPECT_GE(green, 200) << "the overlap fills many pixels";
  }
}

INSTANTIATE_TEST_SUITE_P(Methods, CoplanarQuads, ::testing::Values("raytrace", "abuffer", "zbuffer", "gpu"));

// The same pair on a wall (plane x = 3, facing -x), seen only in a 45-degree mirror: the
// map searches meet both quads at the same distance and must also pick the later one.
// Mirror pixels whose 32 samples all see green must be exactly green; every raytrace pixel
// is exact.
TEST(CoplanarQuadsInAMirror, TheSearchesPickTheLaterObject) {
  const glm::dvec3 u(0, 0, 1), v(0, 1, 0);  // u x v = -x: facing the mirror
  const CoplanarPair pair{{{3, 1.02, -2.03}, u, v, 0.8, 0.6}, {{3, 1.23, -1.77}, u, v, 0.55, 0.5}};
  const Rect mirror{{0, 1, -2}, glm::normalize(glm::dvec3(1, 0, -1)), {0, 1, 0}, 1.2, 1.0};
  // mirror: u x v = (1, 0, 1)/sqrt 2, facing the camera; flip to keep it one-sided-agnostic
  const std::string objects = pair.red.json("red") + ", " + pair.green.json("green") + ", " + mirror.json("mirror");
  const std::string camera =
      R"({"position": [0.03, 1.04, 0.5], "look_at": [0, 1, -2], "fov_y": 40, "width": 48, "height": 48})";
  const Scene scene = Scene::from_json(scene_json(camera, objects), "coplanar_mirror.json");
  const CameraFrame frame = make_camera_frame(scene.data().camera);
  const auto seen = [&](const glm::dvec3& eye, const glm::dvec3& d) -> glm::dvec3 {
    glm::dvec3 p;
    if (!mirror.hit(eye, d, &p)) return pair.seen(eye, d);
    const glm::dvec3 n = glm::normalize(glm::cross(mirror.u, mirror.v));
    const glm::dvec3 dn = glm::normalize(d);
    return pair.seen(p, dn - 2.0 * glm::dot(dn, n) * n);
  };
  Renderer renderer(RendererOptions{"none", -1, 0});
  RenderOptions o;
  o.method = "raytrace";
  int green = 0;
  EXPECT_EQ(wrong_pixels(renderer.render(scene, o).image, frame, seen, &green), 0) << "raytrace";
  EXPECT_GE(green, 100);
  for (const std::string method : {"abuffer", "zbuffer"}) {
    o.method = method;
    const Image image = renderer.render(scene, o).image;
    const auto [checked, wrong] = uniform_pixels(image, frame, seen, glm::dvec3(0, 1, 0));
    EXPECT_EQ(wrong, 0) << method << ": " << checked << " all-green mirror pixels checked";
    EXPECT_GE(checked, 100) << method;
  }
}

// Not a tie: a decal 1e-4 of the floor's size above it (the thinnest of the hard suite),
// listed BEFORE the floor, so a tie would hand it to the floor. Seen at 3 to 60 degrees,
// the rule keeps it in front: same_distance is false on every eye ray that meets it, and
// raytrace, abuffer and gpu show it wherever it covers the whole pixel (or its centre).
TEST(CoplanarQuads, ADecalIsNotATie) {
  const double size = 10.0, offset = 1e-4 * size;
  const glm::dvec3 u(0, 0, 1), v(1, 0, 0);
  const Rect decal{{0.05, offset, 0.02}, u, v, 1.5, 0.3}, floor{{0, 0, 0}, u, v, size / 2, size / 2};
  for (const double elevation : {3.0, 10.0, 60.0}) {
    const double e = elevation * M_PI / 180.0;
    std::ostringstream camera;
    camera.precision(17);
    camera << R"({"position": [0.3, )" << 2.5 * std::sin(e) << ", " << 2.5 * std::cos(e)
           << R"(], "look_at": [0.05, 0, 0.02], "fov_y": 20, "width": 64, "height": 48})";
    const Scene scene =
        Scene::from_json(scene_json(camera.str(), decal.json("red") + ", " + floor.json("green")), "decal.json");
    const SceneData& data = scene.data();
    const CameraFrame frame = make_camera_frame(data.camera);
    // The rule on every sample ray that meets the decal: never the same distance as the floor.
    int rays = 0, ties = 0;
    for (int y = 0; y < frame.height; ++y) {
      for (int x = 0; x < frame.width; ++x) {
        const glm::dvec3 d = frame.direction(x + 0.5, y + 0.5);
        glm::dvec3 p;
        if (!decal.hit(frame.eye, d, &p)) continue;
        const double t_decal = glm::dot(p - frame.eye, d) / glm::dot(d, d);
        const double t_floor = -frame.eye.y / d.y;
        for (uint32_t td = 0; td < 2; ++td) {  // the decal's two triangles against the floor's
          ++rays;
          ties += same_distance(*data.triangles, d, {td, t_decal}, {2 + td, t_floor});
        }
      }
    }
    EXPECT_GT(rays, 100) << elevation << " degrees";
    EXPECT_EQ(ties, 0) << elevation << " degrees";
    const auto seen = [&](const glm::dvec3& eye, const glm::dvec3& d) -> glm::dvec3 {
      if (decal.hit(eye, d)) return {1, 0, 0};
      if (floor.hit(eye, d)) return {0, 1, 0};
      return {0, 0, 1};
    };
    for (const std::string method : {"raytrace", "abuffer", "gpu"}) {
      Renderer renderer(RendererOptions{method == "gpu" ? "auto" : "none", -1, 0});
      RenderOptions o;
      o.method = method;
      const Image image = renderer.render(scene, o).image;
      const auto [checked, wrong] = uniform_pixels(image, frame, seen, glm::dvec3(1, 0, 0), method == "gpu" ? 1 : 0);
      EXPECT_GE(checked, 20) << method << " at " << elevation << " degrees";
      EXPECT_EQ(wrong, 0) << method << " at " << elevation << " degrees: decal pixels not red";
    }
  }
}

}  // namespace
}  // namespace abcube::test
