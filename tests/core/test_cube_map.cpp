// The CPU side of the cube-map convention (cube_map.hpp); tests/gl checks GL against it.
#include <random>

#include <gtest/gtest.h>

#include "scene/camera.hpp"
#include "raster/cube_map.hpp"
#include "base/samples.hpp"

namespace abcube {
namespace {

// GL 4.5 core spec table 8.19 written out per face, independently of cube_map.cpp.
CubeCoord table_8_19(const glm::dvec3& r) {
  const double ax = std::abs(r.x), ay = std::abs(r.y), az = std::abs(r.z);
  double sc, tc, ma;
  int face;
  if (ax >= ay && ax >= az) {
    face = r.x >= 0 ? 0 : 1;
    sc = r.x >= 0 ? -r.z : r.z;
    tc = -r.y;
    ma = ax;
  } else if (ay >= az) {
    face = r.y >= 0 ? 2 : 3;
    sc = r.x;
    tc = r.y >= 0 ? r.z : -r.z;
    ma = ay;
  } else {
    face = r.z >= 0 ? 4 : 5;
    sc = r.z >= 0 ? r.x : -r.x;
    tc = -r.y;
    ma = az;
  }
  return {face, 0.5 * (sc / ma + 1), 0.5 * (tc / ma + 1)};
}

TEST(CubeMap, AgreesWithSpecTable) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  for (int k = 0; k < 20000; ++k) {
    const glm::dvec3 r(g(rng), g(rng), g(rng));
    const CubeCoord a = direction_to_cube(r), b = table_8_19(r);
    ASSERT_EQ(a.face, b.face);
    ASSERT_NEAR(a.s, b.s, 1e-12);
    ASSERT_NEAR(a.t, b.t, 1e-12);
  }
}

TEST(CubeMap, RoundTripThroughFaceCoordinates) {
  for (int face = 0; face < CUBE_FACES; ++face) {
    for (double s : {0.01, 0.25, 0.5, 0.77, 0.99}) {
      for (double t : {0.02, 0.5, 0.93}) {
        const CubeCoord c = direction_to_cube(3.7 * cube_to_direction(face, s, t));
        EXPECT_EQ(c.face, face);
        EXPECT_NEAR(c.s, s, 1e-12);
        EXPECT_NEAR(c.t, t, 1e-12);
      }
    }
  }
}

TEST(CubeMap, TexelCentresMapBackToTheirTexel) {
  const int n = 17;
  for (int face = 0; face < CUBE_FACES; ++face) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const CubeTexel t = direction_to_texel(texel_center_direction(face, i, j, n), n);
        ASSERT_EQ(t.face, face);
        ASSERT_EQ(t.i, i);
        ASSERT_EQ(t.j, j);
      }
    }
  }
}

// Seams and corners: the tie goes to x, then y (GL's order), and s = 1 clamps inside.
TEST(CubeMap, SeamsAndCorners) {
  EXPECT_EQ(direction_to_cube({1, 1, 1}).face, POS_X);
  EXPECT_EQ(direction_to_cube({-1, 1, 1}).face, NEG_X);
  EXPECT_EQ(direction_to_cube({0, -1, -1}).face, NEG_Y);
  EXPECT_EQ(direction_to_cube({0, 0, -1}).face, NEG_Z);
  const CubeTexel t = direction_to_texel({1, -1, -1}, 8);  // +X: s = 1, t = 1
  EXPECT_EQ(t.face, POS_X);
  EXPECT_EQ(t.i, 7);
  EXPECT_EQ(t.j, 7);
}

// The face's clip matrix puts direction (face, s, t) at NDC (2s-1, 2t-1): the GL raster
// and the CPU mapping share one definition.
TEST(CubeMap, ClipMatrixMatchesMapping) {
  const glm::dvec3 center(0.4, -1.2, 2.5);
  for (int face = 0; face < CUBE_FACES; ++face) {
    const glm::dmat4 m(face_clip_matrix(face, center, 0.01));
    for (double s : {0.1, 0.6}) {
      for (double t : {0.3, 0.9}) {
        const glm::dvec3 p = center + 2.5 * glm::normalize(cube_to_direction(face, s, t));
        const glm::dvec4 clip = m * glm::dvec4(p, 1.0);
        EXPECT_NEAR(clip.x / clip.w, 2 * s - 1, 1e-5);
        EXPECT_NEAR(clip.y / clip.w, 2 * t - 1, 1e-5);
        EXPECT_NEAR(clip.z / clip.w, 0.01 / clip.w, 1e-7);  // reversed infinite depth
        EXPECT_GT(clip.w, 0);
      }
    }
  }
}

// The camera's clip matrix and CameraFrame::direction agree on where a point lands.
TEST(Camera, ClipMatrixMatchesRayDirections) {
  Camera c;
  c.position = {1, 2, -3};
  c.look_at = {0, 0.5, 0};
  c.width = 320;
  c.height = 200;
  c.fov_y_deg = 50;
  const CameraFrame f = make_camera_frame(c);
  const glm::dmat4 m(
      camera_clip_matrix(c.position, c.look_at, c.up, glm::radians(c.fov_y_deg), double(c.width) / c.height, 0.01));
  for (double x : {0.5, 100.25, 319.5}) {
    for (double y : {0.5, 77.0, 199.5}) {
      const glm::dvec4 clip = m * glm::dvec4(f.eye + 4.0 * f.direction(x, y), 1.0);
      EXPECT_NEAR((clip.x / clip.w + 1) * 0.5 * c.width, x, 1e-4);
      EXPECT_NEAR((1 - clip.y / clip.w) * 0.5 * c.height, y, 1e-4);  // GL y up, image y down
    }
  }
}

TEST(Samples, GridCentresAndBitOrder) {
  EXPECT_EQ(MASK_SAMPLES, 32);
  EXPECT_DOUBLE_EQ(sample_dx(0), 1.0 / 16);
  EXPECT_DOUBLE_EQ(sample_dy(0), 1.0 / 8);
  EXPECT_DOUBLE_EQ(sample_dx(31), 15.0 / 16);
  EXPECT_DOUBLE_EQ(sample_dy(31), 7.0 / 8);
  EXPECT_EQ(sample_index(3, 2), 19);
  double mx = 0, my = 0;
  for (int k = 0; k < MASK_SAMPLES; ++k) {
    mx += sample_dx(k);
    my += sample_dy(k);
  }
  EXPECT_DOUBLE_EQ(mx / 32, 0.5);
  EXPECT_DOUBLE_EQ(my / 32, 0.5);
}

}  // namespace
}  // namespace abcube
