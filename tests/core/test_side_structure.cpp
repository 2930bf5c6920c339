// THE SIDE STRUCTURE of the searches (search.hpp): a sliver triangle thinner than a texel,
// which covers no sample of the cube map, is found by reflection and shadow searches
// through it, counted in side_hits; with side_structure off the searches do not see it.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "abuffer_testkit.hpp"
#include "raster/abuffer.hpp"
#include "search/search.hpp"
#include "material/shading.hpp"

namespace abcube {
namespace {

using glm::dvec3;
using namespace testkit;

// The sliver's corners: 0.3 long, 4e-4 wide (a texel at its distance, N = 64, is ~0.1).
const dvec3 SLIVER_A(0.1, 0.2, 3.0), SLIVER_B(0.4, 0.25, 3.01), SLIVER_C(0.1, 0.2004, 3.0);

// Camera at the origin, a mirror at z = -2 facing it, an opaque sliver behind the camera,
// an emissive room. Returns the sliver's triangle index in *sliver.
SceneData sliver_scene(uint32_t* sliver) {
  SceneData s = empty_scene({0, 0, 0}, {0, 0, -1}, 60, 64, 64);
  Material mirror;
  mirror.reflect = 1.0;
  const uint32_t m = add_material(s, mirror);
  const uint32_t wall = add_material(s, emissive({0, 0.5, 1}));
  Material opaque;
  opaque.color = {1, 0, 0};
  const uint32_t red = add_material(s, opaque);
  add_quad(s, {-1, -1, -2}, {1, -1, -2}, {1, 1, -2}, {-1, 1, -2}, m);  // facing +z
  begin_object(s, "triangle", red, false);
  *sliver = static_cast<uint32_t>(s.triangles->triangle_count());
  add_flat_triangle(s, SLIVER_A, SLIVER_B, SLIVER_C);
  const double r = 6;
  add_quad(s, {-r, -r, -r}, {r, -r, -r}, {r, -r, r}, {-r, -r, r}, wall);
  add_quad(s, {-r, r, -r}, {-r, r, r}, {r, r, r}, {r, r, -r}, wall);
  add_quad(s, {-r, -r, -r}, {-r, r, -r}, {r, r, -r}, {r, -r, -r}, wall);
  add_quad(s, {-r, -r, r}, {r, -r, r}, {r, r, r}, {-r, r, r}, wall);
  add_quad(s, {-r, -r, -r}, {-r, -r, r}, {-r, r, r}, {-r, r, -r}, wall);
  add_quad(s, {r, -r, -r}, {r, r, -r}, {r, r, r}, {r, -r, r}, wall);
  return s;
}

// Points inside the sliver, spread along it.
std::vector<dvec3> sliver_points() {
  std::vector<dvec3> out;
  for (int k = 0; k < 10; ++k) {
    const double u = 0.05 + 0.08 * k, v = 0.3 * (1.0 - u);  // barycentric weights of B and C
    out.push_back(SLIVER_A + u * (SLIVER_B - SLIVER_A) + v * (SLIVER_C - SLIVER_A));
  }
  return out;
}

struct SliverWorld {
  uint32_t sliver = 0;  // before scene: set by its initialiser
  SceneData scene;
  CubeABuffer cube;
  std::unique_ptr<SearchContext> ctx;
  SliverWorld() : scene(sliver_scene(&sliver)) {
    cube = build_cube_abuffer(scene, scene.camera.position, 64, abtest::test_options());
    ctx = std::make_unique<SearchContext>(scene, cube);
  }
};

TEST(SideStructure, SliverWithoutFragmentsIsListed) {
  const SliverWorld world;
  const std::vector<uint32_t>& side = world.ctx->side_triangles();
  EXPECT_TRUE(std::find(side.begin(), side.end(), world.sliver) != side.end());
  EXPECT_TRUE(world.ctx->zero_area_triangles().empty());
  EXPECT_EQ(side.size(), 1u);  // only the sliver: every other triangle has fragments
}

TEST(SideStructure, SliverSeenInAMirrorIsFound) {
  const SliverWorld world;
  SearchOptions map_only;
  map_only.side_structure = false;
  SearchKindStats stats, stats_map_only;
  int k = 0;
  for (const dvec3& target : sliver_points()) {
    const dvec3 w(-0.5 + 0.1 * k, -0.4 + 0.08 * k, -2.0);  // on the mirror
    const dvec3 r = glm::normalize(target - w);
    const SearchResult found = reflection_search(*world.ctx, w, r);
    stats.add(found);
    ASSERT_TRUE(found.hit) << k;
    EXPECT_TRUE(found.side) << k;
    EXPECT_EQ(found.triangle, world.sliver) << k;
    EXPECT_LT(glm::length(found.point - target), 1e-6) << k;  // the float triangle, not the double corners
    EXPECT_NEAR(found.distance, glm::length(target - w), 1e-6) << k;
    EXPECT_TRUE(found.back_face);  // its normal (+z) points away from the centre: the map's facing
    const SearchResult seen = reflection_search(*world.ctx, w, r, map_only);
    stats_map_only.add(seen);
    EXPECT_TRUE(!seen.hit || seen.triangle != world.sliver) << k;
    ++k;
  }
  EXPECT_EQ(stats.side_hits, static_cast<uint64_t>(k));
  EXPECT_EQ(stats_map_only.side_hits, 0u);
}

TEST(SideStructure, SliverCastsAShadow) {
  const SliverWorld world;
  SearchOptions map_only;
  map_only.side_structure = false;
  SearchKindStats stats, stats_map_only;
  const dvec3 light(0.2, 0.25, 5.5);
  int k = 0;
  for (const dvec3& target : sliver_points()) {
    const dvec3 q = target + (target - light) * 0.5;  // a point past the sliver, seen from the light
    const ShadowResult s = shadow_search(*world.ctx, q, light);
    stats.add(s);
    EXPECT_TRUE(s.blocked) << k;
    EXPECT_EQ(s.side_blockers, 1u) << k;
    EXPECT_EQ(s.first_blocker, world.sliver) << k;
    const ShadowResult m = shadow_search(*world.ctx, q, light, map_only);
    stats_map_only.add(m);
    EXPECT_FALSE(m.blocked) << k;
    ++k;
  }
  EXPECT_EQ(stats.side_hits, static_cast<uint64_t>(k));
  EXPECT_EQ(stats.hits, static_cast<uint64_t>(k));
  EXPECT_EQ(stats_map_only.side_hits, 0u);
}

}  // namespace
}  // namespace abcube
