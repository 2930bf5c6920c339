// NESTED DIELECTRICS (cpu_core/material/media.hpp) with known answers: the direction of the
// transmitted ray after each interface, from Snell's law for the chain of media, as the
// exact tracer follows it (RayTracer::transmitted_path) and as the map searches follow it
// (MapShader::transmitted_path). Parallel faces: sin(theta_k) = sin(theta_0) / n_k in a
// medium of index n_k, whatever lies between.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "abuffer_testkit.hpp"
#include "raster/abuffer.hpp"
#include "reference/raytrace.hpp"
#include "shading/map_shading.hpp"
#include "material/media.hpp"

namespace abcube {
namespace {

using glm::dvec3;
using namespace testkit;

// A pure transmitter: nothing but kt = 1 (no Phong, no mirror term).
Material clear(double ior) {
  Material m;
  m.ambient = 0;
  m.diffuse = 0;
  m.specular = 0;
  m.transmit = 1.0;
  m.ior = ior;
  return m;
}

// One expected leg of the path: the index of the medium the ray runs in and the plane
// z = z_start it starts on.
struct Leg {
  double n, z_start;
};

// The ray from (0, 0, 3) at theta0 from -z in the x-z plane.
constexpr double THETA0 = 25.0 * M_PI / 180.0;
const dvec3 EYE(0, 0, 3);
dvec3 incoming() { return {std::sin(THETA0), 0, -std::cos(THETA0)}; }

// Checks each ray of `path` against Snell's chain through faces z = legs[k].z_start.
void expect_snell_chain(const std::vector<Ray>& path, const std::vector<Leg>& legs, const char* who) {
  ASSERT_EQ(path.size(), legs.size()) << who;
  const dvec3 d0 = incoming();
  double x = EYE.x + (EYE.z - legs[0].z_start) * std::tan(THETA0);  // where the ray meets the first face
  for (size_t k = 0; k < legs.size(); ++k) {
    const double s = std::sin(THETA0) / legs[k].n;
    const dvec3 want(s, 0, -std::sqrt(1 - s * s));
    EXPECT_NEAR(glm::length(path[k].dir - want), 0.0, 1e-9) << who << " leg " << k << " (n = " << legs[k].n << ")";
    EXPECT_NEAR(path[k].origin.x, x, 1e-6) << who << " leg " << k;
    EXPECT_NEAR(path[k].origin.z, legs[k].z_start, 1e-6) << who << " leg " << k;
    if (k + 1 < legs.size()) x += (legs[k].z_start - legs[k + 1].z_start) * s / std::sqrt(1 - s * s);
  }
  EXPECT_NEAR(glm::length(path.back().dir - d0), 0.0, 1e-9) << who << ": leaves parallel to the incoming ray";
}

// The tracer's path and the map's (crossing mode, N = 256, cube at the eye), from just off
// the eye (a search does not start at the cube's centre).
void expect_both(const SceneData& s, const std::vector<Leg>& legs) {
  const dvec3 origin = EYE + 0.05 * incoming();
  const RayTracer tracer(s);
  expect_snell_chain(tracer.transmitted_path(origin, incoming(), 8), legs, "raytrace");
  const CubeABuffer cube = build_cube_abuffer(s, s.camera.position, 256);
  MapShadingOptions o;
  const MapShader shader(s, cube, o);
  expect_snell_chain(shader.transmitted_path(origin, incoming(), 8), legs, "map");
}

SceneData slab_scene() {
  SceneData s = empty_scene(EYE, {0, 0, 0}, 60, 64, 48);
  s.render.cube_resolution = 256;
  return s;
}

// Two slabs sharing the face z = -0.5: air -> n1 -> n2 -> air, one interface n1 -> n2 at the
// shared face (two coincident triangles), in either order in the file.
TEST(NestedMedia, TouchingSlabsBendAsSnellsChain) {
  for (const bool water_first : {false, true}) {
    SceneData s = slab_scene();
    const uint32_t glass = add_material(s, clear(1.5));
    const uint32_t water = add_material(s, clear(1.33));
    if (water_first) add_box(s, {-4, -4, -1.2}, {4, 4, -0.5}, water);
    add_box(s, {-4, -4, -0.5}, {4, 4, 0}, glass);
    if (!water_first) add_box(s, {-4, -4, -1.2}, {4, 4, -0.5}, water);
    SCOPED_TRACE(water_first ? "water listed first" : "glass listed first");
    expect_both(s, {{1.5, 0.0}, {1.33, -0.5}, {1.0, -1.2}});
  }
}

// Two slabs of one glass sharing a face: no bend at the shared face (n / n = 1).
TEST(NestedMedia, TouchingSlabsOfOneGlassDoNotBendAtTheSharedFace) {
  SceneData s = slab_scene();
  const uint32_t glass = add_material(s, clear(1.5));
  add_box(s, {-4, -4, -0.5}, {4, 4, 0}, glass);
  add_box(s, {-4, -4, -1.2}, {4, 4, -0.5}, glass);
  expect_both(s, {{1.5, 0.0}, {1.5, -0.5}, {1.0, -1.2}});
}

// A water box inside a glass box: air -> glass -> water -> glass -> air; the nested box is
// entered whatever the order of the two in the file (PRIORITY: the smaller bounds win).
TEST(NestedMedia, WaterBoxInsideAGlassBoxIsEnteredFromTheGlass) {
  for (const bool water_first : {false, true}) {
    SceneData s = slab_scene();
    const uint32_t glass = add_material(s, clear(1.5));
    const uint32_t water = add_material(s, clear(1.33));
    if (water_first) add_box(s, {-2.5, -2.5, -1.5}, {2.5, 2.5, -0.5}, water);
    add_box(s, {-4, -4, -2}, {4, 4, 0}, glass);
    if (!water_first) add_box(s, {-2.5, -2.5, -1.5}, {2.5, 2.5, -0.5}, water);
    SCOPED_TRACE(water_first ? "water listed first" : "glass listed first");
    expect_both(s, {{1.5, 0.0}, {1.33, -0.5}, {1.5, -1.5}, {1.0, -2.0}});
  }
}

// PRIORITY and the crossing sets, on the model alone.
TEST(NestedMedia, ResolveDecidesInterfacesByPriority) {
  SceneData s = slab_scene();
  const uint32_t glass = add_material(s, clear(1.5));
  const uint32_t water = add_material(s, clear(1.33));
  Material opaque;
  const uint32_t wall = add_material(s, opaque);
  const uint32_t small = add_box(s, {-1, -1, -1}, {1, 1, 1}, water);  // object 0
  const uint32_t big = add_box(s, {-2, -2, -2}, {2, 2, 2}, glass);    // object 1
  const uint32_t floor_obj = add_quad(s, {-3, -2, -3}, {-3, -2, 3}, {3, -2, 3}, {3, -2, -3}, wall);
  const Media media(s);
  const TriangleSoup& t = *s.triangles;
  const auto tri_of = [&](uint32_t object) { return s.objects[object].first_triangle; };
  EXPECT_TRUE(media.outranks(small, big));  // nested: the smaller bounds win
  EXPECT_FALSE(media.outranks(big, small));
  EXPECT_TRUE(media.is_medium(tri_of(big)));
  EXPECT_FALSE(media.is_medium(tri_of(floor_obj)));

  // Air into the glass: 1 -> 1.5.
  MediumCrossing enter_big{tri_of(big), false, 1.0};
  Interface i = media.resolve(MediumStack{}, &enter_big, 1);
  EXPECT_FALSE(i.pass);
  EXPECT_EQ(i.n_from, 1.0);
  EXPECT_EQ(i.n_to, 1.5);
  ASSERT_EQ(i.after.size, 1);
  // Inside the glass into the water: 1.5 -> 1.33; then out of the water: 1.33 -> 1.5.
  MediumCrossing enter_small{tri_of(small), false, 2.0};
  const Interface j = media.resolve(i.after, &enter_small, 1);
  EXPECT_EQ(j.n_from, 1.5);
  EXPECT_EQ(j.n_to, 1.33);
  MediumCrossing leave_small{tri_of(small), true, 3.0};
  const Interface k = media.resolve(j.after, &leave_small, 1);
  EXPECT_EQ(k.n_from, 1.33);
  EXPECT_EQ(k.n_to, 1.5);
  // Inside the water only (the stack does not know the glass): the glass' surface inside
  // the water is entered but the water outranks it: no interface.
  MediumStack in_water;
  in_water.add(small, 1.33);
  const Interface none = media.resolve(in_water, &enter_big, 1);
  EXPECT_TRUE(none.pass);
  EXPECT_TRUE(none.after.contains(big));
  // Leaving the glass without having entered it (camera inside): glass -> air, as n / 1.
  MediumCrossing leave_big{tri_of(big), true, 1.0};
  const Interface out = media.resolve(MediumStack{}, &leave_big, 1);
  EXPECT_EQ(out.n_from, 1.5);
  EXPECT_EQ(out.n_to, 1.0);
  // A crossing set with an opaque surface stops there, seen from the media before.
  const MediumCrossing with_floor[2] = {{tri_of(floor_obj), false, 1.0}, leave_big};
  const Interface stop = media.resolve(i.after, with_floor, 2);
  EXPECT_FALSE(stop.pass);
  EXPECT_EQ(t.object_id[stop.triangle], floor_obj);
  EXPECT_TRUE(stop.before.contains(big));
}

}  // namespace
}  // namespace abcube
