// edge_ties.hpp: the pixels where a rasteriser with snapped vertices may decide a sample
// unlike the exact rules, and the tracer's pixel mask that renders them (the hybrid method).
#include <gtest/gtest.h>

#include "abuffer_testkit.hpp"
#include "raster/edge_ties.hpp"
#include "base/samples.hpp"
#include "reference/raytrace.hpp"

namespace abcube {
namespace {

using namespace testkit;
using glm::dvec3;

// The camera at the origin looking down +z, fov_y 90 degrees, 16 x 12 pixels: the sample
// grid is 128 x 48, and a point (x, y, 1) falls at sample coordinates (64 - 48 x, 24 - 24 y)
// (right is -x). y = 0.3125 is sample row 16's centre (16.5), exactly, in float and double.
constexpr int W = 16, H = 12;
SceneData camera_at_origin() { return empty_scene({0, 0, 0}, {0, 0, 1}, 90, W, H); }

// A triangle with one horizontal edge at height y from x = -0.5 to 0.5 (sample columns 40
// to 88: pixels 5 to 10) at depth 1, its apex far below (its other edges cross no sample
// centre of pixel row 4).
void add_ledge(SceneData& s, double y) {
  begin_object(s, "triangle", add_material(s, Material{}), false);
  add_flat_triangle(s, {-0.5, y, 1}, {0.5, y, 1}, {0.0, -40.0, 1});
}

bool marked(const std::vector<uint8_t>& m, int x, int y) { return m[static_cast<size_t>(y * W + x)] != 0; }

TEST(EdgeTies, AnEdgeAlongASampleRowMarksEveryPixelItCrosses) {
  SceneData s = camera_at_origin();
  add_ledge(s, 0.3125);
  const std::vector<uint8_t> m = edge_tie_pixels(s);
  for (int x = 5; x <= 10; ++x) EXPECT_TRUE(marked(m, x, 4)) << "pixel " << x;
  EXPECT_FALSE(marked(m, 4, 4));  // beyond the edge's ends
  EXPECT_FALSE(marked(m, 11, 4));
  for (int y : {3, 5}) {
    for (int x = 5; x <= 10; ++x) EXPECT_FALSE(marked(m, x, y)) << "pixel " << x << ", " << y;
  }
}

TEST(EdgeTies, AnEdgeFartherThanEpsFromEveryCentreMarksNothingThere) {
  for (const double off : {0.02, -0.02, 0.5}) {  // samples; eps is 1/128
    SceneData s = camera_at_origin();
    add_ledge(s, 0.3125 - off / 24.0);
    const std::vector<uint8_t> m = edge_tie_pixels(s);
    for (int x = 5; x <= 10; ++x) EXPECT_FALSE(marked(m, x, 4)) << "offset " << off << ", pixel " << x;
  }
  // Within eps on the other side of the centre: marked again.
  SceneData s = camera_at_origin();
  add_ledge(s, 0.3125 - 0.004 / 24.0);
  EXPECT_TRUE(marked(edge_tie_pixels(s), 7, 4));
}

TEST(EdgeTies, AVerticalEdgeOnASampleColumnAndAnEdgeBehindTheEye) {
  // Points (k z, y, z) fall at sample column X = 64 - 48 k whatever their depth: k below
  // puts them on column 70's centre (70.5).
  const double k = (64.0 - 70.5) / 48.0;
  {
    SceneData s = camera_at_origin();
    begin_object(s, "triangle", add_material(s, Material{}), false);
    add_flat_triangle(s, {k, -0.2, 1}, {k, 0.2, 1}, {40.0, 0.0, 1});  // sample rows 19 to 28
    const std::vector<uint8_t> m = edge_tie_pixels(s);
    for (int y = 5; y <= 6; ++y) EXPECT_TRUE(marked(m, 70 / MASK_COLUMNS, y)) << "row " << y;
    EXPECT_FALSE(marked(m, 70 / MASK_COLUMNS - 1, 5));
    EXPECT_FALSE(marked(m, 70 / MASK_COLUMNS, 10));
  }
  {
    // From depth 1 to depth -1 (behind the eye): cut at the near depth, its visible part runs
    // from sample row 36 (y = -0.5 at depth 1) down off the image, on the same column.
    SceneData s = camera_at_origin();
    begin_object(s, "triangle", add_material(s, Material{}), false);
    add_flat_triangle(s, {k, -0.5, 1}, {-k, -0.5, -1}, {40.0, -0.5, 1});
    const std::vector<uint8_t> m = edge_tie_pixels(s);
    for (int y = 9; y <= 11; ++y) EXPECT_TRUE(marked(m, 70 / MASK_COLUMNS, y)) << "row " << y;
    for (int y = 0; y <= 8; ++y) EXPECT_FALSE(marked(m, 70 / MASK_COLUMNS, y)) << "row " << y;
  }
}

TEST(EdgeTies, TheTracersPixelMaskRendersOnlyThosePixelsAndThemAlike) {
  SceneData s = camera_at_origin();
  s.lights.push_back(PointLight{});
  s.lights.back().position = {0, 2, 0};
  s.ambient = dvec3(0.2);
  add_sphere(s, {0.2, 0.1, 3}, 1.0, 24, add_material(s, Material{}));
  add_ledge(s, 0.3125);
  RaytraceOptions all;
  all.threads = 2;
  const Image full = render_raytrace(s, all);
  std::vector<uint8_t> only = edge_tie_pixels(s);
  ASSERT_GT(std::count(only.begin(), only.end(), 1), 5);
  RaytraceOptions some = all;
  some.only = &only;
  const Image part = render_raytrace(s, some);
  for (size_t p = 0; p < only.size(); ++p) {
    for (size_t c = 0; c < 3; ++c) {
      const float expected = only[p] ? full.data[3 * p + c] : 0.f;
      ASSERT_EQ(part.data[3 * p + c], expected) << "pixel " << p;
    }
  }
}

}  // namespace
}  // namespace abcube
