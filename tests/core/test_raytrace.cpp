// Known-answer tests of the exact ray tracer (raytrace.hpp): every expected value is
// computed analytically from the geometry, never from a golden image.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "scene/camera.hpp"
#include "base/constants.hpp"
#include "base/error.hpp"
#include "io/image_io.hpp"
#include "io/metrics.hpp"
#include "reference/raytrace.hpp"
#include "scene/scene_load.hpp"
#include "scene/tie_rule.hpp"
#include "material/shading.hpp"

// Scene builders for hand-made test scenes, independent of the scene loader. External
// linkage: test_pov.cpp declares and uses them too.
namespace abcube::testkit {

using glm::dvec3;

SceneData empty_scene(const dvec3& eye, const dvec3& look_at, double fov_y_deg, int width, int height) {
  SceneData s;
  s.file = "(test scene)";
  s.camera.position = eye;
  s.camera.look_at = look_at;
  s.camera.up = {0, 1, 0};
  s.camera.fov_y_deg = fov_y_deg;
  s.camera.width = width;
  s.camera.height = height;
  s.background = dvec3(0.0);
  s.ambient = dvec3(0.0);
  s.render.method = "raytrace";
  s.render.max_depth = 4;
  return s;
}

uint32_t add_material(SceneData& s, const Material& m) {
  s.materials.push_back(m);
  if (s.materials.back().name.empty()) s.materials.back().name = "m" + std::to_string(s.materials.size() - 1);
  return static_cast<uint32_t>(s.materials.size() - 1);
}

// A surface showing its colour under ambient light 1: ka = 1, kd = 0.
Material emissive(const dvec3& color) {
  Material m;
  m.color = color;
  m.ambient = 1;
  m.diffuse = 0;
  return m;
}

uint32_t begin_object(SceneData& s, const std::string& type, uint32_t material, bool closed) {
  SceneObject o;
  o.type = type;
  o.path = "objects[" + std::to_string(s.objects.size()) + "]";
  o.material = material;
  o.closed = closed;
  o.first_triangle = static_cast<uint32_t>(s.triangles->triangle_count());
  s.objects.push_back(o);
  return static_cast<uint32_t>(s.objects.size() - 1);
}

// Appends a triangle with corner normals to the last object begun.
void add_triangle(SceneData& s, const dvec3& a, const dvec3& b, const dvec3& c, const dvec3& na, const dvec3& nb,
                  const dvec3& nc) {
  TriangleSoup& t = s.triangles.edit();
  for (const dvec3& p : {a, b, c}) t.positions.emplace_back(p);
  for (const dvec3& n : {na, nb, nc}) t.normals.emplace_back(n);
  t.object_id.push_back(static_cast<uint32_t>(s.objects.size() - 1));
  t.material_id.push_back(s.objects.back().material);
  ++s.objects.back().triangle_count;
}

void add_flat_triangle(SceneData& s, const dvec3& a, const dvec3& b, const dvec3& c) {
  const dvec3 n = glm::normalize(glm::cross(b - a, c - a));
  add_triangle(s, a, b, c, n, n, n);
}

// A flat triangle wound so that its geometric normal points along `outward`.
void add_oriented(SceneData& s, const dvec3& a, const dvec3& b, const dvec3& c, const dvec3& outward) {
  if (glm::dot(glm::cross(b - a, c - a), outward) >= 0) {
    add_flat_triangle(s, a, b, c);
  } else {
    add_flat_triangle(s, a, c, b);
  }
}

uint32_t add_quad(SceneData& s, const dvec3& a, const dvec3& b, const dvec3& c, const dvec3& d, uint32_t material) {
  const uint32_t id = begin_object(s, "quad", material, false);
  add_flat_triangle(s, a, b, c);
  add_flat_triangle(s, a, c, d);
  return id;
}

// Closed axis-aligned box, outward winding, flat normals.
uint32_t add_box(SceneData& s, const dvec3& lo, const dvec3& hi, uint32_t material) {
  const uint32_t id = begin_object(s, "box", material, true);
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      dvec3 outward(0.0);
      outward[axis] = side ? 1.0 : -1.0;
      auto corner = [&](int i, int j) {
        dvec3 p;
        p[axis] = side ? hi[axis] : lo[axis];
        p[u] = i ? hi[u] : lo[u];
        p[v] = j ? hi[v] : lo[v];
        return p;
      };
      add_oriented(s, corner(0, 0), corner(1, 0), corner(1, 1), outward);
      add_oriented(s, corner(0, 0), corner(1, 1), corner(0, 1), outward);
    }
  }
  return id;
}

// Latitude-longitude sphere (poles on y), segments/2 bands, smooth normals, outward winding;
// shared vertices are computed once so the mesh is closed exactly.
uint32_t add_sphere(SceneData& s, const dvec3& center, double radius, int segments, uint32_t material) {
  const uint32_t id = begin_object(s, "sphere", material, true);
  const int rings = segments / 2;
  const double pi = 3.14159265358979323846;
  auto unit = [&](int i, int j) {
    if (i == 0) return dvec3(0, 1, 0);
    if (i == rings) return dvec3(0, -1, 0);
    const double theta = pi * i / rings, phi = 2.0 * pi * (j % segments) / segments;
    return dvec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
  };
  auto tri = [&](const dvec3& a, const dvec3& b, const dvec3& c) {
    const dvec3 pa = center + radius * a, pb = center + radius * b, pc = center + radius * c;
    if (glm::dot(glm::cross(pb - pa, pc - pa), a + b + c) >= 0) {
      add_triangle(s, pa, pb, pc, a, b, c);
    } else {
      add_triangle(s, pa, pc, pb, a, c, b);
    }
  };
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      if (i + 1 < rings) tri(unit(i, j), unit(i + 1, j), unit(i + 1, j + 1));
      if (i > 0) tri(unit(i, j), unit(i + 1, j + 1), unit(i, j + 1));
    }
  }
  return id;
}

}  // namespace abcube::testkit

namespace abcube {
namespace {

using glm::dvec3;
using namespace testkit;

// The image point (pixel units) where world point p projects (inverse of CameraFrame::direction).
glm::dvec2 project(const CameraFrame& f, const dvec3& p) {
  const dvec3 d = p - f.eye;
  const double z = glm::dot(d, f.forward);
  const double nx = glm::dot(d, f.right) / (z * f.tan_half_fov_y * f.aspect);
  const double ny = glm::dot(d, f.up) / (z * f.tan_half_fov_y);
  return {(nx + 1.0) * 0.5 * f.width, (1.0 - ny) * 0.5 * f.height};
}

dvec3 pixel_center_dir(const CameraFrame& f, int x, int y) { return glm::normalize(f.direction(x + 0.5, y + 0.5)); }

dvec3 pixel(const Image& img, int x, int y) { return dvec3(img.rgb(x, y)); }

RaytraceOptions centre_samples() {
  RaytraceOptions o;
  o.samples_per_pixel = 1;
  o.threads = 2;
  return o;
}

// Writes actual, expected and their heatmap into the build folder for a person to look at.
void save_failure(const std::string& name, const Image& actual, const Image& expected) {
  const std::string dir = std::string(ABCUBE_BINARY_DIR) + "/test-artifacts";
  std::filesystem::create_directories(dir);
  write_image(dir + "/" + name + ".actual.png", actual);
  write_image(dir + "/" + name + ".expected.png", expected);
  write_image(dir + "/" + name + ".diff.png", error_heatmap(actual, expected));
}

// THE TIE RULE (scene/tie_rule.hpp) over a list of hits of a ray along `dir` (not empty):
// the highest-ranking of those at the nearest one's distance; *tied counts those, and
// *nearest_out (when given) is the nearest (smallest t, then ranking above).
TriangleHit rule_over(const TriangleSoup& soup, const dvec3& dir, const std::vector<TriangleHit>& all, int* tied,
                      TriangleHit* nearest_out = nullptr) {
  TriangleHit nearest = all[0];
  for (const TriangleHit& h : all) {
    if (h.t < nearest.t || (h.t == nearest.t && ranks_above(soup, h.triangle, nearest.triangle))) nearest = h;
  }
  TriangleHit best = nearest;
  *tied = 0;
  for (const TriangleHit& h : all) {
    if (!same_distance(soup, dir, {nearest.triangle, nearest.t}, {h.triangle, h.t})) continue;
    ++*tied;
    if (ranks_above(soup, h.triangle, best.triangle)) best = h;
  }
  if (nearest_out) *nearest_out = nearest;
  return best;
}

// One query of `bvh` against a loop over `candidates` (its triangles): the set of all hits
// (each once) and the visible hit by the rule, bit for bit. Returns whether the ray hits.
bool check_query(const Bvh& bvh, const std::vector<uint32_t>& candidates, const RayQuery& q, const std::string& what) {
  const TriangleSoup& soup = bvh.soup();
  std::vector<TriangleHit> brute;
  std::vector<uint32_t> brute_ids, ids;
  for (const uint32_t t : candidates) {
    TriangleHit h;
    if (intersect_triangle(q, soup, t, INFINITY, &h)) {
      brute.push_back(h);
      brute_ids.push_back(t);
    }
  }
  bvh.for_each_hit(q, INFINITY, [&](const TriangleHit& h) {
    ids.push_back(h.triangle);
    return true;
  });
  std::sort(ids.begin(), ids.end());
  std::sort(brute_ids.begin(), brute_ids.end());
  EXPECT_EQ(ids, brute_ids) << what;
  TriangleHit fast;
  EXPECT_EQ(bvh.visible_hit(q, INFINITY, &fast), !brute.empty()) << what;
  if (brute.empty()) return false;
  int tied = 0;
  const TriangleHit best = rule_over(soup, q.dir, brute, &tied);
  EXPECT_EQ(fast.triangle, best.triangle) << what;
  EXPECT_EQ(fast.t, best.t) << what;
  return true;
}

TEST(Raytrace, BvhMatchesBruteForce) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  SceneData s = empty_scene({0, 0, 5}, {0, 0, 0}, 60, 8, 8);
  const uint32_t mat = add_material(s, Material{});
  begin_object(s, "mesh", mat, false);
  for (int i = 0; i < 3000; ++i) {
    const dvec3 c(u(rng), u(rng), u(rng));
    add_flat_triangle(s, c, c + 0.2 * dvec3(u(rng), u(rng), u(rng)), c + 0.2 * dvec3(u(rng), u(rng), u(rng)));
  }
  const RayTracer tracer(s);
  const Bvh& bvh = tracer.bvh();
  const TriangleSoup& soup = *s.triangles;
  int hits = 0;
  for (int r = 0; r < 3000; ++r) {
    const dvec3 o = 2.0 * dvec3(u(rng), u(rng), u(rng));
    const dvec3 d(u(rng), u(rng), u(rng));
    const RayQuery q(o, d);
    TriangleHit brute;
    bool brute_found = false;
    double tmax = INFINITY;
    std::vector<uint32_t> brute_all;
    for (uint32_t t = 0; t < soup.triangle_count(); ++t) {
      TriangleHit h;
      if (intersect_triangle(q, soup, t, INFINITY, &h)) brute_all.push_back(t);
      if (intersect_triangle(q, soup, t, tmax, &h)) {
        brute = h;
        tmax = h.t;
        brute_found = true;
      }
    }
    TriangleHit fast;
    ASSERT_EQ(bvh.visible_hit(q, INFINITY, &fast), brute_found) << "ray " << r;
    std::vector<uint32_t> all;
    bvh.for_each_hit(q, INFINITY, [&](const TriangleHit& h) {
      all.push_back(h.triangle);
      return true;
    });
    std::sort(all.begin(), all.end());
    EXPECT_EQ(all, brute_all) << "ray " << r;  // each hit once
    if (!brute_found) continue;
    ++hits;
    EXPECT_EQ(fast.t, brute.t) << "ray " << r;  // bit-identical: same test, same triangle
    EXPECT_EQ(fast.triangle, brute.triangle) << "ray " << r;
  }
  EXPECT_GT(hits, 500);  // the comparison is not vacuous
  // Built in chunks (12 of 256 triangles, each under an identity instance, as a soup of more
  // than Bvh::BUILD_CHUNK is): the same answers.
  const Bvh chunked(soup, 256);
  std::vector<uint32_t> every(soup.triangle_count());
  std::iota(every.begin(), every.end(), 0u);
  int chunked_hits = 0;
  for (int r = 0; r < 3000; ++r) {
    const RayQuery q(2.0 * dvec3(u(rng), u(rng), u(rng)), dvec3(u(rng), u(rng), u(rng)));
    chunked_hits += check_query(chunked, every, q, "chunked, ray " + std::to_string(r));
  }
  EXPECT_GT(chunked_hits, 500);
}

// A Bvh over some of a soup's triangles (the searches' side structure) answers for those
// only, naming them by their index in the soup.
TEST(Raytrace, BvhOverASubsetAnswersForItsTrianglesOnly) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  SceneData s = empty_scene({0, 0, 5}, {0, 0, 0}, 60, 8, 8);
  const uint32_t mat = add_material(s, Material{});
  begin_object(s, "mesh", mat, false);
  for (int i = 0; i < 600; ++i) {
    const dvec3 c(u(rng), u(rng), u(rng));
    add_flat_triangle(s, c, c + 0.3 * dvec3(u(rng), u(rng), u(rng)), c + 0.3 * dvec3(u(rng), u(rng), u(rng)));
  }
  const TriangleSoup& soup = *s.triangles;
  std::vector<uint32_t> subset;
  for (uint32_t t = 1; t < soup.triangle_count(); t += 3) subset.push_back(t);
  const Bvh bvh(soup, subset);
  const Bvh chunked(soup, subset, 50);  // 4 chunks, the last one short
  ASSERT_EQ(bvh.triangle_count(), subset.size());
  ASSERT_EQ(chunked.triangle_count(), subset.size());
  int hits = 0;
  for (int r = 0; r < 3000; ++r) {
    const RayQuery q(2.0 * dvec3(u(rng), u(rng), u(rng)), dvec3(u(rng), u(rng), u(rng)));
    hits += check_query(bvh, subset, q, "ray " + std::to_string(r));
    check_query(chunked, subset, q, "chunked, ray " + std::to_string(r));
  }
  EXPECT_GT(hits, 100);
}

// Embree's float traversal never loses a hit the double test makes (bvh.hpp "Exactness"):
// rays aimed exactly at the vertices and edge midpoints of closed spheres and open quads,
// the worst case for float, from origins inside the scene and up to 1e4 times its size
// away, at scene sizes from 1e-6 to 1e6. Every query must give what a loop over every
// triangle gives: the visible hit (tie rule) and the set of all hits.
TEST(Raytrace, BvhMatchesBruteForceAtEdgesFarAndAtEveryScale) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int queries = 0, hits = 0;
  for (const double scale : {1e-6, 1.0, 1e6}) {
    SceneData s = empty_scene({0, 0, 5}, {0, 0, 0}, 60, 8, 8);
    const uint32_t mat = add_material(s, Material{});
    add_sphere(s, scale * dvec3(0.1, 0.2, 0.3), scale * 0.7, 16, mat);
    add_sphere(s, scale * dvec3(-0.6, -0.1, 0.2), scale * 0.3, 12, mat);
    for (int i = 0; i < 6; ++i) {
      const dvec3 c = scale * dvec3(u(rng), u(rng), u(rng));
      const dvec3 a = scale * 0.4 * dvec3(u(rng), u(rng), u(rng)), b = scale * 0.4 * dvec3(u(rng), u(rng), u(rng));
      add_quad(s, c - a - b, c + a - b, c + a + b, c - a + b, mat);
    }
    const TriangleSoup& soup = *s.triangles;
    const Bvh bvh(soup);
    const Bvh chunked(soup, 37);  // in chunks under identity instances: the same answers
    std::vector<uint32_t> all(soup.triangle_count());
    std::iota(all.begin(), all.end(), 0u);
    std::vector<dvec3> targets;
    for (size_t i = 0; i < soup.positions.size(); ++i) {
      const dvec3 v(soup.positions[i]), w(soup.positions[i % 3 == 2 ? i - 2 : i + 1]);
      targets.push_back(v);
      targets.push_back(0.5 * (v + w));
    }
    for (size_t k = 0; k < targets.size(); ++k) {
      const double reach = std::pow(10.0, 4.0 * (k % 5) / 4.0);  // 1 to 1e4 times the scene
      const dvec3 o = scale * reach * 2.0 * glm::normalize(dvec3(u(rng), u(rng), u(rng)));
      const RayQuery q(o, targets[k] - o);
      ++queries;
      hits += check_query(bvh, all, q, "scale " + std::to_string(scale) + " target " + std::to_string(k));
      check_query(chunked, all, q, "chunked, scale " + std::to_string(scale) + " target " + std::to_string(k));
    }
  }
  EXPECT_GT(hits, queries * 9 / 10);  // aimed at the triangles: nearly every ray hits
}

// THE TIE RULE (scene/tie_rule.hpp) through the BVH: 12 objects of triangles in three
// shared tilted planes (float vertices: coplanar to float precision only), up to 12 deep
// at one point, among random ones. visible_hit must give what the rule gives over a loop
// on every triangle: the highest-ranking of the hits at the nearest one's distance.
TEST(Raytrace, VisibleHitIsTheTieRuleOverEveryTriangle) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  SceneData s = empty_scene({0, 0, 5}, {0, 0, 0}, 60, 8, 8);
  const uint32_t mat = add_material(s, Material{});
  const dvec3 normals[3] = {glm::normalize(dvec3(0.2, 1, 0.3)), glm::normalize(dvec3(1, 0.1, -0.4)), dvec3(0, 0, 1)};
  for (int object = 0; object < 12; ++object) {
    begin_object(s, "mesh", mat, false);
    for (int i = 0; i < 60; ++i) {
      const dvec3 n = normals[i % 3];
      const dvec3 a = glm::normalize(glm::cross(n, dvec3(0.3, 0.5, 0.7))), b = glm::cross(n, a);
      const dvec3 c = 0.1 * double(i % 3) * n + 0.4 * u(rng) * a + 0.4 * u(rng) * b;
      add_flat_triangle(s, c - 0.5 * a - 0.4 * b, c + 0.5 * a - 0.3 * b, c + 0.6 * b);
    }
    for (int i = 0; i < 40; ++i) {
      const dvec3 c(u(rng), u(rng), u(rng));
      add_flat_triangle(s, c, c + 0.2 * dvec3(u(rng), u(rng), u(rng)), c + 0.2 * dvec3(u(rng), u(rng), u(rng)));
    }
  }
  const RayTracer tracer(s);
  const Bvh& bvh = tracer.bvh();
  const TriangleSoup& soup = *s.triangles;
  int hits = 0, ties = 0, deep = 0;
  for (int r = 0; r < 3000; ++r) {
    const dvec3 o = 2.0 * dvec3(u(rng), u(rng), u(rng));
    const dvec3 d = 0.3 * dvec3(u(rng), u(rng), u(rng)) - o;  // towards the planes' shared part
    const RayQuery q(o, d);
    std::vector<TriangleHit> all;
    for (uint32_t t = 0; t < soup.triangle_count(); ++t) {
      TriangleHit h;
      if (intersect_triangle(q, soup, t, INFINITY, &h)) all.push_back(h);
    }
    TriangleHit fast;
    ASSERT_EQ(bvh.visible_hit(q, INFINITY, &fast), !all.empty()) << "ray " << r;
    if (all.empty()) continue;
    ++hits;
    int tied = 0;
    TriangleHit nearest;
    const TriangleHit best = rule_over(soup, d, all, &tied, &nearest);
    ties += best.triangle != nearest.triangle;
    deep += tied > 8;
    EXPECT_EQ(fast.triangle, best.triangle) << "ray " << r;
    EXPECT_EQ(fast.t, best.t) << "ray " << r;
  }
  EXPECT_GT(hits, 2000);
  EXPECT_GT(ties, 500) << "rays whose visible hit is not the nearest by t";
  EXPECT_GT(deep, 100) << "rays with more than 8 surfaces at one distance (the second traversal)";
  std::printf("[ ties     ] %d hits, %d decided by the tie rule, %d with more than 8 tied\n", hits, ties, deep);
}

TEST(Raytrace, WatertightClosedSphere) {
  SceneData s = empty_scene({0, 0, 5}, {0, 0, 0}, 60, 8, 8);
  const dvec3 c(0.1, 0.2, 0.3);
  add_sphere(s, c, 1.0, 48, add_material(s, Material{}));
  const RayTracer tracer(s);
  const TriangleSoup& soup = *s.triangles;
  int misses = 0, rays = 0;
  // Rays through every vertex and every edge midpoint: from inside points they must all
  // hit; from outside points, those aimed at a vertex or edge facing the origin too
  // (near the silhouette a rounding-off ray may pass outside, legitimately).
  const dvec3 inside[] = {c, c + dvec3(0.3, -0.2, 0.1), c + dvec3(-0.5, 0.6, 0.2)};
  const dvec3 outside[] = {{3.0, 2.5, 4.0}, {-0.2, -4.0, 0.7}};
  for (size_t i = 0; i < soup.positions.size(); ++i) {
    const dvec3 v(soup.positions[i]);
    const dvec3 w(soup.positions[i % 3 == 2 ? i - 2 : i + 1]);
    for (const dvec3& target : {v, 0.5 * (v + w)}) {
      for (const dvec3& origin : inside) {
        Hit h;
        ++rays;
        misses += !tracer.intersect(origin, target - origin, &h);
      }
      for (const dvec3& origin : outside) {
        if (glm::dot(glm::normalize(target - c), glm::normalize(origin - target)) < 0.2) continue;
        Hit h;
        ++rays;
        misses += !tracer.intersect(origin, target - origin, &h);
      }
    }
  }
  EXPECT_GT(rays, 30000);
  EXPECT_EQ(misses, 0) << "of " << rays << " rays through vertices and edges";
}

TEST(Raytrace, HitCarriesExactGeometry) {
  SceneData s = empty_scene({0, 0, 5}, {0, 0, 0}, 60, 8, 8);
  add_material(s, Material{});
  const uint32_t mat = add_material(s, Material{});
  const uint32_t obj = begin_object(s, "triangle", mat, false);
  const dvec3 na(0, 0, 1), nb = glm::normalize(dvec3(1, 0, 1)), nc = glm::normalize(dvec3(0, 1, 1));
  add_triangle(s, {0, 0, -2}, {2, 0, -2}, {0, 2, -2}, na, nb, nc);
  const RayTracer tracer(s);
  Hit h;
  ASSERT_TRUE(tracer.intersect({0.5, 0.5, 0}, {0, 0, -2}, &h));
  EXPECT_DOUBLE_EQ(h.t, 1.0);  // in units of |dir|
  EXPECT_DOUBLE_EQ(h.point.x, 0.5);
  EXPECT_DOUBLE_EQ(h.point.z, -2.0);
  EXPECT_NEAR(h.barycentric.x, 0.5, 1e-15);
  EXPECT_NEAR(h.barycentric.y, 0.25, 1e-15);
  EXPECT_NEAR(h.barycentric.z, 0.25, 1e-15);
  EXPECT_EQ(h.geometric_normal, dvec3(0, 0, 1));
  const dvec3 ns = glm::normalize(0.5 * na + 0.25 * nb + 0.25 * nc);
  EXPECT_NEAR(glm::length(h.shading_normal - ns), 0.0, 1e-7);  // float normals
  EXPECT_EQ(h.object_id, obj);
  EXPECT_EQ(h.material_id, mat);
  EXPECT_TRUE(h.front_face);
  EXPECT_FALSE(tracer.intersect({0.5, 0.5, 0}, {0, 0, -2}, 0.999, &h));  // tmax is exclusive of hits beyond
  ASSERT_TRUE(tracer.intersect({0.5, 0.5, -4}, {0, 0, 1}, &h));
  EXPECT_FALSE(h.front_face);
}

// THE ORIGIN RULE (triangle_test.hpp): a ray never meets a triangle whose plane passes
// through its origin. Origins exactly on the plane (vertices, edge midpoints, interior points
// with power-of-two weights: exact in double), at scales 1e-3 to 1e4, in every direction,
// grazing ones too: no hit, where the sign of a rounded t = 0 would hit about half of them.
TEST(Raytrace, NoHitFromAnOriginOnTheTrianglesPlane) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  TriangleSoup soup;
  int rays = 0, hits = 0;
  for (int k = 0; k < 200; ++k) {
    const double scale = std::pow(10.0, -3.0 + 7.0 * (k % 8) / 7.0);
    const dvec3 shift = scale * 3.0 * dvec3(unit(rng), unit(rng), unit(rng));
    glm::vec3 p[3];
    for (glm::vec3& v : p) v = glm::vec3(shift + scale * dvec3(unit(rng), unit(rng), unit(rng)));
    soup.positions.assign(p, p + 3);
    const dvec3 a(p[0]), b(p[1]), c(p[2]);
    const dvec3 n = glm::normalize(glm::cross(b - a, c - a));
    for (const dvec3& origin : {a, (a + b) * 0.5, (b + c) * 0.5, (a + b + 2.0 * c) * 0.25, (a + 2.0 * b + c) * 0.25}) {
      for (int j = 0; j < 50; ++j) {
        dvec3 d = glm::normalize(dvec3(unit(rng), unit(rng), unit(rng)));
        if (j % 5 == 0) d = glm::normalize(d - glm::dot(d, n) * n + 1e-6 * unit(rng) * n);  // grazing
        TriangleHit h;
        ++rays;
        if (intersect_triangle(RayQuery(origin, d), soup, 0, INFINITY, &h)) ++hits;
      }
    }
  }
  EXPECT_EQ(rays, 200 * 5 * 50);
  EXPECT_EQ(hits, 0);
}

// The rule costs no real hit: from 1e-9 of the scene off the plane (where secondary rays
// start, shading.hpp), every ray towards the triangle's inside meets it, at scales 1e-3 to 1e4.
TEST(Raytrace, OriginRuleKeepsHitsFromTheSecondaryRaysOffset) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), weight(0.1, 1.0);
  TriangleSoup soup;
  int misses = 0;
  for (int k = 0; k < 400; ++k) {
    const double scale = std::pow(10.0, -3.0 + 7.0 * (k % 8) / 7.0);
    glm::vec3 p[3];
    for (glm::vec3& v : p) v = glm::vec3(scale * dvec3(unit(rng), unit(rng), unit(rng)));
    soup.positions.assign(p, p + 3);
    const dvec3 a(p[0]), b(p[1]), c(p[2]);
    const dvec3 n = glm::normalize(glm::cross(b - a, c - a));
    const double wa = weight(rng), wb = weight(rng), wc = weight(rng);
    const dvec3 inside = (wa * a + wb * b + wc * c) / (wa + wb + wc);
    const double offset = self_intersection_offset(inside, 2.0 * scale);
    const dvec3 origin = inside + offset * n;
    dvec3 d = glm::normalize(-n + 0.5 * dvec3(unit(rng), unit(rng), unit(rng)));
    if (glm::dot(d, n) > -0.05) d = -n;
    TriangleHit h;
    if (!intersect_triangle(RayQuery(origin, d), soup, 0, INFINITY, &h)) ++misses;
  }
  EXPECT_EQ(misses, 0);
}

// A camera exactly on a plane sees none of it: every camera ray starts on the plane, so every
// pixel is the background, as the cube map, which gives the plane no area, sees it.
TEST(Raytrace, CameraOnAPlaneSeesNoneOfIt) {
  SceneData s = empty_scene({0.375, 1.25, 2.0}, {-4.0, 0.2, -20.0}, 70, 48, 36);
  s.background = {0.2, 0.3, 0.4};
  begin_object(s, "quad", add_material(s, emissive({0.9, 0.1, 0.1})), false);
  // A plane through the eye, tilted, its vertices exact in float: the eye is on it exactly.
  const dvec3 eye = s.camera.position, u(1.0, 0.25, 0.0), v(0.0, 0.5, 1.0);
  add_flat_triangle(s, eye - 40.0 * u - 40.0 * v, eye + 40.0 * u - 40.0 * v, eye + 40.0 * u + 40.0 * v);
  add_flat_triangle(s, eye - 40.0 * u - 40.0 * v, eye + 40.0 * u + 40.0 * v, eye - 40.0 * u + 40.0 * v);
  for (const glm::vec3& p : s.triangles->positions) {
    ASSERT_EQ(glm::dot(glm::dvec3(p) - eye, glm::cross(u, v)), 0.0);  // exactly on the plane
  }
  RaytraceOptions o;
  o.threads = 2;
  const Image img = render_raytrace(s, o);
  int plane_pixels = 0;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) plane_pixels += pixel(img, x, y) != dvec3(glm::vec3(s.background));
  }
  EXPECT_EQ(plane_pixels, 0);
}

// A shadow ray, or any ray, started on its own surface towards the light does not meet that
// surface: the light is unblocked.
TEST(Raytrace, RayFromItsOwnSurfaceDoesNotMeetIt) {
  SceneData s = empty_scene({0, 5, 5}, {0, 0, 0}, 60, 8, 8);
  const uint32_t m = add_material(s, Material{});
  begin_object(s, "triangle", m, false);
  const dvec3 a(-3.1, 0.2, -2.9), b(2.7, -0.3, -3.3), c(0.1, 0.4, 3.7);
  add_flat_triangle(s, a, b, c);
  const RayTracer tracer(s);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int hits = 0;
  for (int k = 0; k < 2000; ++k) {
    const dvec3 pa(s.triangles->positions[0]), pb(s.triangles->positions[1]), pc(s.triangles->positions[2]);
    const dvec3 origin = k % 2 ? (pa + pb + 2.0 * pc) * 0.25 : (pb + pc) * 0.5;
    const dvec3 light(unit(rng) * 10, 5 + unit(rng) * 4, unit(rng) * 10);
    Hit h;
    hits += tracer.intersect(origin, light - origin, 1.0, &h);
  }
  EXPECT_EQ(hits, 0);
}

TEST(Raytrace, MirrorAt45SendsMarkerToComputedPixel) {
  // Camera at the origin looking down -z; a mirror in the plane x + z = -5 (45 degrees);
  // a red square at x = 3, out of the camera's view, seen only in the mirror.
  SceneData s = empty_scene({0, 0, 0}, {0, 0, -1}, 60, 64, 64);
  s.ambient = dvec3(1.0);
  s.render.max_depth = 1;
  Material mirror;
  mirror.color = dvec3(0.0);
  mirror.ambient = 0;
  mirror.diffuse = 0;
  mirror.reflect = 1;
  const dvec3 mc(0, 0, -5), mu = glm::normalize(dvec3(1, 0, -1)), mv(0, 1, 0);
  add_quad(s, mc - 4.0 * mu - 4.0 * mv, mc + 4.0 * mu - 4.0 * mv, mc + 4.0 * mu + 4.0 * mv, mc - 4.0 * mu + 4.0 * mv,
           add_material(s, mirror));
  const dvec3 m(3.0, 0.5, -4.0);  // marker centre, side 0.4, in the plane x = 3
  add_quad(s, m + dvec3(0, -0.2, -0.2), m + dvec3(0, 0.2, -0.2), m + dvec3(0, 0.2, 0.2), m + dvec3(0, -0.2, 0.2),
           add_material(s, emissive({1, 0, 0})));
  RaytraceOptions opt;
  opt.threads = 2;
  const Image img = render_raytrace(s, opt);

  // Expected: the marker's mirror image M' = M - 2 (n.M - d) n projects through the camera.
  const dvec3 n = glm::normalize(dvec3(1, 0, 1));
  const double plane_d = glm::dot(n, mc);
  const CameraFrame f = make_camera_frame(s.camera);
  const glm::dvec2 expect = project(f, m - 2.0 * (glm::dot(n, m) - plane_d) * n);
  const double side_px =
      0.4 / (glm::dot(m - 2.0 * (glm::dot(n, m) - plane_d) * n, f.forward) * f.tan_half_fov_y) * 0.5 * f.height;
  double area = 0, cx = 0, cy = 0, stray = 0;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const dvec3 c = pixel(img, x, y);
      area += c.r;
      cx += c.r * (x + 0.5);
      cy += c.r * (y + 0.5);
      stray += c.g + c.b;
    }
  }
  ASSERT_GT(area, 0.0) << "the marker is not visible in the mirror";
  EXPECT_NEAR(cx / area, expect.x, 0.1);
  EXPECT_NEAR(cy / area, expect.y, 0.1);
  EXPECT_NEAR(area, side_px * side_px, 0.05 * side_px * side_px);
  EXPECT_EQ(stray, 0.0);
  EXPECT_NEAR(pixel(img, static_cast<int>(expect.x), static_cast<int>(expect.y)).r, 1.0, 1e-6);
}

TEST(Raytrace, GlassSlabShiftsRayLaterally) {
  // Slab z in [-2, -1] (thickness d = 1), ior 1.5; ray from the origin at 30 degrees.
  const double ior = 1.5, d = 1.0, theta = 30.0 * PI / 180.0;
  const double theta_t = std::asin(std::sin(theta) / ior);
  const double expect_shift = d * std::sin(theta - theta_t) / std::cos(theta_t);
  SceneData s = empty_scene({0, 0, 3}, {0, 0, 0}, 60, 8, 8);
  s.ambient = dvec3(1.0);
  Material glass;
  glass.color = dvec3(1.0);
  glass.ambient = 0;
  glass.diffuse = 0;
  glass.transmit = 1;
  glass.ior = ior;
  add_box(s, {-10, -10, -2}, {10, 10, -1}, add_material(s, glass));
  // Thin strips on a wall at z = -4: green where the shifted ray lands, red where an
  // unrefracted ray would.
  const double x_shifted = std::tan(theta) * 1.0 + std::tan(theta_t) * d + std::tan(theta) * 2.0;
  const double x_straight = std::tan(theta) * 4.0;
  auto strip = [&](double x, const dvec3& color) {
    add_quad(s, {x - 5e-4, -1, -4}, {x + 5e-4, -1, -4}, {x + 5e-4, 1, -4}, {x - 5e-4, 1, -4},
             add_material(s, emissive(color)));
  };
  strip(x_shifted, {0, 1, 0});
  strip(x_straight, {1, 0, 0});
  const RayTracer tracer(s);
  const dvec3 dir(std::sin(theta), 0.0, -std::cos(theta));

  // Ray level: in through z = -1, out through z = -2, parallel to the incident ray.
  Hit in, out;
  ASSERT_TRUE(tracer.intersect({0, 0, 0}, dir, &in));
  EXPECT_TRUE(in.front_face);
  bool tir = true;
  const Ray inside = tracer.transmitted_ray(in, dir, &tir);
  EXPECT_FALSE(tir);
  EXPECT_NEAR(inside.dir.x, std::sin(theta_t), 1e-12);  // Snell
  ASSERT_TRUE(tracer.intersect(inside.origin, inside.dir, &out));
  EXPECT_FALSE(out.front_face);
  const Ray exit = tracer.transmitted_ray(out, inside.dir, &tir);
  EXPECT_FALSE(tir);
  EXPECT_NEAR(glm::length(exit.dir - dir), 0.0, 1e-12);
  const dvec3 e = exit.origin;  // perpendicular distance between incident and exit lines
  EXPECT_NEAR(glm::length(e - glm::dot(e, dir) * dir), expect_shift, 1e-7);

  // Trace level: the ray's colour is what the shifted line meets (kt = 1 twice).
  const dvec3 c = tracer.trace({0, 0, 0}, dir, 0);
  EXPECT_NEAR(c.g, 1.0, 1e-12);
  EXPECT_EQ(c.r, 0.0);
}

TEST(Raytrace, TotalInternalReflectionBeyondCriticalAngle) {
  const double ior = 1.5, critical = std::asin(1.0 / ior);
  SceneData s = empty_scene({0, 0, 3}, {0, 0, 0}, 60, 8, 8);
  s.ambient = dvec3(1.0);
  s.render.max_depth = 6;
  Material glass;
  glass.color = dvec3(1.0);
  glass.ambient = 0;
  glass.diffuse = 0;
  glass.transmit = 1;
  glass.ior = ior;
  add_box(s, {-10, -10, -2}, {10, 10, -1}, add_material(s, glass));
  // A green wall far along +x that catches the grazing exit ray above the slab.
  add_quad(s, {100, -100, -0.9999}, {100, 100, -0.9999}, {100, 100, 100}, {100, -100, 100},
           add_material(s, emissive({0, 1, 0})));
  const RayTracer tracer(s);
  const dvec3 origin(0, 0, -1.5);  // inside the glass
  auto ray_at = [](double theta) { return dvec3(std::sin(theta), 0.0, std::cos(theta)); };
  for (double f : {1.0 - 1e-9, 1.0 + 1e-9}) {
    const double theta = critical * f;
    Hit h;
    ASSERT_TRUE(tracer.intersect(origin, ray_at(theta), &h));
    EXPECT_FALSE(h.front_face);  // leaving through z = -1
    bool tir = false;
    const Ray t = tracer.transmitted_ray(h, ray_at(theta), &tir);
    const dvec3 c = tracer.trace(origin, ray_at(theta), 0);
    if (f < 1.0) {
      EXPECT_FALSE(tir) << "just below the critical angle";
      EXPECT_GT(t.dir.z, 0.0);
      EXPECT_NEAR(c.g, 1.0, 1e-12);  // the exit ray reaches the wall
    } else {
      EXPECT_TRUE(tir) << "just beyond the critical angle";
      EXPECT_NEAR(t.dir.z, -std::cos(theta), 1e-15);
      EXPECT_NEAR(t.dir.x, std::sin(theta), 1e-15);
      EXPECT_EQ(c, dvec3(0.0));  // trapped: bounces inside until the depth limit
    }
  }
}

TEST(Raytrace, SphereUnderPointLightIsLambert) {
  const dvec3 center(0, 0, -5), light_pos(5, 5, 0), od(0.8, 0.6, 0.4);
  SceneData s = empty_scene({0, 0, 0}, center, 30, 48, 48);
  s.ambient = dvec3(0.1);
  PointLight l;
  l.position = light_pos;
  s.lights.push_back(l);
  Material m;
  m.color = od;
  add_sphere(s, center, 1.0, 256, add_material(s, m));
  const Image img = render_raytrace(s, centre_samples());
  const CameraFrame f = make_camera_frame(s.camera);
  Image expected = img;
  int checked = 0, lit = 0, failures = 0;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      // Exact ray-sphere intersection; skip the silhouette and the terminator band.
      const dvec3 d = pixel_center_dir(f, x, y);
      const double b = glm::dot(d, center);
      const double h2 = b * b - (glm::dot(center, center) - 1.0);
      if (h2 < 0.1) continue;  // misses, or within ~5% of the radius from the silhouette
      const dvec3 p = (b - std::sqrt(h2)) * d;
      const double ndotl = glm::dot(p - center, glm::normalize(light_pos - p));
      if (std::fabs(ndotl) < 0.05) continue;
      const dvec3 want = 0.1 * od + std::max(0.0, ndotl) * od;  // ka Ia Od + kd Od I N.L
      expected.set_rgb(x, y, glm::vec3(want));
      const double err = glm::length(pixel(img, x, y) - want);
      ++checked;
      lit += ndotl > 0;
      if (err > (ndotl > 0 ? 2e-3 : 1e-6)) ++failures;  // unlit: ambient exactly
    }
  }
  EXPECT_GT(checked, 800);
  EXPECT_GT(lit, 300);
  EXPECT_LT(checked - lit, checked);  // some unlit pixels too
  EXPECT_EQ(failures, 0);
  if (failures) save_failure("raytrace_sphere_lambert", img, expected);
}

// Renders a floor lit from (0, 4, 0) with a square blocker at height 2; checks every pixel
// against the similar-triangles shadow [-1, 1]^2 scaled by the blocker's transmittance.
void check_shadow(const Material& blocker, const dvec3& shadow_factor, const std::string& name) {
  SceneData s = empty_scene({0, 6, 6}, {0, 0, 0}, 50, 64, 64);
  s.ambient = dvec3(0.1);
  PointLight l;
  l.position = {0, 4, 0};
  s.lights.push_back(l);
  Material floor;
  floor.color = dvec3(1.0);
  add_quad(s, {-10, 0, -10}, {-10, 0, 10}, {10, 0, 10}, {10, 0, -10}, add_material(s, floor));
  add_quad(s, {-0.5, 2, -0.5}, {-0.5, 2, 0.5}, {0.5, 2, 0.5}, {0.5, 2, -0.5}, add_material(s, blocker));
  const Image img = render_raytrace(s, centre_samples());
  const CameraFrame f = make_camera_frame(s.camera);
  Image expected = img;
  int shadowed = 0, lit = 0, failures = 0;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const dvec3 d = pixel_center_dir(f, x, y);
      if (d.y >= 0) continue;
      const dvec3 q = f.eye + ((2.0 - f.eye.y) / d.y) * d;  // crosses the blocker's plane
      if (std::fabs(q.x) < 0.51 && std::fabs(q.z) < 0.51) continue;
      const dvec3 p = f.eye + (-f.eye.y / d.y) * d;  // floor point
      if (std::fabs(p.x) > 9.9 || std::fabs(p.z) > 9.9) continue;
      if (std::fabs(std::fabs(p.x) - 1.0) < 0.02 || std::fabs(std::fabs(p.z) - 1.0) < 0.02) continue;
      const bool in_shadow = std::fabs(p.x) < 1.0 && std::fabs(p.z) < 1.0;
      const double ndotl = glm::normalize(l.position - p).y;
      const dvec3 want = dvec3(0.1) + (in_shadow ? shadow_factor : dvec3(1.0)) * ndotl;
      expected.set_rgb(x, y, glm::vec3(want));
      (in_shadow ? shadowed : lit) += 1;
      if (glm::length(pixel(img, x, y) - want) > 1e-6) ++failures;
    }
  }
  EXPECT_GT(shadowed, 100) << name;
  EXPECT_GT(lit, 1000) << name;
  EXPECT_EQ(failures, 0) << name;
  if (failures) save_failure("raytrace_shadow_" + name, img, expected);
}

TEST(Raytrace, ShadowFallsWhereGeometryPutsIt) {
  check_shadow(Material{}, dvec3(0.0), "opaque");
  Material glass;  // kt * Od, not refracted
  glass.color = {1.0, 0.5, 0.25};
  glass.transmit = 0.5;
  glass.ior = 1.5;
  check_shadow(glass, {0.5, 0.25, 0.125}, "glass");
  Material veil;  // 1 - opacity
  veil.opacity = 0.3;
  check_shadow(veil, dvec3(0.7), "veil");
}

// Rodrigues' rotation formula: rotation by `angle` about unit `axis`.
glm::dmat3 rotation(const dvec3& axis, double angle) {
  const dvec3 k = glm::normalize(axis);
  const glm::dmat3 kx(0, k.z, -k.y, -k.z, 0, k.x, k.y, -k.x, 0);  // column-major cross matrix
  return glm::dmat3(1.0) + std::sin(angle) * kx + (1.0 - std::cos(angle)) * (kx * kx);
}

// Moves a whole scene rigidly; every shading value is unchanged, but the hit points no
// longer have exactly representable coordinates.
void move_scene(SceneData& s, const glm::dmat3& rot, const dvec3& shift) {
  for (glm::vec3& p : s.triangles.edit().positions) p = glm::vec3(rot * dvec3(p) + shift);
  for (glm::vec3& n : s.triangles.edit().normals) n = glm::vec3(rot * dvec3(n));
  s.camera.position = rot * s.camera.position + shift;
  s.camera.look_at = rot * s.camera.look_at + shift;
  s.camera.up = rot * s.camera.up;
  for (PointLight& l : s.lights) l.position = rot * l.position + shift;
}

TEST(Raytrace, GrazingHitsDoNotSelfShadowOrSelfReflect) {
  // A floor seen and lit at grazing angles, moved off the axes: every floor pixel must get
  // the full Lambert term (no self-shadowing) and the background in its reflection.
  SceneData s = empty_scene({0, 0.01, 10}, {0, 0, -100}, 10, 64, 64);
  s.ambient = dvec3(0.1);
  s.background = {0.2, 0.3, 0.4};
  PointLight l;
  l.position = {0, 0.3, -60};
  s.lights.push_back(l);
  Material floor;
  floor.color = dvec3(0.5);
  floor.reflect = 0.5;
  begin_object(s, "triangle", add_material(s, floor), false);
  add_flat_triangle(s, {-300, 0, 200}, {300, 0, 200}, {0, 0, -400});  // one plane, no crease
  const CameraFrame f = make_camera_frame(s.camera);                  // expectations in the unmoved frame
  move_scene(s, rotation({1, 2, 3}, 0.7), {3.3, 1.7, -2.9});
  const Image img = render_raytrace(s, centre_samples());
  Image expected = img;
  int checked = 0, failures = 0;
  double min_cos = 1.0;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const dvec3 d = pixel_center_dir(f, x, y);
      if (d.y >= 0) continue;
      const dvec3 p = f.eye + (-f.eye.y / d.y) * d;
      if (std::fabs(p.x) > 100 || std::fabs(p.z) > 150) continue;
      const double ndotl = glm::normalize(l.position - p).y;
      const dvec3 want = 0.1 * floor.color + ndotl * floor.color + 0.5 * s.background;
      expected.set_rgb(x, y, glm::vec3(want));
      min_cos = std::min(min_cos, -d.y);
      ++checked;
      if (glm::length(pixel(img, x, y) - want) > 1e-5) ++failures;
    }
  }
  EXPECT_GT(checked, 1000);
  EXPECT_LT(min_cos, 0.005);  // the view really grazes the floor (under 0.3 degrees)
  EXPECT_EQ(failures, 0);
  if (failures) save_failure("raytrace_grazing", img, expected);
}

TEST(Raytrace, DepthLimitTruncatesMirrorSeries) {
  // Two facing mirrors, a ray perpendicular to both: C = a (1 + kr + ... + kr^D).
  for (int depth : {0, 1, 2, 5}) {
    SceneData s = empty_scene({0, 0, 0}, {0, 0, -1}, 60, 8, 8);
    s.ambient = dvec3(0.2);
    s.render.max_depth = depth;
    Material m;
    m.color = dvec3(1.0);
    m.diffuse = 0;
    m.reflect = 0.5;
    const uint32_t mat = add_material(s, m);
    add_quad(s, {-5, -5, -1}, {5, -5, -1}, {5, 5, -1}, {-5, 5, -1}, mat);
    add_quad(s, {-5, -5, 1}, {-5, 5, 1}, {5, 5, 1}, {5, -5, 1}, mat);
    const RayTracer tracer(s);
    double want = 0, w = 0.2;
    for (int k = 0; k <= depth; ++k, w *= 0.5) want += w;
    EXPECT_NEAR(tracer.trace({0, 0, 0}, {0, 0, -1}, 0).r, want, 1e-12) << "max_depth " << depth;
  }
}

TEST(Raytrace, OpacityBlendsWithWhatIsBehind) {
  SceneData s = empty_scene({0, 0, 0}, {0, 0, -1}, 60, 8, 8);
  s.ambient = dvec3(1.0);
  s.render.max_depth = 0;  // the continuation does not consume depth
  Material veil = emissive({0, 0, 1});
  veil.opacity = 0.25;
  Material veil2 = emissive({0, 1, 0});
  veil2.opacity = 0.5;
  add_quad(s, {-5, -5, -2}, {5, -5, -2}, {5, 5, -2}, {-5, 5, -2}, add_material(s, veil));
  add_quad(s, {-5, -5, -3}, {5, -5, -3}, {5, 5, -3}, {-5, 5, -3}, add_material(s, veil2));
  add_quad(s, {-5, -5, -4}, {5, -5, -4}, {5, 5, -4}, {-5, 5, -4}, add_material(s, emissive({1, 0, 0})));
  const RayTracer tracer(s);
  const dvec3 c = tracer.trace({0, 0, 0}, {0.1, 0.05, -1}, 0);
  const dvec3 want = 0.25 * dvec3(0, 0, 1) + 0.75 * (0.5 * dvec3(0, 1, 0) + 0.5 * dvec3(1, 0, 0));
  EXPECT_NEAR(glm::length(c - want), 0.0, 1e-12);
}

TEST(Raytrace, SamplesAreTheABufferPositions) {
  // A white quad covering the image right of x = 5.28 and below y = 9.3 (y grows down):
  // pixel column 5 has 6 of 8 sample columns inside (dx = (c + 0.5)/8 > 0.28), pixel
  // row 9 has 3 of 4 sample rows inside (dy = (r + 0.5)/4 > 0.3). Mirrored sample
  // positions would give 2/8 and 1/4.
  SceneData s = empty_scene({0, 0, 0}, {0, 0, -1}, 90, 16, 16);
  s.ambient = dvec3(1.0);
  const double left = 2.0 * 5.28 / 16 - 1.0, top = 1.0 - 2.0 * 9.3 / 16;  // at z = -1, tan = 1
  add_quad(s, {left, -5, -1}, {5, -5, -1}, {5, top, -1}, {left, top, -1}, add_material(s, emissive(dvec3(1.0))));
  RaytraceOptions opt;
  opt.threads = 1;
  const Image img = render_raytrace(s, opt);
  EXPECT_DOUBLE_EQ(img.rgb(5, 12).r, 0.75);
  EXPECT_DOUBLE_EQ(img.rgb(8, 9).r, 0.75);
  EXPECT_DOUBLE_EQ(img.rgb(5, 9).r, 18.0 / 32.0);
  EXPECT_DOUBLE_EQ(img.rgb(8, 8).r, 0.0);
  EXPECT_DOUBLE_EQ(img.rgb(4, 12).r, 0.0);
  EXPECT_DOUBLE_EQ(img.rgb(6, 12).r, 1.0);
  const Image centre = render_raytrace(s, centre_samples());
  EXPECT_DOUBLE_EQ(centre.rgb(5, 12).r, 1.0);  // centre 5.5 > 5.28
  EXPECT_DOUBLE_EQ(centre.rgb(8, 9).r, 1.0);   // centre 9.5 > 9.3
}

// Floor, glass sphere in a glass box, mirror box, veil, two lights.
SceneData mixed_scene(int w, int h) {
  SceneData s = empty_scene({0.3, 1.5, 4}, {0, 0.2, 0}, 50, w, h);
  s.ambient = dvec3(0.1);
  s.background = {0.1, 0.2, 0.3};
  PointLight a, b;
  a.position = {2, 4, 3};
  b.position = {-3, 2, 1};
  b.color = dvec3(0.3);
  b.cast_shadows = false;
  s.lights = {a, b};
  Material floor, glass, inner, mirror, veil;
  floor.color = {0.8, 0.7, 0.6};
  glass.color = dvec3(1.0);
  glass.ambient = glass.diffuse = 0;
  glass.transmit = 0.9;
  glass.reflect = 0.1;
  glass.ior = 1.5;
  inner = glass;
  inner.ior = 1.33;
  mirror.color = dvec3(0.1);
  mirror.reflect = 0.8;
  mirror.specular = 0.5;
  veil.color = {0.2, 0.4, 1.0};
  veil.opacity = 0.5;
  add_quad(s, {-5, -1, -5}, {-5, -1, 5}, {5, -1, 5}, {5, -1, -5}, add_material(s, floor));
  add_box(s, {-1, -1, -1}, {1, 1, 1}, add_material(s, glass));
  add_sphere(s, {0, 0, 0}, 0.6, 32, add_material(s, inner));
  add_box(s, {1.5, -1, -1.5}, {2.5, 0.5, -0.5}, add_material(s, mirror));
  add_quad(s, {-2.5, -1, 0}, {-1.5, -1, 1}, {-1.5, 1, 1}, {-2.5, 1, 0}, add_material(s, veil));
  return s;
}

TEST(Raytrace, NestedGlassAndGrazingRaysStayFinite) {
  const SceneData s = mixed_scene(48, 48);
  RaytraceOptions opt;
  opt.threads = 2;
  const Image img = render_raytrace(s, opt);
  int bad = 0;
  for (float v : img.data) bad += !(std::isfinite(v) && v >= 0.0f);
  EXPECT_EQ(bad, 0);
  // Rays aimed exactly at vertices (silhouette corners and edges) and rays lying in a
  // face's plane or leaving glass at exactly the critical angle.
  const RayTracer tracer(s);
  const dvec3 eye = s.camera.position;
  int rays = 0;
  bad = 0;
  auto check = [&](const dvec3& o, const dvec3& d) {
    const dvec3 c = tracer.trace(o, d, 0);
    ++rays;
    bad += !(std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b) &&
             glm::all(glm::greaterThanEqual(c, dvec3(0))));
  };
  for (const glm::vec3& v : s.triangles->positions) check(eye, dvec3(v) - eye);
  check({-5, 1, 0}, {1, 0, 0});     // in the plane of the glass box's top face
  check({-5, -1, 0.3}, {1, 0, 0});  // in the floor's plane
  check({0, 0.9, 0}, {std::sin(std::asin(1 / 1.5)), std::cos(std::asin(1 / 1.5)), 0});  // inside, critical
  EXPECT_EQ(bad, 0) << "of " << rays << " rays";
}

TEST(Raytrace, ImageIdenticalForAnyThreadCount) {
  const SceneData s = mixed_scene(40, 30);
  RaytraceOptions one, three;
  one.threads = 1;
  three.threads = 3;
  std::vector<double> progress;
  three.progress = [&](double done) { progress.push_back(done); };  // called on this thread
  RaytraceStats st1, st3;
  const Image a = render_raytrace(s, one, &st1);
  const Image b = render_raytrace(s, three, &st3);
  ASSERT_EQ(a.data.size(), b.data.size());
  EXPECT_EQ(std::memcmp(a.data.data(), b.data.data(), a.data.size() * sizeof(float)), 0);
  EXPECT_EQ(st1.primary_rays, 40u * 30u * 32u);
  EXPECT_EQ(st1.primary_rays, st3.primary_rays);
  EXPECT_EQ(st1.secondary_rays, st3.secondary_rays);
  EXPECT_EQ(st1.shadow_rays, st3.shadow_rays);
  EXPECT_GT(st1.secondary_rays, 0u);
  EXPECT_GT(st1.shadow_rays, 0u);
  EXPECT_EQ(st3.threads, 3);
  ASSERT_FALSE(progress.empty());
  EXPECT_TRUE(std::is_sorted(progress.begin(), progress.end()));
  EXPECT_EQ(progress.back(), 1.0);  // ends at 1 whichever thread did the last row
}

// The Embree tracer against the images of the tracer before it (the hand-written double
// BVH, commit f347706): every repository scene at 128 pixels wide, 32 samples, 2 threads,
// pinned in tests/golden/pre_embree/ (README.md there says how they were made). The
// answers are exact both ways, so the images are expected identical; the floor is 60 dB.
TEST(Raytrace, EmbreeTracerMatchesThePreEmbreeImagesOnEveryRepositoryScene) {
  const std::filesystem::path root(ABCUBE_SOURCE_DIR);
  std::vector<std::filesystem::path> scenes;
  for (const char* dir : {"scenes", "scenes/bench"}) {
    for (const auto& e : std::filesystem::directory_iterator(root / dir)) {
      // textured.json is newer than the Embree change: no image from before it exists.
      if (e.path().extension() == ".json" && e.path().stem() != "textured") scenes.push_back(e.path());
    }
  }
  std::sort(scenes.begin(), scenes.end());
  ASSERT_GE(scenes.size(), 5u);
  for (const std::filesystem::path& path : scenes) {
    SceneData s = load_scene(path.string());
    const int w = 128;
    s.camera.height = (s.camera.height * w + s.camera.width / 2) / s.camera.width;
    s.camera.width = w;
    RaytraceOptions o;
    o.threads = 2;
    const Image now = render_raytrace(s, o);
    const std::string name = path.stem().string();
    const std::filesystem::path old = root / "tests/golden/pre_embree" / (name + "_raytrace.exr");
    ASSERT_TRUE(std::filesystem::exists(old)) << "no pre-Embree image for " << path << ": " << old;
    const Image before = read_image(old.string());
    const ImageError e = image_error(now, before);
    const bool identical = now.data == before.data;
    std::printf("[ embree   ] %-16s %dx%d PSNR against the pre-Embree tracer %s dB%s\n", name.c_str(), now.width,
                now.height, std::isinf(e.psnr) ? "inf" : std::to_string(e.psnr).c_str(),
                identical ? " (identical floats)" : "");
    EXPECT_GE(e.psnr, 60.0) << name;
    if (!identical) save_failure("pre_embree_" + name, now, before);
  }
}

TEST(Raytrace, RejectsBadOptions) {
  const SceneData s = mixed_scene(4, 4);
  RaytraceOptions opt;
  opt.samples_per_pixel = 3;  // not a rung of the ladder
  EXPECT_THROW(render_raytrace(s, opt), InputError);
  opt.samples_per_pixel = 64;
  EXPECT_THROW(render_raytrace(s, opt), InputError);
  std::array<Image, LOWER_RUNGS> rungs;
  opt.samples_per_pixel = 16;
  opt.rungs = &rungs;  // the rungs are prefixes of the 32
  EXPECT_THROW(render_raytrace(s, opt), InputError);
  opt.rungs = nullptr;
  opt.samples_per_pixel = 1;
  opt.threads = -1;
  EXPECT_THROW(render_raytrace(s, opt), InputError);
}

}  // namespace
}  // namespace abcube
