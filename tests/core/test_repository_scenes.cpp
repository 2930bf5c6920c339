// The repository's scenes (scenes/): every one loads, and hidden_point.json does what
// scenes/README.md says.
#include "scene_load_fixtures.hpp"

namespace abcube {
namespace {

using namespace scene_test;

// ---- The repository's scenes -----------------------------------------------------------

TEST(RepositoryScenes, AllLoad) {
  const fs::path root = fs::path(ABCUBE_SOURCE_DIR) / "scenes";
  int count = 0;
  for (const fs::path& dir : {root, root / "bench"}) {
    for (const auto& entry : fs::directory_iterator(dir)) {
      if (entry.path().extension() != ".json") continue;
      SCOPED_TRACE(entry.path().string());
      SceneData s;
      EXPECT_NO_THROW(s = load_scene(entry.path().string()));
      EXPECT_GT(s.triangles->triangle_count(), 0u);
      EXPECT_FALSE(s.lights.empty());
      EXPECT_EQ(s.dropped_triangles, 0u);
      ++count;
    }
  }
  EXPECT_GE(count, 5);
  const SceneData bench = load_scene((root / "bench/spheres_terrain.json").string());
  EXPECT_GE(bench.triangles->triangle_count(), 100000u);
}

// Exact ray-triangle intersection (Moller-Trumbore 1997); returns the distance or -1.
double hit_triangle(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& a, const glm::dvec3& b,
                    const glm::dvec3& c) {
  const glm::dvec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
  const double det = glm::dot(e1, p);
  if (std::fabs(det) < 1e-12) return -1;
  const glm::dvec3 s = o - a, q = glm::cross(s, e1);
  const double u = glm::dot(s, p) / det, v = glm::dot(d, q) / det;
  if (u < 0 || v < 0 || u + v > 1) return -1;
  const double t = glm::dot(e2, q) / det;
  return t > 1e-9 ? t : -1;
}

// hidden_point.json (thesis fig. 11.3) does what scenes/README.md says: some points of the
// green triangle are hidden from the camera by the red one, yet seen in the mirror.
TEST(RepositoryScenes, HiddenPointSeenOnlyInTheMirror) {
  const SceneData s = load_scene(std::string(ABCUBE_SOURCE_DIR) + "/scenes/hidden_point.json");
  ASSERT_EQ(s.objects.size(), 3u);  // mirror, red, green: one triangle each
  auto tri = [&](size_t i, int k) { return corner(s, i, k); };
  const glm::dvec3 eye = s.camera.position;
  int seen_in_mirror = 0, hidden_but_reflected = 0;
  const int n = 60;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; i + j <= n; ++j) {
      // A point on the mirror, and the camera ray reflected there.
      const glm::dvec3 m =
          tri(0, 0) + (tri(0, 1) - tri(0, 0)) * (i / double(n)) + (tri(0, 2) - tri(0, 0)) * (j / double(n));
      const glm::dvec3 d = glm::normalize(m - eye);
      const glm::dvec3 normal = geometric_normal(s, 0);
      const glm::dvec3 r = d - 2.0 * glm::dot(d, normal) * normal;
      const double to_red = hit_triangle(m, r, tri(1, 0), tri(1, 1), tri(1, 2));
      const double to_green = hit_triangle(m, r, tri(2, 0), tri(2, 1), tri(2, 2));
      if (to_green < 0 || (to_red > 0 && to_red < to_green)) continue;
      ++seen_in_mirror;
      const glm::dvec3 g = m + to_green * r;
      const double along = glm::length(g - eye);
      const double blocked = hit_triangle(eye, (g - eye) / along, tri(1, 0), tri(1, 1), tri(1, 2));
      if (blocked > 0 && blocked < along) ++hidden_but_reflected;
    }
  }
  EXPECT_GT(seen_in_mirror, 50);
  EXPECT_GT(hidden_but_reflected, seen_in_mirror / 5) << seen_in_mirror;
}

}  // namespace
}  // namespace abcube
