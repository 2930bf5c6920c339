// The searches in the A-buffered cube map (search.hpp) against the exact tracer on the same
// triangles (raytrace.hpp): reflections in both modes, the hidden point (A-buffer vs one
// layer), refraction exits and total internal reflection, shadows, and the degenerate
// cases of the walk.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include "base/error.hpp"
#include "raster/abuffer.hpp"
#include "abuffer_testkit.hpp"
#include "scene/camera.hpp"
#include "search/cube_walk.hpp"
#include "io/metrics.hpp"
#include "reference/raytrace.hpp"
#include "scene/scene_load.hpp"
#include "search/search.hpp"
#include "material/shading.hpp"

namespace abcube {
namespace {

using glm::dvec3;
using namespace testkit;

// A scene, its exact tracer and its cube map around the camera.
struct World {
  SceneData scene;
  std::unique_ptr<RayTracer> tracer;
  CubeABuffer cube;
  std::unique_ptr<SearchContext> ctx;
  int n = 0;
};

std::unique_ptr<World> make_world(SceneData scene, int n, bool merge = false) {
  auto w = std::make_unique<World>();
  w->scene = std::move(scene);
  w->n = n;
  w->tracer = std::make_unique<RayTracer>(w->scene);
  w->cube = build_cube_abuffer(w->scene, w->scene.camera.position, n, abtest::test_options(merge));
  w->ctx = std::make_unique<SearchContext>(w->scene, w->cube);
  return w;
}

// A ray leaving a surface: origin on the surface, unit direction, the surface's geometric normal.
struct SurfaceRay {
  dvec3 w, r, normal;
};

// The exact answer for a surface ray, from the origin moved off the surface (rule "offset").
bool exact_hit(const World& world, const SurfaceRay& s, Hit* hit, double tmax = HUGE_VAL) {
  const dvec3 o = offset_origin(s.w, s.normal, s.r, self_intersection_offset(s.w, world.tracer->scene_scale()));
  return world.tracer->intersect(o, s.r, tmax, hit);
}

// Is the exact answer stable under moving the ray's end by `texels` map texels (at the hit,
// or at distance 10 for a miss) in eight directions? False near silhouettes.
bool away_from_silhouettes(const World& world, const SurfaceRay& s, double texels = 2.0) {
  Hit h;
  const bool hit = exact_hit(world, s, &h);
  const dvec3 end = hit ? h.point : s.w + 10.0 * s.r;
  const double delta = texels * texel_size_at(end - world.cube.centre, world.n);
  const dvec3 e1 = glm::normalize(glm::cross(s.r, std::fabs(s.r.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0)));
  const dvec3 e2 = glm::cross(s.r, e1);
  const double c = std::sqrt(0.5);
  for (const dvec3& e : {e1, -e1, e2, -e2, c * (e1 + e2), c * (e1 - e2), c * (e2 - e1), -c * (e1 + e2)}) {
    Hit h2;
    const SurfaceRay moved{s.w, glm::normalize(end + delta * e - s.w), s.normal};
    const bool hit2 = exact_hit(world, moved, &h2);
    if (hit2 != hit || (hit && h2.object_id != h.object_id)) return false;
  }
  return true;
}

// Reflection rays from the camera-visible points of reflective surfaces (a grid of pixel centres).
std::vector<SurfaceRay> mirror_rays(const World& world, int cols, int rows) {
  const CameraFrame frame = make_camera_frame(world.scene.camera);
  std::vector<SurfaceRay> out;
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      const dvec3 d = glm::normalize(frame.direction((x + 0.5) * frame.width / cols, (y + 0.5) * frame.height / rows));
      Hit h;
      if (!world.tracer->intersect(frame.eye, d, &h)) continue;
      if (world.scene.materials[h.material_id].reflect <= 0.0) continue;
      out.push_back({h.point, world.tracer->reflected_ray(h, d).dir, h.geometric_normal});
    }
  }
  return out;
}

// A perfect mirror material added to s.
uint32_t add_mirror(SceneData& s) {
  Material mirror;
  mirror.reflect = 1.0;
  return add_material(s, mirror);
}

// Mirror floor and back wall, a box, a sphere, a tilted triangle, and a box behind the camera.
SceneData reflection_scene() {
  SceneData s = empty_scene({0.3, 1.6, 4.2}, {0, 0.3, 0}, 60, 320, 240);
  const uint32_t m = add_mirror(s);
  const uint32_t red = add_material(s, emissive({1, 0, 0}));
  const uint32_t blue = add_material(s, emissive({0, 0, 1}));
  add_quad(s, {-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, m);
  add_box(s, {-1.6, 0.2, -1.2}, {-0.6, 1.4, -0.2}, red);
  add_sphere(s, {1.0, 0.8, -0.6}, 0.7, 24, blue);
  begin_object(s, "triangle", red, false);
  add_flat_triangle(s, {-0.5, 0.3, 1.0}, {0.6, 0.2, 0.8}, {0.0, 1.3, 0.2});
  add_quad(s, {-4, 0, -3}, {4, 0, -3}, {4, 3, -3}, {-4, 3, -3}, m);
  add_box(s, {-0.6, 0.8, 4.8}, {1.2, 2.4, 5.4}, blue);  // behind the camera, seen in the back wall
  return s;
}

TEST(Search, ReflectionCrossingMatchesExactTracer) {
  const auto world = make_world(reflection_scene(), 96);
  const std::vector<SurfaceRay> rays = mirror_rays(*world, 80, 60);
  ASSERT_GT(rays.size(), 1000u);
  int interior = 0, same = 0, both_miss = 0, hits = 0;
  double worst_parallax = 0;
  SearchKindStats stats;
  for (const SurfaceRay& s : rays) {
    const SearchResult r = reflection_search(*world->ctx, s.w, s.r);
    stats.add(r);
    if (r.hit) {
      ++hits;
      worst_parallax = std::max(worst_parallax, error_parallax(r.point, s.w, s.r));
      // The refined point is within the tolerance of its triangle (in texels at the point).
      EXPECT_LE(r.outside_texels, SearchOptions().tolerance_texels);
    }
    if (!away_from_silhouettes(*world, s)) continue;
    ++interior;
    Hit h;
    const bool exact = exact_hit(*world, s, &h);
    if (!exact && !r.hit) ++both_miss;
    if (exact && r.hit && r.triangle == h.triangle) {
      ++same;
      // Same triangle: the refined point is the exact point, to the tracer's origin offset
      // (1e-9 of the scene scale, shading.hpp) and rounding.
      EXPECT_LT(glm::length(r.point - h.point), 1e-7 * world->tracer->scene_scale());
    }
  }
  std::printf(
      "crossing: %zu rays, %d away from silhouettes, same triangle %d, both miss %d; hits %d; "
      "max Error_Parallax %.3g; texels mean %.1f max %llu\n",
      rays.size(), interior, same, both_miss, hits, worst_parallax, stats.mean_texels(),
      static_cast<unsigned long long>(stats.max_texels));
  EXPECT_GE(same + both_miss, 0.99 * interior);
  EXPECT_LT(worst_parallax, 1e-12);  // a refined point is on the ray
  EXPECT_EQ(stats.aborted, 0u);
}

TEST(Search, MergedMapStillFindsTheSameObject) {
  // With merging (the renderer's default) a fragment carries one triangle for several: the
  // object is still right and the point on the neighbouring triangle's plane.
  const auto world = make_world(reflection_scene(), 96, true);
  int interior = 0, same_object = 0, same_triangle = 0;
  for (const SurfaceRay& s : mirror_rays(*world, 80, 60)) {
    if (!away_from_silhouettes(*world, s)) continue;
    ++interior;
    const SearchResult r = reflection_search(*world->ctx, s.w, s.r);
    Hit h;
    const bool exact = exact_hit(*world, s, &h);
    if (exact != r.hit) continue;
    same_object += !exact || h.object_id == r.object_id;
    same_triangle += !exact || h.triangle == r.triangle;
  }
  std::printf("merged map: %d interior rays, same object %d, same triangle %d\n", interior, same_object, same_triangle);
  EXPECT_GE(same_object, 0.99 * interior);
}

// The thesis mode's ideal candidate for a ray with exact hit h: the texel holding the true
// point's direction (seen from C, at angle theta_c from it), its centre's point on the hit
// plane, and that point's angle theta_0 seen from W.
struct IdealCandidate {
  double theta_c = 0, theta_0 = 0;
};

IdealCandidate ideal_candidate(const World& world, const SurfaceRay& s, const Hit& h) {
  const dvec3 sc = h.point - world.cube.centre;
  const CubeTexel t = direction_to_texel(sc, world.n);
  const dvec3 v = texel_center_direction(t.face, t.i, t.j, world.n);
  const dvec3 p = world.cube.centre + (glm::dot(h.geometric_normal, sc) / glm::dot(h.geometric_normal, v)) * v;
  const auto angle = [](const dvec3& a, const dvec3& b) {
    return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
  };
  return {angle(v, sc), angle(s.r, p - s.w)};
}

TEST(Search, ReflectionThesisModeErrorBounds) {
  // thesis 9.3.4: the texel holding the true point's direction has its centre within half a
  // texel diagonal of it seen from C, theta_c <= atan(sqrt(2)/N); the thesis takes the
  // same angle seen from W, giving Error_Parallax <= theta^2/4 = 1/(2 N^2). Seen from W the
  // angle is theta_0 = A theta_c, A ~ |S| / (|S - W| cos(view angle on the hit plane)), S
  // the point relative to C. So the bound holds where A <= 1, and is exceeded by A^2
  // elsewhere. Always: angle <= theta_max and Error_Parallax <= theta_max^2/4.
  for (const int n : {64, 128}) {
    const auto world = make_world(reflection_scene(), n);
    SearchOptions o;
    o.mode = SearchMode::thesis;
    ErrorStats all, plain;
    int worse_than_ideal = 0, misses_explained = 0, amplified = 0;
    for (const SurfaceRay& s : mirror_rays(*world, 64, 48)) {
      if (!away_from_silhouettes(*world, s)) continue;
      Hit h;
      if (!exact_hit(*world, s, &h)) continue;
      const IdealCandidate ideal = ideal_candidate(*world, s, h);
      EXPECT_LE(ideal.theta_c, std::atan(std::sqrt(2.0) / n) * (1 + 1e-9));
      const SearchResult r = reflection_search(*world->ctx, s.w, s.r, o);
      if (!r.hit) {
        all.add_miss();
        EXPECT_EQ(r.miss, MissReason::threshold_rejection);
        misses_explained += ideal.theta_0 > o.theta_max;
        continue;
      }
      EXPECT_LE(r.angle, o.theta_max);
      worse_than_ideal += r.angle > ideal.theta_0 * (1 + 1e-6);
      const double e = error_parallax(r.point, s.w, s.r);
      EXPECT_LE(e, o.theta_max * o.theta_max / 4.0 * (1 + 1e-9));
      all.add(e);
      if (ideal.theta_0 <= ideal.theta_c) {
        plain.add(e);
        EXPECT_LE(e, 1.0 / (2.0 * n * n) * (1 + 1e-6));
      } else {
        ++amplified;
      }
    }
    std::printf(
        "thesis N=%d: hits %llu, misses %llu (ideal texel over theta_max: %d); Error_Parallax mean %.3g "
        "p99 %.3g max %.3g vs 1/(2N^2) = %.3g; amplified (theta_0 > theta_c) %d, not amplified %llu with max "
        "%.3g; found worse than the ideal texel %d\n",
        n, static_cast<unsigned long long>(all.count()), static_cast<unsigned long long>(all.miss_count()),
        misses_explained, all.mean(), all.percentile(0.99), all.max(), 1.0 / (2.0 * n * n), amplified,
        static_cast<unsigned long long>(plain.count()), plain.max(), worse_than_ideal);
    EXPECT_EQ(misses_explained, static_cast<int>(all.miss_count()));
    EXPECT_GT(plain.count(), 20u);  // the mirror wall sees the box behind the camera
  }
}

// thesis 7.4.2, fig. 7.5: reflected points hidden from C by a nearer surface.
TEST(Search, HiddenPointFoundOnlyWithAllLayers) {
  const auto world = make_world(load_scene(std::string(ABCUBE_SOURCE_DIR) + "/scenes/hidden_point.json"), 128);
  const uint32_t red = 1, green = 2;
  const dvec3 c = world->cube.centre;
  int hidden = 0, all_green = 0, nearest_green = 0, nearest_red_or_miss = 0;
  SearchOptions zbuffer;
  zbuffer.layers = SearchLayers::nearest;
  for (const SurfaceRay& s : mirror_rays(*world, 256, 192)) {
    Hit h, from_c;
    if (!exact_hit(*world, s, &h) || h.object_id != green) continue;
    // Hidden: from the centre, red comes before the green point, also 2 texels around it
    // (the one-layer map's red silhouette is exact to a texel only).
    const double delta = 2.0 * texel_size_at(h.point - c, world->n);
    bool hidden_here = true;
    for (const dvec3& e :
         {dvec3(0), dvec3(delta, 0, 0), dvec3(-delta, 0, 0), dvec3(0, delta, 0), dvec3(0, -delta, 0)}) {
      hidden_here =
          hidden_here && world->tracer->intersect(c, h.point + e - c, 1.0 - 1e-9, &from_c) && from_c.object_id == red;
    }
    if (!hidden_here) continue;
    if (!away_from_silhouettes(*world, s)) continue;
    ++hidden;
    const SearchResult a = reflection_search(*world->ctx, s.w, s.r);
    const SearchResult z = reflection_search(*world->ctx, s.w, s.r, zbuffer);
    all_green += a.hit && a.object_id == green;
    nearest_green += z.hit && z.object_id == green;
    nearest_red_or_miss += !z.hit || z.object_id == red;
  }
  std::printf("hidden point: %d rays; all layers green %d; nearest layer green %d, red or miss %d\n", hidden, all_green,
              nearest_green, nearest_red_or_miss);
  ASSERT_GT(hidden, 50);
  EXPECT_GE(all_green, 0.99 * hidden);
  EXPECT_EQ(nearest_green, 0);
  EXPECT_EQ(nearest_red_or_miss, hidden);
}

// Glass sphere and glass box in front of a wall.
SceneData glass_scene() {
  SceneData s = empty_scene({0.2, 1.2, 4.0}, {0, 0.6, 0}, 50, 320, 240);
  Material glass;
  glass.transmit = 0.9;
  glass.ior = 1.5;
  glass.color = {0.9, 0.95, 1.0};
  const uint32_t g = add_material(s, glass);
  const uint32_t wall = add_material(s, emissive({0.5, 0.5, 0.5}));
  add_sphere(s, {-0.7, 0.7, 0}, 0.6, 32, g);
  add_box(s, {0.3, 0.1, -0.5}, {1.3, 1.1, 0.4}, g);
  add_quad(s, {-4, -1, -2}, {4, -1, -2}, {4, 3, -2}, {-4, 3, -2}, wall);
  return s;
}

TEST(Search, RefractionExitMatchesExactTracer) {
  const auto world = make_world(glass_scene(), 96);
  const CameraFrame frame = make_camera_frame(world->scene.camera);
  int entries = 0, same = 0, close = 0, near_misses = 0;
  for (int y = 0; y < 60; ++y) {
    for (int x = 0; x < 80; ++x) {
      const dvec3 d = glm::normalize(frame.direction((x + 0.5) * 4, (y + 0.5) * 4));
      Hit h;
      if (!world->tracer->intersect(frame.eye, d, &h) || world->scene.materials[h.material_id].transmit <= 0) continue;
      const Transmission tr = transmission(d, h.geometric_normal, h.shading_normal, 1.5);
      if (!tr.entering || tr.total_internal_reflection) continue;
      const SurfaceRay s{h.point, glm::normalize(tr.dir), h.geometric_normal};
      Hit out;
      ASSERT_TRUE(exact_hit(*world, s, &out));
      ASSERT_EQ(out.object_id, h.object_id);  // nothing inside the glass
      ++entries;
      const SearchResult r = refraction_exit_search(*world->ctx, s.w, s.r, h.object_id);
      if (!r.hit) {
        // Only an exit closer to W than the self offset (header, SELF-HITS) may be missed.
        EXPECT_LT(out.t, self_offset_texels(SearchOptions()) * texel_size_at(s.w - world->cube.centre, world->n))
            << miss_reason_name(r.miss);
        ++near_misses;
        continue;
      }
      EXPECT_EQ(r.object_id, h.object_id);
      same += r.triangle == out.triangle;
      close += glm::length(r.point - out.point) <= texel_size_at(out.point - world->cube.centre, world->n);
    }
  }
  std::printf("refraction exits: %d, same triangle %d, within one texel %d, missed (exit within the self offset) %d\n",
              entries, same, close, near_misses);
  ASSERT_GT(entries, 500);
  EXPECT_GE(same, 0.99 * entries);
  EXPECT_GE(close, 0.995 * entries);
}

TEST(Search, TotalInternalReflectionIsSearchedAgain) {
  // Inside the glass box a ray meets the bottom y = 0.1 at 60 degrees (critical angle 41.8):
  // total internal reflection; the mirrored ray's exit is searched again in the same object.
  const auto world = make_world(glass_scene(), 96);
  const uint32_t box = 1;
  const dvec3 w(0.8, 0.5, 0.4);  // on the box's front face (z = 0.4)
  const dvec3 d = glm::normalize(dvec3(0.05, -0.5, -0.866));
  SurfaceRay s{w, d, {0, 0, 1}};
  int tir = 0;
  for (int bounce = 0; bounce < 3; ++bounce) {
    Hit exact;
    ASSERT_TRUE(exact_hit(*world, s, &exact));
    const SearchResult r = refraction_exit_search(*world->ctx, s.w, s.r, box);
    ASSERT_TRUE(r.hit) << bounce << " " << miss_reason_name(r.miss);
    EXPECT_EQ(r.triangle, exact.triangle) << bounce;
    EXPECT_LT(glm::length(r.point - exact.point), 1e-7);
    const Transmission tr = transmission(s.r, exact.geometric_normal, exact.shading_normal, 1.5);
    if (!tr.total_internal_reflection) break;
    ++tir;
    s = {r.point, glm::normalize(tr.dir), exact.geometric_normal};
  }
  EXPECT_GE(tir, 1);
}

// Floor, an opaque slab and a glass slab floating above it, one light above.
SceneData shadow_scene() {
  SceneData s = empty_scene({0, 3, 6}, {0, 0, 0}, 50, 320, 240);
  Material floor;
  floor.color = {0.8, 0.8, 0.8};
  Material glass;
  glass.transmit = 0.8;
  glass.ior = 1.5;
  glass.color = {0.5, 0.75, 1.0};
  const uint32_t f = add_material(s, floor);
  const uint32_t g = add_material(s, glass);
  add_quad(s, {-5, 0, -5}, {-5, 0, 5}, {5, 0, 5}, {5, 0, -5}, f);
  add_box(s, {-1.5, 0.8, -0.5}, {-0.5, 1.0, 0.5}, f);
  add_box(s, {0.5, 0.8, -0.5}, {1.5, 1.0, 0.5}, g);
  s.lights.push_back({{0, 4, 0}, {1, 1, 1}, true});
  return s;
}

TEST(Search, ShadowsMatchExactVisibility) {
  const auto world = make_world(shadow_scene(), 96);
  const PointLight& light = world->scene.lights[0];
  int points = 0, agree = 0, blocked = 0, glass = 0;
  SearchKindStats stats;
  for (int iz = 0; iz < 40; ++iz) {
    for (int ix = 0; ix < 60; ++ix) {
      const dvec3 p(-3.0 + 6.0 * (ix + 0.5) / 60, 0.0, -2.0 + 4.0 * (iz + 0.5) / 40);
      // Exact visibility at p and at points moved by 3 texels (away from shadow edges).
      const double delta = 3.0 * texel_size_at(p - world->cube.centre, world->n);
      dvec3 ref(0.0);
      bool edge = false;
      for (const dvec3& q :
           {p, p + dvec3(delta, 0, 0), p - dvec3(delta, 0, 0), p + dvec3(0, 0, delta), p - dvec3(0, 0, delta)}) {
        Hit h;
        ASSERT_TRUE(world->tracer->intersect(q + dvec3(0, 1e-4, 0), {0, -1, 0}, &h));
        const dvec3 v = world->tracer->light_visibility(h, light, nullptr);
        if (q == p)
          ref = v;
        else
          edge = edge || glm::length(v - ref) > 1e-9;
      }
      if (edge) continue;
      ++points;
      const ShadowResult r = shadow_search(*world->ctx, p, light.position);
      stats.add(r);
      agree += glm::length(r.transmittance - ref) < 1e-9;
      if (ref == dvec3(0.0)) {
        ++blocked;
        EXPECT_TRUE(r.blocked) << p.x << " " << p.z;
      } else if (ref != dvec3(1.0)) {
        ++glass;
        // Glass slab: entry and exit, each kt * Od.
        const dvec3 kt_od = 0.8 * dvec3(0.5, 0.75, 1.0);
        EXPECT_LT(glm::length(r.transmittance - kt_od * kt_od), 1e-9) << p.x << " " << p.z;
        EXPECT_EQ(r.blockers, 2u);
      }
    }
  }
  std::printf("shadows: %d points off edges, agree %d, opaque %d, glass %d; texels mean %.1f\n", points, agree, blocked,
              glass, stats.mean_texels());
  EXPECT_GT(blocked, 20);
  EXPECT_GT(glass, 20);
  EXPECT_EQ(agree, points);
}

// KNOWN BLOCKER (search.hpp): along each row of floor points, every point takes the opaque
// blocker of the point before it. What the known blocker answers is blocked for the exact
// tracer too; every other answer is the walk's, bit for bit.
TEST(Search, AKnownBlockerAnswersOnlyWhereTheExactSegmentIsBlocked) {
  const auto world = make_world(shadow_scene(), 96);
  const PointLight& light = world->scene.lights[0];
  int known = 0, blocked = 0;
  for (int iz = 0; iz < 40; ++iz) {
    uint32_t previous = NO_TRIANGLE;
    for (int ix = 0; ix < 60; ++ix) {
      const dvec3 p(-3.0 + 6.0 * (ix + 0.5) / 60, 0.0, -2.0 + 4.0 * (iz + 0.5) / 40);
      const ShadowResult walked = shadow_search(*world->ctx, p, light.position);
      const ShadowResult r = shadow_search(*world->ctx, p, light.position, {}, previous);
      Hit h;
      ASSERT_TRUE(world->tracer->intersect(p + dvec3(0, 1e-4, 0), {0, -1, 0}, &h));
      const dvec3 exact = world->tracer->light_visibility(h, light, nullptr);
      blocked += exact == dvec3(0.0);
      if (r.known_blocker) {
        ++known;
        EXPECT_EQ(exact, dvec3(0.0)) << p.x << " " << p.z;
        EXPECT_EQ(r.transmittance, dvec3(0.0));
        EXPECT_TRUE(r.blocked);
        EXPECT_EQ(r.opaque_blocker, previous);
        EXPECT_EQ(r.fragments_tested, 0u);
      } else {
        EXPECT_TRUE(same_answer(r, walked)) << p.x << " " << p.z;
      }
      previous = r.opaque_blocker;
    }
  }
  std::printf("known blockers: %d of %d blocked points\n", known, blocked);
  EXPECT_GT(blocked, 100);
  EXPECT_GT(known, blocked * 3 / 4);  // all but the first point of each row's shadow
}

// A known blocker answers only an opaque crossing beyond the point's own surface, and only in
// crossing mode over all layers.
TEST(Search, AKnownBlockerIsIgnoredWhereItCannotAnswer) {
  const auto world = make_world(shadow_scene(), 96);
  const PointLight& light = world->scene.lights[0];
  const dvec3 under_opaque(-1.0, 0.0, 0.0), under_glass(1.0, 0.0, 0.0);
  const ShadowResult opaque = shadow_search(*world->ctx, under_opaque, light.position);
  ASSERT_TRUE(opaque.blocked);
  ASSERT_NE(opaque.opaque_blocker, NO_TRIANGLE);
  EXPECT_TRUE(shadow_search(*world->ctx, under_opaque, light.position, {}, opaque.opaque_blocker).known_blocker);
  // Off, in thesis mode, over the nearest layer only, or the map alone: the walk, as without it.
  SearchOptions off, thesis, nearest, map_only;
  off.known_blockers = false;
  thesis.mode = SearchMode::thesis;
  nearest.layers = SearchLayers::nearest;
  map_only.side_structure = false;
  for (const SearchOptions& o : {off, thesis, nearest, map_only}) {
    const ShadowResult r = shadow_search(*world->ctx, under_opaque, light.position, o, opaque.opaque_blocker);
    EXPECT_FALSE(r.known_blocker);
    EXPECT_TRUE(same_answer(r, shadow_search(*world->ctx, under_opaque, light.position, o)));
  }
  // Glass is no known blocker, whichever of its triangles: the walk counts its two crossings.
  const ShadowResult glass = shadow_search(*world->ctx, under_glass, light.position);
  ASSERT_EQ(glass.blockers, 2u);
  ASSERT_EQ(glass.opaque_blocker, NO_TRIANGLE);
  const TriangleSoup& soup = *world->scene.triangles;
  for (uint32_t t = 0; t < soup.triangle_count(); ++t) {
    if (world->scene.materials[soup.material_id[t]].transmit <= 0.0) continue;
    EXPECT_TRUE(same_answer(shadow_search(*world->ctx, under_glass, light.position, {}, t), glass)) << t;
  }
  // The floor under a lit point: its own surface, never crossed.
  const dvec3 lit(-2.5, 0.0, 1.5);
  const ShadowResult open = shadow_search(*world->ctx, lit, light.position);
  ASSERT_FALSE(open.blocked);
  for (uint32_t floor : {0u, 1u}) {
    EXPECT_TRUE(same_answer(shadow_search(*world->ctx, lit, light.position, {}, floor), open)) << floor;
  }
}

TEST(Search, OwnSurfaceNeverShadowsGrazingLight) {
  // Lights just above the floor's plane, seen from floor points away from the slabs: the
  // floor is P's own surface (its plane contains P) and must not block.
  const auto world = make_world(shadow_scene(), 96);
  for (const double elevation : {1e-2, 1e-4, 1e-7, 1e-12}) {
    for (int k = 0; k < 20; ++k) {
      const dvec3 p(2.0 + 0.1 * k, 0.0, 1.5 + 0.05 * k);
      for (const dvec3& far : {dvec3(20.0, 0, 3.0), dvec3(-3.0, 0, 20.0), dvec3(2.0, 0, -1.0)}) {
        const dvec3 light = p + far + dvec3(0, glm::length(far) * elevation, 0);
        const ShadowResult r = shadow_search(*world->ctx, p, light);
        EXPECT_EQ(r.blockers, 0u) << elevation << " " << k;
        EXPECT_EQ(r.transmittance, dvec3(1.0));
      }
    }
  }
}

// A room around the camera at the origin, with a mirror, boxes, and a quad in the plane
// y = 0 that contains the centre (zero area in the map).
SceneData room_scene() {
  SceneData s = empty_scene({0, 0, 0}, {0, 0, -1}, 60, 64, 64);
  const uint32_t m = add_mirror(s);
  const uint32_t a = add_material(s, emissive({1, 0.5, 0}));
  const uint32_t b = add_material(s, emissive({0, 0.5, 1}));
  add_box(s, {-1.5, -1.5, -4.0}, {1.5, -1.0, -3.0}, a);                    // 0: behind the mirror
  add_quad(s, {-1, -0.5, -2}, {1, -0.5, -2}, {1, 1, -2}, {-1, 1, -2}, m);  // 1: mirror facing +z
  add_box(s, {-1.0, -1.0, 3.0}, {1.0, 1.0, 4.0}, b);                       // 2: behind the camera
  add_quad(s, {1.5, 0, -1}, {1.5, 0, 1}, {2.5, 0, 1}, {2.5, 0, -1}, a);    // 3: plane y = 0 through C
  // 4..9: the room's walls, inward facing.
  const double r = 6;
  add_quad(s, {-r, -r, -r}, {r, -r, -r}, {r, -r, r}, {-r, -r, r}, b);
  add_quad(s, {-r, r, -r}, {-r, r, r}, {r, r, r}, {r, r, -r}, b);
  add_quad(s, {-r, -r, -r}, {-r, r, -r}, {r, r, -r}, {r, -r, -r}, a);
  add_quad(s, {-r, -r, r}, {r, -r, r}, {r, r, r}, {-r, r, r}, a);
  add_quad(s, {-r, -r, -r}, {-r, -r, r}, {-r, r, r}, {-r, r, -r}, b);
  add_quad(s, {r, -r, -r}, {r, r, -r}, {r, r, r}, {r, -r, r}, b);
  return s;
}

// The search agrees with the exact tracer: same triangle (or the same point of the same
// object: a ray through the edge two triangles share), or both find nothing.
::testing::AssertionResult matches_tracer(const World& world, const SurfaceRay& s, const SearchOptions& o = {}) {
  Hit h;
  const bool exact = exact_hit(world, s, &h);
  const SearchResult r = reflection_search(*world.ctx, s.w, s.r, o);
  const bool same = exact && r.hit &&
                    (h.triangle == r.triangle || (h.object_id == r.object_id &&
                                                  glm::length(h.point - r.point) < 1e-7 * world.tracer->scene_scale()));
  if (exact != r.hit || (exact && !same)) {
    return ::testing::AssertionFailure() << "exact " << (exact ? static_cast<int>(h.triangle) : -1) << " search "
                                         << (r.hit ? static_cast<int>(r.triangle) : -1) << " ("
                                         << miss_reason_name(r.miss) << ")";
  }
  return ::testing::AssertionSuccess();
}

TEST(Search, TessellatedMirrorSphereDoesNotFindItself) {
  // A coarse mirror sphere: near W the extended planes of its neighbouring triangles pass
  // within the tolerance of every reflected ray; only an exact crossing may be found there.
  SceneData s = room_scene();
  add_sphere(s, {0.2, -0.3, -2.6}, 0.5, 16, add_mirror(s));
  const auto world = make_world(std::move(s), 64);
  const uint32_t sphere = static_cast<uint32_t>(world->scene.objects.size() - 1);
  int interior = 0, agree = 0, self = 0;
  for (const SurfaceRay& r : mirror_rays(*world, 160, 160)) {
    Hit at;
    if (!world->tracer->intersect(world->cube.centre, r.w - world->cube.centre, &at) || at.object_id != sphere)
      continue;
    if (!away_from_silhouettes(*world, r)) continue;
    ++interior;
    agree += static_cast<bool>(matches_tracer(*world, r));
    Hit h;
    const bool exact = exact_hit(*world, r, &h);
    const SearchResult res = reflection_search(*world->ctx, r.w, r.r);
    self += res.hit && res.object_id == sphere && !(exact && h.object_id == sphere);
  }
  std::printf("mirror sphere: %d interior rays, agree %d, found itself wrongly %d\n", interior, agree, self);
  ASSERT_GT(interior, 100);
  EXPECT_EQ(self, 0);
  EXPECT_GE(agree, 0.99 * interior);
}

TEST(SearchDegenerate, DirectionAlongW) {
  // R . [[W]] = +1: the walk is one texel; the mirror's plane is W's own and is skipped, the
  // box behind the mirror is found through it.
  const auto world = make_world(room_scene(), 64);
  for (const dvec3 w : {dvec3(0.3, 0.2, -2), dvec3(-0.7, -0.3, -2), dvec3(0.9, 0.9, -2)}) {
    const SurfaceRay s{w, glm::normalize(w), {0, 0, 1}};
    EXPECT_TRUE(matches_tracer(*world, s));
    const SearchResult r = reflection_search(*world->ctx, s.w, s.r);
    EXPECT_EQ(r.texels_visited, 1u);
  }
}

TEST(SearchDegenerate, RayThroughAndNearTheCentre) {
  // R . [[W]] = -1: the ray passes through C and its direction jumps to the antipode; then
  // rays passing at 1e-2 .. 1e-12 from C (inside and outside the near ball).
  const auto world = make_world(room_scene(), 64);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-0.9, 0.9);
  for (int k = 0; k < 20; ++k) {
    const dvec3 w(u(rng), 0.5 * u(rng) + 0.2, -2);
    EXPECT_TRUE(matches_tracer(*world, {w, -glm::normalize(w), {0, 0, 1}})) << k;
    for (const double miss_by : {1e-2, 1e-4, 1e-7, 1e-12}) {
      const dvec3 side = glm::normalize(glm::cross(w, dvec3(u(rng), u(rng), 1)));
      const SurfaceRay s{w, glm::normalize(miss_by * side - w), {0, 0, 1}};
      EXPECT_TRUE(matches_tracer(*world, s)) << k << " " << miss_by;
    }
  }
}

TEST(SearchDegenerate, ArcsAlongSeamsEdgesAndCorners) {
  const auto world = make_world(room_scene(), 32);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  int checked = 0, failed = 0;
  const auto check = [&](const SurfaceRay& s) {
    if (!away_from_silhouettes(*world, s)) return;
    ++checked;
    if (!matches_tracer(*world, s) && ++failed <= 5) {
      const SearchResult r = reflection_search(*world->ctx, s.w, s.r);
      ADD_FAILURE() << matches_tracer(*world, s).message() << " W " << s.w.x << " " << s.w.y << " " << s.w.z << " R "
                    << s.r.x << " " << s.r.y << " " << s.r.z << " X' " << r.point.x << " " << r.point.y << " "
                    << r.point.z << " outside " << r.outside_texels;
    }
  };
  for (int k = 0; k < 200; ++k) {
    // From points of the mirror: in the seam planes x = +-y of the cube (a cube edge's plane
    // through C), and towards the corner directions (+-1, +-1, +-1) at several distances.
    const dvec3 w(u(rng), 0.25 + 0.7 * u(rng), -2);
    const dvec3 in_plane = glm::normalize(dvec3(w.x, w.x, 0) * u(rng) + dvec3(0, 0, 1) * (0.5 + u(rng)));
    const dvec3 w_seam(w.x, w.x, -2);
    if (in_plane.z > 0) check({w_seam, in_plane, {0, 0, 1}});
    const dvec3 corner((k & 1) ? 1 : -1, (k & 2) ? 1 : -1, 1);
    check({w, glm::normalize(corner * (1.0 + 4.0 * std::fabs(u(rng))) - w), {0, 0, 1}});
  }
  std::printf("seams and corners: %d rays checked, %d failed\n", checked, failed);
  EXPECT_GT(checked, 100);
  EXPECT_EQ(failed, 0);
}

TEST(SearchDegenerate, GrazingReflectionDoesNotFindItsOwnSurface) {
  // Rays leaving the mirror at 1e-2 .. 1e-9 radians: in thesis mode the mirror's own points
  // would be under theta_max (2 degrees) without the own-surface rule.
  const auto world = make_world(room_scene(), 64);
  SearchOptions thesis;
  thesis.mode = SearchMode::thesis;
  for (const double angle : {1e-2, 1e-5, 1e-9}) {
    for (int k = 0; k < 10; ++k) {
      const dvec3 w(-0.8 + 0.15 * k, 0.1, -2);
      const dvec3 r = glm::normalize(dvec3(std::cos(0.3 * k), std::sin(0.3 * k), angle));
      for (const SearchOptions& o : {SearchOptions(), thesis}) {
        const SearchResult res = reflection_search(*world->ctx, w, r, o);
        EXPECT_TRUE(res.hit);
        EXPECT_NE(world->scene.triangles->object_id[res.triangle], 1u) << angle << " " << k;
      }
      EXPECT_TRUE(matches_tracer(*world, {w, r, {0, 0, 1}})) << angle << " " << k;
    }
  }
}

// THE SIDE STRUCTURE (search.hpp): the quad in y = 0 holds no fragment; the searches find
// it exactly there, and only say "zero_area_surface" when it is off (--map-only).
TEST(SearchDegenerate, SurfaceThroughTheCentreIsAnsweredByTheSideStructure) {
  const auto world = make_world(room_scene(), 64);
  ASSERT_EQ(world->ctx->zero_area_triangles().size(), 2u);  // the quad in y = 0
  ASSERT_TRUE(world->ctx->has_side_triangles());
  SearchOptions map_only;
  map_only.side_structure = false;
  SearchKindStats stats, stats_map_only;
  int checked = 0;
  for (int k = 0; k < 20; ++k) {
    // From the floor wall up through the quad (x in [1.5, 2.5], z in [-1, 1]).
    const dvec3 w(1.6 + 0.04 * k, -6, -0.8 + 0.08 * k);
    const dvec3 target(2.0 + 0.02 * k, 0.0, 0.5 - 0.05 * k);
    const SurfaceRay s{w, glm::normalize(target - w), {0, 1, 0}};
    Hit h;
    ASSERT_TRUE(exact_hit(*world, s, &h));
    ASSERT_EQ(h.object_id, 3u);
    const SearchResult r = reflection_search(*world->ctx, s.w, s.r);
    stats.add(r);
    ASSERT_TRUE(r.hit) << k;
    EXPECT_TRUE(r.side);
    EXPECT_EQ(r.object_id, 3u);
    EXPECT_LT(glm::length(r.point - h.point), 1e-7 * world->tracer->scene_scale());  // the tracer starts offset
    EXPECT_TRUE(r.back_face);  // the ray goes up, along the quad's geometric normal +y: its back
    const SearchResult m = reflection_search(*world->ctx, s.w, s.r, map_only);
    stats_map_only.add(m);
    EXPECT_FALSE(m.hit);
    EXPECT_EQ(m.miss, MissReason::zero_area_surface);
    ++checked;
  }
  EXPECT_EQ(stats.side_hits, static_cast<uint64_t>(checked));
  EXPECT_EQ(stats.hits, static_cast<uint64_t>(checked));
  EXPECT_EQ(stats.zero_area, 0u);
  EXPECT_EQ(stats_map_only.zero_area, static_cast<uint64_t>(checked));
  EXPECT_EQ(stats_map_only.misses, static_cast<uint64_t>(checked));
  EXPECT_EQ(stats_map_only.side_hits, 0u);
}

TEST(Search, StatsCountEveryRay) {
  const auto world = make_world(room_scene(), 32);
  SearchStats stats;
  SearchOptions tight;
  tight.mode = SearchMode::thesis;
  tight.theta_max = 1e-9;  // nothing passes: threshold rejections
  for (int k = 0; k < 10; ++k) {
    const dvec3 w(-0.8 + 0.15 * k, 0.1, -2);
    const dvec3 r = glm::normalize(dvec3(0.1 * k - 0.5, 0.2, 1));
    stats.reflection.add(reflection_search(*world->ctx, w, r));
    stats.refraction_exit.add(reflection_search(*world->ctx, w, r, tight));
    stats.shadow.add(shadow_search(*world->ctx, w, w + dvec3(0, 0, 3)));
  }
  SearchStats twice = stats;
  twice.merge(stats);
  EXPECT_EQ(stats.reflection.rays, 10u);
  EXPECT_EQ(stats.reflection.hits, 10u);  // the room is closed
  EXPECT_EQ(stats.refraction_exit.threshold_rejections, 10u);
  EXPECT_EQ(stats.refraction_exit.misses, 10u);
  EXPECT_EQ(twice.shadow.rays, 20u);
  EXPECT_EQ(twice.reflection.max_texels, stats.reflection.max_texels);
  EXPECT_GT(stats.reflection.mean_texels(), 1.0);
  EXPECT_GE(stats.reflection.fragments, stats.reflection.candidates);
  SearchMode mode;
  EXPECT_TRUE(parse_search_mode("thesis", &mode));
  EXPECT_EQ(mode, SearchMode::thesis);
  EXPECT_FALSE(parse_search_mode("march", &mode));
}

// scan_candidates: the fragments a search tests, in the walk's order. Where none is accepted
// (the thesis mode with a zero angle walks to the end), the search counts exactly those,
// whatever its skips over empty texels stepped past.
TEST(Search, ScanCandidatesAreTheFragmentsASearchTests) {
  const auto world = make_world(room_scene(), 32);
  const SearchContext& ctx = *world->ctx;
  SearchOptions none;
  none.mode = SearchMode::thesis;
  none.theta_max = 1e-9;
  size_t total = 0;
  for (int k = 0; k < 10; ++k) {
    const dvec3 w(-0.8 + 0.15 * k, 0.1, -2);
    const dvec3 r = glm::normalize(dvec3(0.1 * k - 0.5, 0.2, 1));
    const SearchResult res = reflection_search(ctx, w, r, none);
    const SearchRay q = reflection_ray(ctx, w, r, none);
    const CandidateScan scan = scan_candidates(ctx, q, none);
    EXPECT_EQ(res.candidates, scan.candidates.size()) << k;
    EXPECT_FALSE(scan.aborted);
    // Each candidate is a fragment of the list of the texel the walk visits at its place.
    const CubeABuffer& cube = ctx.cube();
    CubeWalk walk(q.w, q.d, cube.n, q.l_max, cube.near_distance);
    std::vector<WalkTexel> texels;
    WalkTexel t;
    while (walk.next(&t)) texels.push_back(t);
    ASSERT_EQ(texels.size(), scan.texels);
    for (size_t c = 0; c < scan.candidates.size(); ++c) {
      const ScanCandidate& x = scan.candidates[c];
      ASSERT_LT(x.texel, scan.texels);
      const WalkTexel& at = texels[x.texel];
      EXPECT_EQ(x.face, static_cast<uint32_t>(at.face));
      const ABuffer& face = cube.faces[x.face];
      const size_t list = static_cast<size_t>(at.j) * static_cast<size_t>(cube.n) + static_cast<size_t>(at.i);
      EXPECT_GE(x.fragment, face.offsets[list]);
      EXPECT_LT(x.fragment, face.offsets[list + 1]);
      if (c > 0) EXPECT_GE(x.texel, scan.candidates[c - 1].texel);
    }
    total += scan.candidates.size();
  }
  EXPECT_GT(total, 10u);
}

// search_from_candidates and shadow_from_candidates: the searches' choices fed a ray's
// candidates give the walked searches' answers, for reflections and refraction exits, hits
// and misses, and shadow segments, blocked and lit, with the side structure and under a cap
// that stops walks.
TEST(Search, AnswerFromCandidatesIsTheWalkedSearchs) {
  const auto world = make_world(room_scene(), 32);
  const SearchContext& ctx = *world->ctx;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  size_t hits = 0, misses = 0, blocked = 0, lit = 0;
  for (const uint32_t cap : {0u, 9u}) {
    SearchOptions o;
    o.max_texels = cap;
    for (int k = 0; k < 400; ++k) {
      const dvec3 w(0.9 * u(rng), 0.9 * u(rng), -2 + 0.5 * u(rng));
      const dvec3 d = glm::normalize(dvec3(u(rng), u(rng), u(rng)) + dvec3(0, 0, 1e-3));
      const SearchRay q = k % 3 == 0 ? refraction_exit_ray(ctx, w, d, 0, o) : reflection_ray(ctx, w, d, o);
      const SearchResult walked = search_along(ctx, q, o);
      const SearchResult found = search_from_candidates(ctx, q, o, scan_candidates(ctx, q, o));
      EXPECT_TRUE(same_found(walked, found))
          << "ray " << k << " cap " << cap << ": hit " << walked.hit << " / " << found.hit << ", triangle "
          << walked.triangle << " / " << found.triangle;
      (walked.hit ? hits : misses) += 1;
      const dvec3 light(3 * u(rng), 3 * u(rng), 3 * u(rng));
      SearchRay segment;
      if (!shadow_ray(ctx, w, light, o, &segment)) continue;
      const ShadowResult shade = shadow_along(ctx, segment, light, o);
      EXPECT_TRUE(same_found(shade, shadow_from_candidates(ctx, segment, light, o, scan_candidates(ctx, segment, o))))
          << "segment " << k << " cap " << cap;
      (shade.blocked ? blocked : lit) += 1;
    }
  }
  EXPECT_GT(hits, 300u);
  EXPECT_GT(misses, 50u);
  EXPECT_GT(blocked, 100u);
  EXPECT_GT(lit, 100u);
  SearchOptions thesis;
  thesis.mode = SearchMode::thesis;
  EXPECT_THROW(search_from_candidates(ctx, reflection_ray(ctx, dvec3(0, 0, -2), dvec3(0, 0, 1)), thesis, {}),
               InputError);
}

// MESH REFINEMENT (search.hpp): the crossing search checks a candidate against the mesh
// around its fragment's triangle, so a ray passing within a texel of a silhouette or of a
// crease is no longer taken for a crossing. Each test runs the same rays with
// SearchRefine::plane too: the scenario must show the error the refinement removes, or
// the test would prove nothing. Merged maps, as the renderer builds them.
SearchOptions with_refine(SearchRefine r, bool side_structure = true) {
  SearchOptions o;
  o.refine = r;
  o.side_structure = side_structure;
  return o;
}

TEST(MeshRefine, ClosedMeshesAreLinkedAcrossEveryEdgeAndObjectsAreNot) {
  SceneData s = empty_scene({0, 0, 5}, {0, 0, 0}, 50, 32, 32);
  const uint32_t m = add_material(s, Material{});
  add_sphere(s, {0, 0, 0}, 1.0, 24, m);
  add_box(s, {1.0, -0.5, -0.5}, {2.0, 0.5, 0.5}, m);  // touches the sphere at (1, 0, 0)
  const uint32_t quad = begin_object(s, "quad", m, false);
  add_flat_triangle(s, {-3, -2, 0}, {-2, -2, 0}, {-2, -1, 0});
  add_flat_triangle(s, {-3, -2, 0}, {-2, -1, 0}, {-3, -1, 0});
  const auto w = make_world(s, 8, true);
  const TriangleSoup& t = *w->scene.triangles;
  size_t border = 0;
  for (uint32_t k = 0; k < t.triangle_count(); ++k) {
    for (int e = 0; e < 3; ++e) {
      const uint32_t nb = w->ctx->neighbour(k, e);
      if (nb == SearchContext::NO_NEIGHBOUR) {
        ++border;
        EXPECT_EQ(t.object_id[k], quad) << "triangle " << k << " edge " << e;  // only the open quad has borders
        continue;
      }
      EXPECT_EQ(t.object_id[nb], t.object_id[k]);  // never across objects, even where they touch
      int back = 0;
      for (int f = 0; f < 3; ++f) back += w->ctx->neighbour(nb, f) == k;
      EXPECT_EQ(back, 1) << "triangle " << k << " edge " << e;
    }
  }
  EXPECT_EQ(border, 4u);  // the quad's outline; its diagonal links its two triangles
}

// Rays from a mirror floor aimed at points within half a texel of a sphere's silhouette,
// inside and outside it: what they meet first, against the exact tracer. The plane-only
// refinement is measured on the map alone: the side structure answers some of the rays it
// gets wrong (the sphere's slivers that cover no sample), which would hide its error.
TEST(MeshRefine, RaysGrazingASilhouetteMeetWhatTheExactRayMeets) {
  SceneData s = empty_scene({0, 1.2, 4}, {0, 0.5, 0}, 50, 64, 48);
  const uint32_t mm = add_mirror(s);
  const uint32_t red = add_material(s, emissive({1, 0, 0}));
  const uint32_t blue = add_material(s, emissive({0, 0, 1}));
  add_quad(s, {-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, mm);
  add_sphere(s, {0.2, 0.9, -0.8}, 0.6, 32, red);
  add_quad(s, {-4, 0, -3}, {4, 0, -3}, {4, 4, -3}, {-4, 4, -3}, blue);
  const int n = 128;
  const auto w = make_world(s, n, true);
  const dvec3 centre(0.2, 0.9, -0.8);
  int rays = 0, mesh_right = 0, mesh_map_right = 0, plane_right = 0;
  for (int k = 0; k < 400; ++k) {
    const dvec3 origin(-1.5 + 3.0 * ((k * 37) % 400) / 400.0, 0.0, 0.5 + 1.5 * ((k * 91) % 400) / 400.0);
    // The silhouette seen from the origin: unit directions u (to the centre) and e (across).
    const dvec3 to_c = centre - origin;
    const double dist = glm::length(to_c);
    const dvec3 u = to_c / dist;
    const double angle = 2.0 * 3.14159265358979 * ((k * 13) % 400) / 400.0;
    const dvec3 a = glm::normalize(glm::cross(u, dvec3(0, 1, 0)));
    const dvec3 b = glm::cross(a, u);
    const dvec3 e = std::cos(angle) * a + std::sin(angle) * b;
    const double r = 0.6 * std::sqrt(1.0 - 0.36 / (dist * dist));  // silhouette circle radius
    const dvec3 rim = origin + u * (dist - 0.36 / dist) + r * e;
    const double texel = texel_size_at(rim - w->cube.centre, n);
    for (const double off : {-0.45, -0.25, 0.25, 0.45}) {
      const dvec3 dir = glm::normalize(rim + off * texel * e - origin);
      if (dir.y <= 0.0) continue;
      ++rays;
      Hit h;
      const bool exact = w->tracer->intersect(origin + 1e-9 * dir, dir, &h);
      const auto right = [&](const SearchResult& res) {
        return res.hit == exact && (!exact || res.object_id == h.object_id);
      };
      mesh_right += right(reflection_search(*w->ctx, origin, dir, with_refine(SearchRefine::mesh)));
      mesh_map_right += right(reflection_search(*w->ctx, origin, dir, with_refine(SearchRefine::mesh, false)));
      plane_right += right(reflection_search(*w->ctx, origin, dir, with_refine(SearchRefine::plane, false)));
    }
  }
  std::printf("silhouette rays %d: right with mesh refinement %d (map only %d), with plane only (map only) %d\n", rays,
              mesh_right, mesh_map_right, plane_right);
  ASSERT_GT(rays, 1000);
  EXPECT_GE(mesh_right, 0.998 * rays);
  EXPECT_GE(mesh_map_right, 0.998 * rays);
  EXPECT_GT(rays - plane_right, 10);  // the scenario shows the plane tolerance's error
}

// Points on a box's front face 2.75 to 8 texels under its top edge, a light nearly above
// them (slightly in front): each shadow ray crosses the top face's plane 0.07 to 0.2
// texel outside the top face, but never the face itself (the box is convex), and further
// from the point than the 2 texels within which tolerance candidates are ignored. No
// false shadow.
TEST(MeshRefine, ACreaseDoesNotShadowItsOwnFace) {
  SceneData s = empty_scene({0.3, 1.1, 3}, {0, 0.5, 0}, 50, 64, 48);
  const uint32_t white = add_material(s, Material{});
  add_box(s, {-0.5, 0, -0.5}, {0.5, 1.0, 0.5}, white);
  const int n = 128;
  const auto w = make_world(s, n, true);
  const dvec3 light(0.1, 5.0, 0.6);
  int points = 0, mesh_false = 0, plane_false = 0;
  for (int i = 0; i < 50; ++i) {
    for (int j = 1; j <= 8; ++j) {
      const dvec3 probe(-0.45 + 0.9 * i / 49.0, 1.0, 0.5);
      const double texel = texel_size_at(probe - w->cube.centre, n);
      const dvec3 p = probe - dvec3(0, (2.0 + 0.75 * j) * texel, 0);
      Hit h;
      ASSERT_TRUE(w->tracer->intersect(p + dvec3(0, 0, 1e-3), {0, 0, -1}, &h));
      if (w->tracer->light_visibility(h, PointLight{light, dvec3(1.0), true}, nullptr) != dvec3(1.0)) continue;
      ++points;
      mesh_false += shadow_search(*w->ctx, p, light, with_refine(SearchRefine::mesh)).blockers > 0;
      plane_false += shadow_search(*w->ctx, p, light, with_refine(SearchRefine::plane)).blockers > 0;
    }
  }
  std::printf("crease: %d lit points, false shadows with mesh refinement %d, with plane only %d\n", points, mesh_false,
              plane_false);
  ASSERT_GT(points, 300);
  EXPECT_EQ(mesh_false, 0);
  EXPECT_GT(plane_false, points / 10);  // the scenario shows the plane tolerance's error
}

// A point light lying on a floor (flat, then tilted with coordinates float cannot hold), a
// wall facing it: the segment from the wall to the light meets the floor's plane only at
// the light. Neither the tracer nor the shadow search may call it a blocker (rule "lights
// on surfaces", shading.hpp); without the rule both decide by rounding, and differently.
TEST(ShadowRules, ALightLyingOnASurfaceIsNotShadowedByIt) {
  for (const dvec3 slope : {dvec3(0.0, 0.0, 0.0), dvec3(0.3137, 0.0, 0.1171)}) {
    const auto height = [&](double x, double z) { return slope.x * x + slope.z * z + (slope.x > 0 ? 0.0731 : 0.0); };
    SceneData s = empty_scene({0.3, 1.1, 3}, {0, 0.5, 0}, 50, 64, 48);
    const uint32_t white = add_material(s, Material{});
    add_quad(s, {-4, height(-4, -4), -4}, {-4, height(-4, 4), 4}, {4, height(4, 4), 4}, {4, height(4, -4), -4}, white);
    add_quad(s, {-2, 1.5, -1}, {2, 1.5, -1}, {2, 3.5, -1}, {-2, 3.5, -1}, white);
    const auto w = make_world(s, 128, true);
    int points = 0, tracer_shadowed = 0, search_shadowed = 0;
    for (int k = 0; k < 40; ++k) {
      const double lx = -1.5 + 3.0 * ((k * 7) % 40) / 40.0, lz = 0.3 + 1.2 * ((k * 13) % 40) / 40.0;
      const PointLight light{dvec3(lx, height(lx, lz), lz), dvec3(1.0), true};
      for (int j = 0; j < 10; ++j) {
        const dvec3 probe(-1.8 + 0.4 * j, 1.6 + std::fmod(0.17 * k, 1.8), 0.0);
        Hit h;
        ASSERT_TRUE(w->tracer->intersect(probe, {0, 0, -1}, &h));
        ++points;
        tracer_shadowed += w->tracer->light_visibility(h, light, nullptr) != dvec3(1.0);
        search_shadowed += shadow_search(*w->ctx, h.point, light.position).blockers > 0;
      }
    }
    std::printf("light on a floor (slope %g): %d points, shadowed by the tracer %d, by the search %d\n", slope.x,
                points, tracer_shadowed, search_shadowed);
    EXPECT_EQ(tracer_shadowed, 0);
    EXPECT_EQ(search_shadowed, 0);
  }
}

}  // namespace
}  // namespace abcube
