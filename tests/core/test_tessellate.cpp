// The primitives' tessellation and the object transform (cpu_core/scene/tessellate.cpp),
// through the loader: known answers for boxes, spheres and transforms, and the closed-surface
// test.
#include <cstdio>
#include <random>

#include "scene_load_fixtures.hpp"

namespace abcube {
namespace {

using namespace scene_test;

// ---- Geometry --------------------------------------------------------------------------

// Triangles are written by runs on several threads and the dropped ones closed up after:
// across many runs, the soup holds the kept triangles in order after what it held, each
// with its own normals, texture coordinates and material.
TEST(SceneLoadGeometry, AppendKeepsTheKeptTrianglesInOrderAcrossRuns) {
  LocalMesh local;
  const size_t count = 70000;  // several runs of triangles
  std::vector<size_t> kept;
  for (size_t t = 0; t < count; ++t) {
    const double x = static_cast<double>(t);
    const bool drop = t % 7 == 3 || t % 1000 == 999;
    const glm::dvec3 far = drop ? glm::dvec3(x + 2, 0, 0) : glm::dvec3(x, 1, 0);  // collinear when dropped
    for (const glm::dvec3& p : {glm::dvec3(x, 0, 0), glm::dvec3(x + 1, 0, 0), far}) {
      local.positions.push_back(p);
      local.normals.push_back(glm::dvec3(0, 0, 1));
      local.uvs.push_back(glm::dvec2(x, 0.5));
    }
    local.material.push_back(static_cast<int>(t % 5));
    if (!drop) kept.push_back(t);
  }
  TriangleSoup soup;
  soup.positions.assign(3, glm::vec3(9));
  soup.normals.assign(3, glm::vec3(0, 1, 0));
  soup.object_id.assign(1, 0);
  soup.material_id.assign(1, 7);
  const size_t dropped = append_triangles(local, make_affine_map(Transform{}), 1, 0, &soup);
  EXPECT_EQ(dropped, count - kept.size());
  ASSERT_EQ(soup.triangle_count(), 1 + kept.size());
  ASSERT_EQ(soup.uvs.size(), soup.positions.size());
  EXPECT_EQ(soup.positions[0], glm::vec3(9));
  EXPECT_EQ(soup.uvs[0], glm::vec2(0.0f));  // the object before got (0, 0)
  for (size_t k = 0; k < kept.size(); ++k) {
    const size_t at = 1 + k;
    const float x = static_cast<float>(kept[k]);
    ASSERT_EQ(soup.positions[3 * at], glm::vec3(x, 0, 0)) << k;
    ASSERT_EQ(soup.positions[3 * at + 2], glm::vec3(x, 1, 0)) << k;
    ASSERT_EQ(soup.uvs[3 * at + 1], glm::vec2(x, 0.5f)) << k;
    ASSERT_EQ(soup.normals[3 * at + 1], glm::vec3(0, 0, 1)) << k;
    ASSERT_EQ(soup.object_id[at], 1u) << k;
    ASSERT_EQ(soup.material_id[at], static_cast<uint32_t>(kept[k] % 5)) << k;
  }
}

TEST(SceneLoadGeometry, ZeroAreaTrianglesAreDroppedAndCounted) {
  const SceneData s = load_text(with_objects(R"([
      {"type": "triangle", "vertices": [[0,0,0],[1,1,1],[2,2,2]]},
      {"type": "triangle", "vertices": [[0,0,0],[0,0,0],[1,0,0]]},
      {"type": "quad", "vertices": [[0,0,0],[1,0,0],[2,0,0],[0,1,0]]},
      {"type": "triangle", "vertices": [[1e30,0,0],[0,1e30,0],[0,0,1e30]], "transform": {"scale": 1e30}},
      {"type": "triangle", "vertices": [[0,0,0],[1e-6,0,0],[0,1e-6,0]]},
      {"type": "triangle", "vertices": [[0,0,0],[1e6,0,0],[0,1e6,0]]}])")
                                    .str());
  ASSERT_EQ(s.objects.size(), 6u);
  EXPECT_EQ(s.dropped_triangles, 4u);  // collinear, repeated vertex, half the quad, overflow
  const uint32_t expected[6] = {0, 0, 1, 0, 1, 1};
  for (size_t i = 0; i < 6; ++i) EXPECT_EQ(s.objects[i].triangle_count, expected[i]) << i;
  EXPECT_EQ(s.triangles->triangle_count(), 3u);
  EXPECT_FALSE(s.objects[0].closed);
}

TEST(SceneLoadGeometry, BoxIsClosedWithOutwardFlatNormals) {
  const SceneData s = load_text(with_objects(R"([{"type": "box", "min": [-1,0,2], "max": [0,2,5]}])").str());
  const SceneObject& box = s.objects[0];
  EXPECT_EQ(box.triangle_count, 12u);
  EXPECT_TRUE(box.closed);
  EXPECT_TRUE(edges_shared_twice(s, box));
  EXPECT_NEAR(object_volume(s, box), 1.0 * 2.0 * 3.0, 1e-9);
  const glm::dvec3 center(-0.5, 1, 3.5);
  for (size_t t = 0; t < 12; ++t) {
    const glm::dvec3 n = geometric_normal(s, t);
    const glm::dvec3 mid = (corner(s, t, 0) + corner(s, t, 1) + corner(s, t, 2)) / 3.0;
    EXPECT_GT(glm::dot(n, mid - center), 0.0) << t;                             // outward
    EXPECT_NEAR(std::fabs(n.x) + std::fabs(n.y) + std::fabs(n.z), 1.0, 1e-12);  // axis-aligned
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(glm::length(glm::dvec3(s.triangles->normals[3 * t + static_cast<size_t>(k)]) - n), 0.0, 1e-6);
    }
  }
}

TEST(SceneLoadGeometry, SphereIsClosedWithOutwardSmoothNormals) {
  for (int segments : {3, 7, 32, 65}) {
    const std::string objects =
        R"([{"type": "sphere", "center": [1,2,3], "radius": 2, "segments": )" + std::to_string(segments) + "}]";
    const SceneData s = load_text(with_objects(objects).str());
    const SceneObject& o = s.objects[0];
    const int rings = std::max(2, segments / 2);
    EXPECT_EQ(o.triangle_count, static_cast<uint32_t>(2 * segments * (rings - 1))) << segments;
    EXPECT_TRUE(o.closed) << segments;
    EXPECT_TRUE(edges_shared_twice(s, o)) << segments;
    const double v = object_volume(s, o), ball = 4.0 / 3.0 * M_PI * 8.0;
    EXPECT_GT(v, 0.0);
    EXPECT_LT(v, ball);  // inscribed polyhedron
    if (segments >= 32) EXPECT_GT(v, 0.97 * ball) << segments;
    const glm::dvec3 c(1, 2, 3);
    for (size_t t = 0; t < o.triangle_count; ++t) {
      const glm::dvec3 g = geometric_normal(s, t);
      for (int k = 0; k < 3; ++k) {
        const glm::dvec3 p = corner(s, t, k);
        const glm::dvec3 n(s.triangles->normals[3 * t + static_cast<size_t>(k)]);
        EXPECT_NEAR(glm::length(p - c), 2.0, 1e-5);
        EXPECT_NEAR(glm::length(n - glm::normalize(p - c)), 0.0, 1e-5);
        EXPECT_GT(glm::dot(n, g), 0.0);  // smooth and geometric normals agree on outside
      }
    }
  }
  // The default is 32 segments.
  EXPECT_EQ(load_text(SceneText().str()).objects[0].triangle_count, 2u * 32 * 15);
}

TEST(SceneLoadGeometry, TransformScalesThenRotatesXYZThenTranslates) {
  // (1,2,3) scaled by (2,3,4) is (2,6,12); 90 degrees about x: (2,-12,6); about y: (6,-12,-2);
  // about z: (12,6,-2); translated by (10,20,30): (22,26,28).
  const SceneData s = load_text(with_objects(R"([{"type": "triangle", "vertices": [[1,2,3],[2,2,3],[1,3,3]],
      "transform": {"scale": [2,3,4], "rotate_deg": [90,90,90], "translate": [10,20,30]}}])")
                                    .str());
  ASSERT_EQ(s.triangles->triangle_count(), 1u);
  const glm::dvec3 p = corner(s, 0, 0);
  EXPECT_NEAR(p.x, 22, 1e-5);
  EXPECT_NEAR(p.y, 26, 1e-5);
  EXPECT_NEAR(p.z, 28, 1e-5);
  // The triangle's normal +z goes through the same rotations: z -> -y -> -y -> +x.
  const glm::dvec3 n(s.triangles->normals[0]);
  EXPECT_NEAR(glm::length(n - glm::dvec3(1, 0, 0)), 0.0, 1e-6);
  EXPECT_NEAR(glm::length(geometric_normal(s, 0) - glm::dvec3(1, 0, 0)), 0.0, 1e-6);
}

TEST(SceneLoadGeometry, MirroringTransformKeepsNormalsOutward) {
  const SceneData s = load_text(with_objects(R"([
      {"type": "box", "min": [0,0,0], "max": [1,2,3], "transform": {"scale": [-1,1,1]}},
      {"type": "triangle", "vertices": [[0,0,0],[1,0,0],[0,1,0]], "transform": {"scale": [1,1,-2]}},
      {"type": "sphere", "center": [0,0,0], "radius": 1, "transform": {"scale": [2,-1,1]}}])")
                                    .str());
  EXPECT_TRUE(s.objects[0].closed);
  EXPECT_NEAR(object_volume(s, s.objects[0]), 6.0, 1e-9);
  // The triangle faced +z; mirrored in z, the surface it becomes still faces the side its
  // normal maps to: the inverse transpose of diag(1,1,-2) takes +z to -z.
  EXPECT_NEAR(glm::length(geometric_normal(s, s.objects[1].first_triangle) - glm::dvec3(0, 0, -1)), 0.0, 1e-6);
  // Ellipsoid x/2, -y, z: normals by the inverse transpose, n ~ (p.x/4, p.y, p.z).
  const SceneObject& e = s.objects[2];
  EXPECT_TRUE(e.closed);
  EXPECT_GT(object_volume(s, e), 0.0);
  for (size_t t = e.first_triangle; t < e.first_triangle + e.triangle_count; ++t) {
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 p = corner(s, t, k);
      const glm::dvec3 n(s.triangles->normals[3 * t + static_cast<size_t>(k)]);
      EXPECT_NEAR(glm::length(n - glm::normalize(glm::dvec3(p.x / 4, p.y, p.z))), 0.0, 1e-5);
    }
  }
}

TEST(SceneLoadGeometry, QuarterTurnsKeepBoxesAxisAligned) {
  const SceneData s = load_text(with_objects(R"([{"type": "box", "min": [0,0,0], "max": [1,2,3],
      "transform": {"rotate_deg": [0,90,0]}}])")
                                    .str());
  const Bounds b = s.bounds();
  EXPECT_EQ(b.lo, glm::dvec3(0, 0, -1));
  EXPECT_EQ(b.hi, glm::dvec3(3, 2, 0));
}

// ---- Tessellation helpers --------------------------------------------------------------

TEST(Tessellate, ClosedSurfaceNeedsConsistentOrientation) {
  SceneData s = load_text(with_objects(R"([{"type": "box", "min": [0,0,0], "max": [1,1,1]}])").str());
  EXPECT_TRUE(is_closed_surface(*s.triangles, 0, 12));
  EXPECT_FALSE(is_closed_surface(*s.triangles, 0, 11));                         // a hole
  std::swap(s.triangles.edit().positions[1], s.triangles.edit().positions[2]);  // one face turned over
  EXPECT_FALSE(is_closed_surface(*s.triangles, 0, 12));
}

// The closed-surface test rules open meshes out by their summed (b - a) x (c - a) before it
// pairs edges: that sum's rounding must never rule a closed one out. Boxes and spheres from
// seeds, far from the origin, at sizes from 1e-4 to 1e4 and turned every way, stay closed
// exactly where the independent edge count says so; and a tube, open at both ends but
// summing to zero, is still found open by its edges.
TEST(Tessellate, ClosedSurfacesStayClosedFarAwayAndAtAnyScale) {
  std::mt19937 rng(20261127);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int closed = 0;
  for (int k = 0; k < 40; ++k) {
    const double scale = std::pow(10.0, -4.0 + 8.0 * unit(rng));
    const double far = std::pow(10.0, 7.0 * unit(rng));
    char shape[128], object[512];
    if (k % 2) {
      std::snprintf(shape, sizeof shape, R"("type": "box", "min": [0,0,0], "max": [1,%g,%g])", 0.01 + unit(rng),
                    1 + 50 * unit(rng));
    } else {
      std::snprintf(shape, sizeof shape, R"("type": "sphere", "center": [0,0,0], "radius": 1, "segments": %d)", 3 + k);
    }
    std::snprintf(object, sizeof object,
                  R"([{%s, "transform": {"scale": %g, "rotate_deg": [%g,%g,%g], "translate": [%g,%g,%g]}}])", shape,
                  scale, 360 * unit(rng), 360 * unit(rng), 360 * unit(rng), far * (unit(rng) - 0.5),
                  far * (unit(rng) - 0.5), far * (unit(rng) - 0.5));
    const std::string text = object;
    SCOPED_TRACE(text);
    const SceneData s = load_text(with_objects(text).str());
    ASSERT_EQ(s.objects.size(), 1u);
    EXPECT_EQ(s.objects[0].closed, edges_shared_twice(s, s.objects[0]));
    EXPECT_EQ(is_closed_surface(*s.triangles, 0, s.objects[0].triangle_count), edges_shared_twice(s, s.objects[0]));
    closed += s.objects[0].closed ? 1 : 0;
  }
  EXPECT_GE(closed, 30);  // float positions far away may merge corners: most stay closed
  // A box without its two end faces: every (b - a) x (c - a) meets its opposite.
  const SceneData box = load_text(with_objects(R"([{"type": "box", "min": [0,0,0], "max": [1,1,1]}])").str());
  ASSERT_EQ(box.triangles->triangle_count(), 12u);
  SceneData tube = box;
  TriangleSoup& soup = tube.triangles.edit();
  std::vector<size_t> keep;
  for (size_t t = 0; t < 12; ++t) {
    const glm::vec3 g = glm::cross(soup.positions[3 * t + 1] - soup.positions[3 * t],
                                   soup.positions[3 * t + 2] - soup.positions[3 * t]);
    if (g.y == 0.0f) keep.push_back(t);  // the four sides
  }
  ASSERT_EQ(keep.size(), 8u);
  TriangleSoup sides;
  for (const size_t t : keep) {
    for (int c = 0; c < 3; ++c) sides.positions.push_back(soup.positions[3 * t + static_cast<size_t>(c)]);
    sides.object_id.push_back(0);
  }
  EXPECT_FALSE(is_closed_surface(sides, 0, 8));
}

// EdgePairing: a grid of quads large enough for the pairing's two partitions (tessellate.cpp
// first_equal), two triangles a quad, as two objects side by side: every half-edge's partner
// is the one the grid says (the other triangle of its quad, or the quad across), none across
// the objects' seam or on the border, whichever thread found it.
TEST(EdgePairing, AGridLargerThanOnePartitionPairsAsItsTopologySays) {
  constexpr int W = 180, H = 80;  // 28,800 triangles, 86,400 half-edges
  TriangleSoup soup;
  const auto at = [](int i, int j) {
    return glm::vec3(0.25f * static_cast<float>(i), 0.0f, 0.5f * static_cast<float>(j));
  };
  // Quad (i, j): triangle A = (i,j) (i+1,j) (i+1,j+1), B = (i,j) (i+1,j+1) (i,j+1); the
  // objects meet between columns W / 2 - 1 and W / 2.
  for (int j = 0; j < H; ++j) {
    for (int i = 0; i < W; ++i) {
      const uint32_t object = i < W / 2 ? 0u : 1u;
      for (const glm::vec3& p : {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)})
        soup.positions.push_back(p);
      soup.object_id.push_back(object);
      soup.object_id.push_back(object);
    }
  }
  const auto half = [](int i, int j, int tri, int edge) {
    return static_cast<uint32_t>(3 * (2 * (j * W + i) + tri) + edge);
  };
  const std::vector<uint32_t> partner = edge_partners(soup, 0, soup.triangle_count());
  ASSERT_EQ(partner.size(), 3u * soup.triangle_count());
  for (int j = 0; j < H; ++j) {
    for (int i = 0; i < W; ++i) {
      const bool seam_right = i + 1 == W / 2, seam_left = i == W / 2;
      // A's edges: 0 the bottom (the top of the quad below, its B's edge 1), 1 the right side
      // (the left of the quad to the right, its B's edge 2), 2 the diagonal (B's edge 0).
      EXPECT_EQ(partner[half(i, j, 0, 0)], j > 0 ? half(i, j - 1, 1, 1) : NO_PARTNER) << i << " " << j;
      EXPECT_EQ(partner[half(i, j, 0, 1)], i + 1 < W && !seam_right ? half(i + 1, j, 1, 2) : NO_PARTNER)
          << i << " " << j;
      EXPECT_EQ(partner[half(i, j, 0, 2)], half(i, j, 1, 0)) << i << " " << j;
      EXPECT_EQ(partner[half(i, j, 1, 0)], half(i, j, 0, 2)) << i << " " << j;
      EXPECT_EQ(partner[half(i, j, 1, 1)], j + 1 < H ? half(i, j + 1, 0, 0) : NO_PARTNER) << i << " " << j;
      EXPECT_EQ(partner[half(i, j, 1, 2)], i > 0 && !seam_left ? half(i - 1, j, 0, 1) : NO_PARTNER) << i << " " << j;
      if (HasFailure()) return;
    }
  }
}

}  // namespace
}  // namespace abcube
