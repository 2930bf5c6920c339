// The cube-map convention, texel for texel: what GL rasterises in direction d lands on the
// face and texel that cpu_core's mapping gives for d (cube_map.hpp).
#include <set>

#include <gtest/gtest.h>

#include "raster/cube_map.hpp"
#include "gl/gl_passes.hpp"
#include "gl_test_support.hpp"
#include "base/samples.hpp"

namespace abcube {
namespace {

using test::add_triangle;

// An equilateral triangle centred on `center`, in the plane normal to `normal`,
// with inradius `inradius` (circumradius twice that).
void add_marker(SceneData& s, glm::dvec3 center, glm::dvec3 normal, glm::dvec3 hint, double inradius) {
  const glm::dvec3 n = glm::normalize(normal);
  const glm::dvec3 u = glm::normalize(glm::cross(n, hint));
  const glm::dvec3 v = glm::cross(n, u);
  const double r = 2.0 * inradius;
  auto corner = [&](double a) { return center + r * (std::cos(a) * u + std::sin(a) * v); };
  add_triangle(s, corner(0.0), corner(2.0944), corner(4.18879));
}

// Every texel of every face: a marker in the face plane (|ma| = 1) around the CPU
// texel centre, too small to reach any other centre, must appear in that texel alone.
TEST(CubeConventionGl, EveryTexelCentreLandsOnItsTexel) {
  test::test_context();
  const int n = 12;
  SceneData s;
  for (int face = 0; face < CUBE_FACES; ++face) {
    const CubeFaceBasis& b = cube_face_basis(face);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        // inradius 0.2 texel (a texel is 2/n wide in the face plane): circumradius 0.4.
        add_marker(s, texel_center_direction(face, i, j, n), b.forward, b.t_axis, 0.2 * 2.0 / n);
      }
    }
  }
  GlScene gl(s);
  CubeImage dist;
  CubeIds ids;
  gl.cube_distance(glm::dvec3(0), n, &dist, &ids);
  int wrong = 0;
  for (int face = 0; face < CUBE_FACES; ++face) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const uint32_t expected = static_cast<uint32_t>((face * n + j) * n + i);
        const uint32_t got = ids.faces[face][static_cast<size_t>(j) * n + i];
        if (got != expected && ++wrong < 10) {
          ADD_FAILURE() << "face " << cube_face_name(face) << " texel (" << i << "," << j << "): GL object " << got
                        << ", CPU mapping expects " << expected;
        }
      }
    }
  }
  EXPECT_EQ(wrong, 0);
}

// Directions on a grid over each face, seams and corners included: a marker around d
// (inradius 0.8 texel, perpendicular to d) covers the texel the CPU mapping gives for d.
TEST(CubeConventionGl, GridDirectionsIncludingSeamsAndCorners) {
  test::test_context();
  const int n = 16;
  std::vector<glm::dvec3> dirs;
  std::set<std::tuple<long, long, long>> seen;
  for (int face = 0; face < CUBE_FACES; ++face) {
    for (int a = 0; a <= 4; ++a) {
      for (int c = 0; c <= 4; ++c) {
        const glm::dvec3 d = cube_to_direction(face, a / 4.0, c / 4.0);
        auto key = std::make_tuple(std::lround(d.x * 8), std::lround(d.y * 8), std::lround(d.z * 8));
        if (seen.insert(key).second) dirs.push_back(d);
      }
    }
  }
  ASSERT_EQ(dirs.size(), 98u);  // 6 * 9 interior + 12 * 3 edge + 8 corner directions
  SceneData s;
  for (const glm::dvec3& d : dirs) {
    // One texel spans 2/n of the face plane at |ma| = 1; d has |ma| = 1 here.
    const glm::dvec3 hint = std::abs(d.y) < 0.9 * glm::length(d) ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
    add_marker(s, d, d, hint, 0.8 * 2.0 / n);
  }
  GlScene gl(s);
  CubeImage dist;
  CubeIds ids;
  gl.cube_distance(glm::dvec3(0), n, &dist, &ids);
  for (size_t k = 0; k < dirs.size(); ++k) {
    const CubeTexel t = direction_to_texel(dirs[k], n);
    const uint32_t got = ids.faces[t.face][static_cast<size_t>(t.j) * n + t.i];
    EXPECT_EQ(got, k) << "direction (" << dirs[k].x << "," << dirs[k].y << "," << dirs[k].z << ") -> CPU face "
                      << cube_face_name(t.face) << " texel (" << t.i << "," << t.j << ")";
  }
}

// The 4x8 sample positions (samples.hpp): a face rendered at 8x the columns and 4x the
// rows has pixel centres at the samples, so sample k of texel (i, j) is GL pixel
// (8i + col, 4j + row). A marker around one sample's direction appears at that pixel.
TEST(CubeConventionGl, SubpixelSamplesMatchSupersampledRaster) {
  test::test_context();
  const int n = 4;
  SceneData s;
  std::vector<std::tuple<int, int, int, int>> where;  // face, i, j, k
  for (int face = 0; face < CUBE_FACES; ++face) {
    const CubeFaceBasis& b = cube_face_basis(face);
    for (int k : {0, 7, 13, 24, 31}) {
      const int i = (face + k) % n, j = (face * 3 + k) % n;
      const double su = (i + sample_dx(k)) / n, tv = (j + sample_dy(k)) / n;
      // inradius 0.2 of a sample cell: the cell is 2/(8n) wide and 2/(4n) tall.
      add_marker(s, cube_to_direction(face, su, tv), b.forward, b.t_axis, 0.2 * 2.0 / (8 * n));
      where.emplace_back(face, i, j, k);
    }
  }
  GlScene gl(s);
  CubeImage dist;
  CubeIds ids;
  gl.cube_distance(glm::dvec3(0), MASK_COLUMNS * n, &dist, &ids, MASK_ROWS * n);
  for (size_t m = 0; m < where.size(); ++m) {
    const auto [face, i, j, k] = where[m];
    const int px = MASK_COLUMNS * i + k % MASK_COLUMNS, py = MASK_ROWS * j + k / MASK_COLUMNS;
    EXPECT_EQ(ids.faces[face][static_cast<size_t>(py) * MASK_COLUMNS * n + px], m)
        << "face " << face << " texel (" << i << "," << j << ") sample " << k;
  }
}

}  // namespace
}  // namespace abcube
