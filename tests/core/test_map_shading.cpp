// The cube-map methods end to end (map_shading.hpp): the thesis's hidden-point result,
// and each method's image against the exact tracer on the repository scenes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <utility>

#include "raster/abuffer.hpp"
#include "scene/camera.hpp"
#include "shading/map_shading.hpp"
#include "io/metrics.hpp"
#include "reference/raytrace.hpp"
#include "scene/scene_load.hpp"

// Scene builders, defined in test_raytrace.cpp.
namespace abcube::testkit {
SceneData empty_scene(const glm::dvec3& eye, const glm::dvec3& look_at, double fov_y_deg, int width, int height);
uint32_t add_material(SceneData& s, const Material& m);
uint32_t add_quad(SceneData& s, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d,
                  uint32_t material);
uint32_t add_box(SceneData& s, const glm::dvec3& lo, const glm::dvec3& hi, uint32_t material);
}  // namespace abcube::testkit

namespace abcube {
namespace {

SceneData small_scene(const char* name, int width, int cube_n) {
  SceneData s = load_scene(std::string(ABCUBE_SOURCE_DIR) + "/scenes/" + name);
  const double aspect = static_cast<double>(s.camera.width) / s.camera.height;
  s.camera.width = width;
  s.camera.height = static_cast<int>(width / aspect + 0.5);
  s.render.cube_resolution = cube_n;
  return s;
}

struct Rendered {
  Image image;
  MapShadingStats stats;
};

Rendered render_method(const SceneData& s, MapVariant variant, const RayTracer* reference = nullptr,
                       SearchMode mode = SearchMode::crossing, SearchRefine refine = SearchRefine::mesh) {
  const CubeABuffer cube = build_cube_abuffer(s, s.camera.position, s.render.cube_resolution);
  MapShadingOptions o;
  o.variant = variant;
  o.search.mode = mode;
  o.search.refine = refine;
  const MapShader shader(s, cube, o, reference);
  const ABuffer camera = build_camera_abuffer(s);
  Rendered r;
  r.image = render_with_map(s, camera, shader, 0, &r.stats);
  return r;
}

// A small scene's maps, built once, rendered with several shading options.
struct Maps {
  explicit Maps(SceneData scene)
      : s(std::move(scene)),
        cube(build_cube_abuffer(s, s.camera.position, s.render.cube_resolution)),
        camera(build_camera_abuffer(s)) {}
  Image render(const MapShadingOptions& o, int threads, MapShadingStats* stats) const {
    const MapShader shader(s, cube, o);
    return render_with_map(s, camera, shader, threads, stats);
  }
  const SceneData s;
  const CubeABuffer cube;
  const ABuffer camera;
};

// KNOWN BLOCKERS (map_shading.hpp) in a whole render: most shadow walks of the shadows scene
// end at the blocker its row's previous search found. The image is the one every segment
// walked gives, bit for bit (here the walk misses no blocker the known one answers), and it
// does not depend on the threads (a worker clears them at each row).
TEST(MapShading, KnownBlockersSpareShadowWalksAndChangeNothing) {
  const Maps maps(small_scene("shadows.json", 160, 128));
  const auto render = [&](bool known, int threads, MapShadingStats* stats) {
    MapShadingOptions o;
    o.search.known_blockers = known;
    return maps.render(o, threads, stats);
  };
  MapShadingStats walked, known, one_thread;
  const Image a = render(false, 2, &walked), b = render(true, 2, &known), c = render(true, 1, &one_thread);
  std::printf("[ known    ] %llu of %llu shadow searches; fragments tested %llu -> %llu\n",
              static_cast<unsigned long long>(known.searches.shadow.known_blockers),
              static_cast<unsigned long long>(known.searches.shadow.rays),
              static_cast<unsigned long long>(walked.searches.shadow.fragments),
              static_cast<unsigned long long>(known.searches.shadow.fragments));
  EXPECT_EQ(walked.searches.shadow.known_blockers, 0u);
  EXPECT_EQ(known.searches.shadow.rays, walked.searches.shadow.rays);
  EXPECT_GT(known.searches.shadow.known_blockers, walked.searches.shadow.hits / 2);
  EXPECT_LT(known.searches.shadow.fragments, walked.searches.shadow.fragments);
  EXPECT_EQ(a.data, b.data);
  EXPECT_EQ(b.data, c.data);
  EXPECT_EQ(one_thread.searches.shadow.known_blockers, known.searches.shadow.known_blockers);
}

// SPARSE (map_shading.hpp), on cornell (mirror and glass spheres, shadows) at 128 pixels
// wide: a pixel the sparse pass leaves is the one-point image's, bit for bit; one it shades
// again is the quarters image's (KNOWN BLOCKERS off, so that no answer depends on the order
// of the pixels); the pass takes a minority of the pixels, and the image is as close to the
// exact tracer's as the quarters' and closer than one point's.
TEST(MapShading, SparseShadesTheQuartersOnlyWhereNeighboursDiffer) {
  const Maps maps(small_scene("cornell.json", 128, 96));
  const SceneData& s = maps.s;
  const auto render = [&](bool one, bool sparse, MapShadingStats* stats) {
    MapShadingOptions o;
    o.search.known_blockers = false;
    o.plan = ShadingPlan(one ? (sparse ? ShadingPoints::sparse : ShadingPoints::one) : ShadingPoints::quarters, false,
                         false);
    return maps.render(o, 2, stats);
  };
  MapShadingStats one_stats, sparse_stats, quarters_stats;
  const Image one = render(true, false, &one_stats), sparse = render(true, true, &sparse_stats),
              quarters = render(false, false, &quarters_stats);
  const size_t pixels = static_cast<size_t>(s.camera.width) * static_cast<size_t>(s.camera.height);
  size_t as_one = 0, as_quarters = 0;
  for (size_t p = 0; p < pixels; ++p) {
    const auto same = [&](const Image& a) {
      for (size_t c = 0; c < 3; ++c) {
        if (a.data[3 * p + c] != sparse.data[3 * p + c]) return false;
      }
      return true;
    };
    if (same(one)) ++as_one;
    if (same(quarters)) ++as_quarters;
    EXPECT_TRUE(same(one) || same(quarters)) << "pixel " << p;
  }
  std::printf("[ sparse   ] %llu of %zu pixels shaded again; %zu as one point, %zu as the quarters\n",
              static_cast<unsigned long long>(sparse_stats.sparse_pixels), pixels, as_one, as_quarters);
  EXPECT_GT(sparse_stats.sparse_pixels, pixels / 50);
  EXPECT_LT(sparse_stats.sparse_pixels, pixels / 2);
  EXPECT_EQ(one_stats.sparse_pixels, 0u);
  EXPECT_LT(sparse_stats.multi_point_fragments, quarters_stats.multi_point_fragments / 2);
  const Image exact = render_raytrace(s);
  const double e_one = image_error(one, exact).psnr, e_sparse = image_error(sparse, exact).psnr,
               e_quarters = image_error(quarters, exact).psnr;
  std::printf("[ sparse   ] PSNR one %.2f, sparse %.2f, quarters %.2f dB\n", e_one, e_sparse, e_quarters);
  EXPECT_GT(e_sparse, e_one + 2.0);
  EXPECT_GT(e_sparse, e_quarters - 0.3);
}

// Thesis 7.4.2 and figures 11.3-11.5: in the mirror pixels whose exact reflected ray meets
// the part of the green triangle hidden from the camera by the red one, the A-buffered map
// shows green and the one-layer Z-buffered map does not. The pixel set comes from the
// exact tracer's geometry; only pixels whose 3x3 neighbourhood is in the set are judged.
TEST(MapShading, HiddenPointIsFoundOnlyWithAllLayers) {
  const SceneData s = small_scene("hidden_point.json", 192, 256);
  const RayTracer rt(s);
  uint32_t green = UINT32_MAX, mirror = UINT32_MAX;
  for (uint32_t o = 0; o < s.objects.size(); ++o) {
    const glm::dvec3 c = s.materials[s.objects[o].material].color;
    if (c.g > 0.5 && c.r < 0.5) green = o;
    if (s.materials[s.objects[o].material].reflect > 0) mirror = o;
  }
  ASSERT_NE(green, UINT32_MAX);
  ASSERT_NE(mirror, UINT32_MAX);
  const CameraFrame f = make_camera_frame(s.camera);
  const int w = s.camera.width, h = s.camera.height;
  std::vector<char> hidden(static_cast<size_t>(w * h), 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      Hit m;
      if (!rt.intersect(f.eye, f.direction(x + 0.5, y + 0.5), &m) || m.object_id != mirror) continue;
      const Ray r = rt.reflected_ray(m, glm::normalize(f.direction(x + 0.5, y + 0.5)));
      Hit g;
      if (!rt.intersect(r.origin, r.dir, &g) || g.object_id != green) continue;
      Hit seen;  // what the camera sees in the direction of that green point
      rt.intersect(f.eye, g.point - f.eye, &seen);
      hidden[static_cast<size_t>(y * w + x)] = seen.object_id != green;
    }
  }
  const Image ab = render_method(s, MapVariant::abuffer).image;
  const Image zb = render_method(s, MapVariant::zbuffer).image;
  int judged = 0, ab_green = 0, zb_green = 0;
  for (int y = 1; y + 1 < h; ++y) {
    for (int x = 1; x + 1 < w; ++x) {
      bool inside = true;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) inside = inside && hidden[static_cast<size_t>((y + dy) * w + x + dx)];
      if (!inside) continue;
      ++judged;
      auto is_green = [](glm::vec3 c) { return c.g > 0.2f && c.g > 2.f * c.r && c.g > 2.f * c.b; };
      ab_green += is_green(ab.rgb(x, y));
      zb_green += is_green(zb.rgb(x, y));
    }
  }
  std::printf("[ hidden   ] %d interior pixels see hidden green: abuffer green %d, zbuffer green %d\n", judged,
              ab_green, zb_green);
  EXPECT_GT(judged, 50);
  EXPECT_EQ(ab_green, judged);
  EXPECT_EQ(zb_green, 0);
}

// A box standing on a floor 2 km wide, lit from straight above: the floor is in shadow
// exactly where the segment to the light crosses the box, max(|x|, |z|) <= 0.75 here (the
// box's top face projected from the light), lit beyond. Every pixel whose footprint lies
// clear inside the ring of contact shadow or clear outside it has the closed-form colour, in
// the exact tracer and in abuffer: a shadow ray starts a hair off the floor (shading.hpp
// SELF_INTERSECTION_REL), never as far as the box's height, however wide the scene.
TEST(MapShading, ContactShadowOfABoxOnAWideFloorIsExact) {
  using namespace testkit;
  SceneData s = empty_scene({0.0, 3.0, 2.6}, {0.0, 0.0, 0.2}, 50, 96, 72);
  s.ambient = glm::dvec3(0.2);
  s.background = glm::dvec3(0.0);
  PointLight light;
  light.position = {0, 3, 0};
  s.lights.push_back(light);
  Material floor;
  floor.color = glm::dvec3(0.8);
  const uint32_t floor_m = add_material(s, floor);
  add_quad(s, {-1000, 0, 1000}, {1000, 0, 1000}, {1000, 0, -1000}, {-1000, 0, -1000}, floor_m);
  add_box(s, {-0.5, 0.0, -0.5}, {0.5, 1.0, 0.5}, add_material(s, Material{}));
  s.render.cube_resolution = 256;
  const CameraFrame f = make_camera_frame(s.camera);
  // The floor point seen at image point (x, y), and its class: 1 in the shadow ring, 2 lit;
  // -1 not judged (within `margin` of a boundary, beside or behind the box, or far).
  const auto floor_at = [&](double x, double y) {
    const glm::dvec3 d = f.direction(x, y);
    return f.eye + (-f.eye.y / d.y) * d;
  };
  const double margin = 0.02;
  const auto classify = [&](const glm::dvec3& p) {
    const double m = std::max(std::fabs(p.x), std::fabs(p.z));
    if (p.z < 0.5 + margin) return -1;                       // beside or behind the box: not judged
    if (std::fabs(m - 0.75) < margin || m > 3.0) return -1;  // at the ring's edge, or far (wide footprints)
    return m < 0.75 ? 1 : 2;
  };
  struct Case {
    const char* name;
    Image image;
  };
  const RayTracer rt(s);
  RaytraceOptions ro;
  ro.threads = 2;
  for (const Case& c :
       {Case{"raytrace", render_raytrace(s, ro)}, Case{"abuffer", render_method(s, MapVariant::abuffer).image}}) {
    int ring = 0, lit = 0, wrong = 0;
    for (int y = 0; y < c.image.height; ++y) {
      for (int x = 0; x < c.image.width; ++x) {
        const int k = classify(floor_at(x, y));
        bool same = k > 0;
        for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}, std::pair{1, 1}})
          same = same && classify(floor_at(x + dx, y + dy)) == k;
        if (!same) continue;
        const glm::dvec3 p = floor_at(x + 0.5, y + 0.5);
        const double ndotl = 3.0 / glm::length(light.position - p);
        // Lambert varies across the pixel: 1e-3 covers it at this footprint.
        const glm::dvec3 want = k == 1 ? 0.2 * floor.color : 0.2 * floor.color + ndotl * floor.color;
        (k == 1 ? ring : lit) += 1;
        if (glm::length(glm::dvec3(c.image.rgb(x, y)) - want) > 1e-3) ++wrong;
      }
    }
    std::printf("[ contact  ] %s: %d ring pixels, %d lit, %d off the closed form\n", c.name, ring, lit, wrong);
    EXPECT_GE(ring, 20) << c.name;
    EXPECT_GE(lit, 200) << c.name;
    EXPECT_EQ(wrong, 0) << c.name;
  }
}

// Each method against the exact tracer on the scenes with hidden points and near
// reflectors (hidden_point, cornell): the A-buffered map is clearly closer than the
// Z-buffered map and Blinn-Newell. Measured at these sizes (2026-11-21, with the mesh
// refinement and the per-quarter shading of camera fragments):
//   hidden_point 128 px, N = 256: abuffer 46.6 dB, thesis 44.3, zbuffer 30.1, envmap 25.4
//   cornell      96 px,  N = 256: abuffer 36.2 dB, thesis 24.6, zbuffer 16.7, envmap 15.5
// The floors below are those figures less 2 dB; the margins are what the thesis claims.
// The crossing search without the mesh refinement (SearchRefine::plane) must lose at
// least `refine_gain` dB (measured: 46.6 against 44.4 on hidden_point, 36.2 against 33.8 on
// cornell).
struct MethodCase {
  const char* scene;
  int width;
  double abuffer_min_psnr;
  double refine_gain;
};

// ctest's name for each case ends in this (the default would print the struct's bytes, a
// pointer among them, so the name would change from build to build).
void PrintTo(const MethodCase& c, std::ostream* os) { *os << c.scene; }

class MethodsAgainstReference : public ::testing::TestWithParam<MethodCase> {};

TEST_P(MethodsAgainstReference, AbufferIsClosestToTheExactImage) {
  const MethodCase& c = GetParam();
  const SceneData s = small_scene(c.scene, c.width, 256);
  const RayTracer rt(s);
  const Image ref = render_raytrace(s);
  const Rendered ab = render_method(s, MapVariant::abuffer, &rt);
  const Rendered th = render_method(s, MapVariant::abuffer, &rt, SearchMode::thesis);
  const Rendered zb = render_method(s, MapVariant::zbuffer, &rt);
  const Rendered em = render_method(s, MapVariant::envmap, &rt);
  const Rendered pl = render_method(s, MapVariant::abuffer, nullptr, SearchMode::crossing, SearchRefine::plane);
  const double p_pl = image_error(pl.image, ref).psnr;
  const double p_ab = image_error(ab.image, ref).psnr, p_th = image_error(th.image, ref).psnr;
  const double p_zb = image_error(zb.image, ref).psnr, p_em = image_error(em.image, ref).psnr;
  std::printf(
      "[ methods  ] %s %dpx N=256: abuffer %.1f dB (plane refinement only %.1f), thesis %.1f, "
      "zbuffer %.1f, envmap %.1f\n",
      c.scene, c.width, p_ab, p_pl, p_th, p_zb, p_em);
  std::printf("[ parallax ] abuffer crossing p99 %.2e, thesis p99 %.2e max %.2e, zbuffer misses %.3f\n",
              ab.stats.errors.error_parallax.percentile(0.99), th.stats.errors.error_parallax.percentile(0.99),
              th.stats.errors.error_parallax.max(), zb.stats.errors.error_parallax.miss_share());
  EXPECT_GE(p_ab, c.abuffer_min_psnr);
  EXPECT_GE(p_ab, p_pl + c.refine_gain);
  EXPECT_GT(p_ab, p_zb + 5.0);
  EXPECT_GT(p_ab, p_em + 5.0);
  // Crossing mode: the found point is on the ray (Error_Parallax 0 to rounding).
  EXPECT_LT(ab.stats.errors.error_parallax.max(), 1e-12);
  // Thesis mode: accepted under theta_max, so Error_Parallax <= (1 - cos theta_max)/2.
  const double bound = (1.0 - std::cos(SearchOptions{}.theta_max)) / 2.0;
  EXPECT_LE(th.stats.errors.error_parallax.max(), bound);
  EXPECT_GT(ab.stats.errors.error_parallax.count(), 100u);
}

INSTANTIATE_TEST_SUITE_P(Scenes, MethodsAgainstReference,
                         ::testing::Values(MethodCase{"hidden_point.json", 128, 44.6, 1.0},
                                           MethodCase{"cornell.json", 96, 34.2, 1.0}),
                         // named by the scene ("/cornell"), so that a filter can name it
                         [](const ::testing::TestParamInfo<MethodCase>& info) {
                           const std::string file = info.param.scene;
                           return file.substr(0, file.find('.'));
                         });

}  // namespace
}  // namespace abcube
