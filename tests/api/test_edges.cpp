// Edges inside a pixel, against answers known in closed form: a straight shadow edge
// crossing a floor at a shallow angle (each pixel's lit share is the share of its 32
// samples whose floor point the blocker leaves lit: map_shading.hpp SHADOW EDGES), a wire a
// tenth of a pixel wide (its covered share is the share of samples inside it), a texture's
// edges finer than the shading points (each pixel the mean of its samples' texels, as the
// exact tracer sees them), and a straight edge seen in a mirror (each pixel's share is that
// of its samples whose reflected ray meets the white quad: map_shading.hpp SECONDARY EDGES).
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <abcube/image.hpp>
#include <abcube/renderer.hpp>

#include "api_test_support.hpp"
#include "base/samples.hpp"
#include "scene/camera.hpp"

namespace abcube::test {
namespace {

constexpr int SIZE = 40;

// Seen straight down from (0, 4, 0): a white floor at y = 0 (x to the right of the image, z
// down it), lit only by a point light at (0, 10, 0). The blocker, a black quad at y = 6,
// covers z' < 0.2 + 0.1 x' of that plane; from the light its edge falls on the floor along
// z = 0.5 + 0.1 x, which crosses the image at a slope of 0.1, about 6 degrees from its rows.
// The cube map must resolve the edge to a sample: a texel of the blocker's edge (about 2.1
// from the camera, a texel (pi / 2) / N wide) moves the edge on the floor 2.5 times as far
// (the light is 10 above the floor, 4 above the blocker), and the samples' rows are 1/4 of a
// pixel (2 * 4 tan(20 deg) / 40 on the floor) apart: 2.5 * 2.1 * (pi / 2) / N < 0.018 for N
// above 458, so N = 512. (At N = 256 one pixel of the edge's 36 is two samples off: the
// search's resolution, not the shading's.)
std::string floor_scene(bool blocker) {
  std::string objects =
      R"({"type": "quad", "vertices": [[-8, 0, -8], [-8, 0, 8], [8, 0, 8], [8, 0, -8]], "material": "floor"})";
  if (blocker) {
    objects +=
        R"(, {"type": "quad", "vertices": [[-5, 6, -0.3], [5, 6, 0.7], [5, 6, -20], [-5, 6, -20]], "material": "black"})";
  }
  return R"({"version": 1,
    "camera": {"position": [0, 4, 0], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov_y": 40, "width": )" +
         std::to_string(SIZE) + R"(, "height": )" + std::to_string(SIZE) + R"(},
    "background": [0, 0, 0], "ambient": [0, 0, 0],
    "lights": [{"type": "point", "position": [0, 10, 0], "color": [1, 1, 1], "cast_shadows": true}],
    "materials": {"floor": {"color": [1, 1, 1]}, "black": {"color": [0, 0, 0]}},
    "objects": [)" +
         objects + R"(],
    "render": {"method": "abuffer", "cube_resolution": 512, "max_depth": 0}})";
}

// The scenes' camera: straight down from (0, 4, 0), x to the right of the image, z down it.
CameraFrame overhead_frame() {
  Camera camera;
  camera.position = {0, 4, 0};
  camera.look_at = {0, 0, 0};
  camera.up = {0, 0, -1};
  camera.fov_y_deg = 40;
  camera.width = camera.height = SIZE;
  return make_camera_frame(camera);
}

// The share of pixel (px, py)'s 32 samples whose floor point is lit: by the geometry above,
// the floor point (x, 0, z) is lit where z >= 0.5 + 0.1 x.
double lit_share(const CameraFrame& frame, int px, int py) {
  int lit = 0;
  for (int k = 0; k < MASK_SAMPLES; ++k) {
    const glm::dvec3 d = frame.direction(px + sample_dx(k), py + sample_dy(k));
    const glm::dvec3 p = frame.eye + (-frame.eye.y / d.y) * d;
    lit += p.z >= 0.5 + 0.1 * p.x ? 1 : 0;
  }
  return lit / double(MASK_SAMPLES);
}

// Largest |lit share rendered - lit share known| over the pixels, the rendered share being
// the shadowed image over the unshadowed one (the light's Phong term cancels); and how
// many pixels the edge crosses (a share strictly between 0 and 1).
struct EdgeError {
  double worst = 0;
  int edge_pixels = 0;
};
EdgeError edge_error(const std::string& shadow_edges, nlohmann::json* stats = nullptr) {
  const Scene shadowed = Scene::from_json(floor_scene(true), "edge.json");
  const Scene open = Scene::from_json(floor_scene(false), "open.json");
  Renderer renderer;
  RenderOptions o;
  o.shadow_edges = shadow_edges;
  o.stats = stats != nullptr;
  const RenderResult a = renderer.render(shadowed, o);
  o.stats = false;
  const RenderResult b = renderer.render(open, o);
  if (stats) *stats = nlohmann::json::parse(a.stats.json);
  const CameraFrame frame = overhead_frame();
  EdgeError e;
  for (int y = 0; y < SIZE; ++y) {
    for (int x = 0; x < SIZE; ++x) {
      const size_t at = (static_cast<size_t>(y) * SIZE + static_cast<size_t>(x)) * 3;
      const double known = lit_share(frame, x, y);
      e.edge_pixels += known > 0.0 && known < 1.0 ? 1 : 0;
      e.worst = std::max(e.worst, std::fabs(a.image.data[at] / b.image.data[at] - known));
    }
  }
  return e;
}

// Every pixel within one sample (1/32) of its known lit share, the edge's pixels too.
TEST(Edges, AShadowEdgeIsWithinOneSampleOfItsLitShare) {
  nlohmann::json stats;
  const EdgeError e = edge_error("samples", &stats);
  EXPECT_GE(e.edge_pixels, SIZE / 2);  // the edge crosses the image
  EXPECT_LE(e.worst, 1.0 / 32.0);
  const nlohmann::json& s = stats["searches"]["shadow_edges"];
  EXPECT_GT(s["fragments"].get<uint64_t>(), 0u) << s.dump();
  EXPECT_LT(s["fragments"].get<uint64_t>(), uint64_t{4} * SIZE) << s.dump();  // only along the edge
}

// At the shading points alone the edge is a step a quarter of a pixel wide or more: the
// test above can fail.
TEST(Edges, AtTheShadingPointsAloneTheEdgeSteps) {
  const EdgeError e = edge_error("points");
  EXPECT_GT(e.worst, 1.0 / 32.0);
}

// A wire a tenth of a pixel wide, lit by ambient light only on a black background: each
// pixel's value is the share of its samples inside the wire, exactly.
TEST(Edges, AWireATenthOfAPixelWideCoversItsSamples) {
  // Seen straight down from (0, 4, 0) as above: a pixel is 2 * 4 * tan(20 deg) / SIZE wide on
  // the floor. The wire runs along z = 0.13 + 0.05 x, 0.1 pixel wide measured along z.
  const double pixel = 8.0 * std::tan(glm::radians(20.0)) / SIZE;
  const double half = 0.05 * pixel;
  const auto wire_z = [](double x) { return 0.13 + 0.05 * x; };
  char quad[256];
  std::snprintf(quad, sizeof quad, R"([[-3, 0, %.17g], [-3, 0, %.17g], [3, 0, %.17g], [3, 0, %.17g]])",
                wire_z(-3) - half, wire_z(-3) + half, wire_z(3) + half, wire_z(3) - half);
  const std::string scene_text = R"({"version": 1,
    "camera": {"position": [0, 4, 0], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov_y": 40, "width": )" +
                                 std::to_string(SIZE) + R"(, "height": )" + std::to_string(SIZE) + R"(},
    "background": [0, 0, 0], "ambient": [1, 1, 1], "lights": [],
    "materials": {"wire": {"color": [1, 1, 1]}},
    "objects": [{"type": "quad", "vertices": )" +
                                 std::string(quad) +
                                 R"(, "material": "wire"}],
    "render": {"method": "abuffer", "cube_resolution": 64, "max_depth": 0}})";
  const Scene scene = Scene::from_json(scene_text, "wire.json");
  Renderer renderer;
  const RenderResult r = renderer.render(scene, RenderOptions{});
  const CameraFrame frame = overhead_frame();
  int covered_pixels = 0;
  for (int y = 0; y < SIZE; ++y) {
    for (int x = 0; x < SIZE; ++x) {
      int inside = 0;
      for (int k = 0; k < MASK_SAMPLES; ++k) {
        const glm::dvec3 d = frame.direction(x + sample_dx(k), y + sample_dy(k));
        const glm::dvec3 p = frame.eye + (-frame.eye.y / d.y) * d;
        inside += std::fabs(p.z - wire_z(p.x)) < half ? 1 : 0;
      }
      covered_pixels += inside > 0 ? 1 : 0;
      const size_t at = (static_cast<size_t>(y) * SIZE + static_cast<size_t>(x)) * 3;
      EXPECT_NEAR(r.image.data[at], inside / double(MASK_SAMPLES), 1e-6) << "pixel " << x << ", " << y;
    }
  }
  EXPECT_GE(covered_pixels, SIZE / 2);  // the wire is seen, in some pixels only: it is thin
}

// A floor under ambient light alone, textured with a checkerboard of 64 x 64 squares, 0 and
// 1, that spans 2 units of floor: a square is 0.43 pixel wide, finer than the shading points'
// spacing (half a pixel). With each shading point's base colour averaged over the samples it
// stands for (map_render.cpp), every pixel is the mean of its 32 samples' texels, as the exact
// tracer's 32 rays see them: the colour is affine in the base colour, and ambient light is
// the same at every point. `lookups`: the --texture-lookups value; `cube_map`: through the
// map methods' shading (the plan's passes all run), else the local shading this scene needs.
double texture_error(const std::string& lookups, bool cube_map) {
  const std::string dir = ::testing::TempDir() + "abcube_texture_edges";
  std::filesystem::create_directories(dir);
  Image checker(64, 64, 3);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      for (int c = 0; c < 3; ++c)
        checker.data[(static_cast<size_t>(y) * 64 + static_cast<size_t>(x)) * 3 + c] = float((x + y) % 2);
    }
  }
  write_image(dir + "/checker.exr", checker);
  const std::string text = R"({"version": 1,
    "camera": {"position": [0.013, 4, 0.021], "look_at": [0.013, 0, 0.021], "up": [0.3, 0, -1], "fov_y": 40,
               "width": )" +
                           std::to_string(SIZE) + R"(, "height": )" + std::to_string(SIZE) + R"(},
    "background": [0, 0, 0], "ambient": [1, 1, 1], "lights": [],
    "materials": {"floor": {"color": [1, 1, 1], "ambient": 1, "texture": "checker.exr"}},
    "objects": [{"type": "quad", "vertices": [[-1, 0, -1], [-1, 0, 1], [1, 0, 1], [1, 0, -1]], "material": "floor"}],
    "render": {"method": "abuffer", "cube_resolution": 64, "max_depth": 0}})";
  const Scene scene = Scene::from_json(text, "checker.json", dir);
  Renderer renderer;
  RenderOptions o;
  o.stats = false;
  o.method = "raytrace";
  const RenderResult exact = renderer.render(scene, o);
  o.method = "abuffer";
  o.texture_lookups = lookups;
  o.plan_everything = cube_map;
  const RenderResult a = renderer.render(scene, o);
  double worst = 0;
  for (size_t k = 0; k < a.image.data.size(); ++k)
    worst = std::max(worst, double(std::fabs(a.image.data[k] - exact.image.data[k])));
  return worst;
}

TEST(Edges, ATextureFinerThanTheShadingPointsIsTheMeanOfItsSamples) {
  EXPECT_LT(texture_error("samples", false), 1e-4);
  EXPECT_LT(texture_error("samples", true), 1e-4);
}

// Looked up at the shading points alone, the checkerboard's pixels are off by a good share
// of its contrast: the test above can fail.
TEST(Edges, AtTheShadingPointsAloneATextureAliases) {
  EXPECT_GT(texture_error("points", false), 0.1);
  EXPECT_GT(texture_error("points", true), 0.1);
}

// Seen straight down from (0, 4, 0) as above: a perfect mirror at y = 0 (it shows only what
// it reflects), and above the camera, out of its view, a white quad at y = 8 lit by ambient
// light alone, covering z < 0.2 + 0.1 x of that plane, on a black background. A sample's
// reflected ray is its eye ray mirrored in y = 0, so each pixel's value is the share of its
// samples whose mirrored ray meets the quad. The cube map must place the quad's edge to a
// sample: seen from the mirror, the edge is 12 from the mirrored eye where the floor is 4, so
// a sample row (1/4 pixel, 0.018 on the floor) is 0.055 on the quad's plane, where N = 512
// puts texels about 4.5 * (pi / 2) / 512 = 0.014 wide.
struct MirrorEdge {
  double worst = 0;
  int edge_pixels = 0;
  nlohmann::json stats;
};
MirrorEdge mirror_edge_error(const std::string& secondary_edges) {
  const std::string text = R"({"version": 1,
    "camera": {"position": [0, 4, 0], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov_y": 40, "width": )" +
                           std::to_string(SIZE) + R"(, "height": )" + std::to_string(SIZE) + R"(},
    "background": [0, 0, 0], "ambient": [1, 1, 1], "lights": [],
    "materials": {"mirror": {"color": [0, 0, 0], "ambient": 0, "diffuse": 0, "specular": 0, "reflect": 1},
                  "white": {"color": [1, 1, 1], "ambient": 1}},
    "objects": [
      {"type": "quad", "vertices": [[-8, 0, -8], [-8, 0, 8], [8, 0, 8], [8, 0, -8]], "material": "mirror"},
      {"type": "quad", "vertices": [[-9, 8, -0.7], [9, 8, 1.1], [9, 8, -30], [-9, 8, -30]], "material": "white"}],
    "render": {"method": "abuffer", "cube_resolution": 512, "max_depth": 1}})";
  const Scene scene = Scene::from_json(text, "mirror_edge.json");
  Renderer renderer;
  RenderOptions o;
  o.secondary_edges = secondary_edges;
  const RenderResult r = renderer.render(scene, o);
  MirrorEdge e;
  e.stats = nlohmann::json::parse(r.stats.json);
  const CameraFrame frame = overhead_frame();
  for (int y = 0; y < SIZE; ++y) {
    for (int x = 0; x < SIZE; ++x) {
      int white = 0;
      for (int k = 0; k < MASK_SAMPLES; ++k) {
        glm::dvec3 d = frame.direction(x + sample_dx(k), y + sample_dy(k));
        const glm::dvec3 p = frame.eye + (-frame.eye.y / d.y) * d;  // on the mirror
        d.y = -d.y;
        const glm::dvec3 q = p + (8.0 / d.y) * d;  // on the quad's plane
        white += q.z < 0.2 + 0.1 * q.x ? 1 : 0;
      }
      const double known = white / double(MASK_SAMPLES);
      e.edge_pixels += known > 0.0 && known < 1.0 ? 1 : 0;
      const size_t at = (static_cast<size_t>(y) * SIZE + static_cast<size_t>(x)) * 3;
      e.worst = std::max(e.worst, std::fabs(r.image.data[at] - known));
    }
  }
  return e;
}

// Every pixel within one sample (1/32) of its known share, the pixels whose points all miss
// the edge too, and only the edge's fragments shaded at their samples.
TEST(Edges, AnEdgeSeenInAMirrorIsWithinOneSampleOfItsShare) {
  const MirrorEdge e = mirror_edge_error("samples");
  EXPECT_GE(e.edge_pixels, SIZE / 2);  // the edge crosses the image
  EXPECT_LE(e.worst, 1.0 / 32.0);
  const nlohmann::json& s = e.stats["searches"]["secondary_edges"];
  EXPECT_GT(s["fragments"].get<uint64_t>(), 0u) << s.dump();
  EXPECT_LT(s["fragments"].get<uint64_t>(), uint64_t{4} * SIZE) << s.dump();  // only along the edge
}

// At the shading points alone the reflected edge steps: the test above can fail.
TEST(Edges, AtTheShadingPointsAloneAnEdgeSeenInAMirrorSteps) {
  const MirrorEdge e = mirror_edge_error("points");
  EXPECT_GT(e.worst, 1.0 / 32.0);
  EXPECT_EQ(e.stats["searches"]["secondary_edges"]["fragments"].get<uint64_t>(), 0u);
}

}  // namespace
}  // namespace abcube::test
