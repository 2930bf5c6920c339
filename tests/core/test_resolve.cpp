// Known-answer tests of Pack_Under_Mask and the image resolve (resolve.hpp; thesis
// 5.2.1.1-5.2.1.2, figures 11.1-11.2): coverage weights, transparency, intersecting
// surfaces, antialiased edges, and determinism.
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "raster/abuffer.hpp"
#include "abuffer_testkit.hpp"
#include "shading/resolve.hpp"
#include "scene/scene_load.hpp"

namespace abcube {
namespace {

using glm::dvec3;
using namespace testkit;
using namespace abtest;

const dvec3 RED(1, 0, 0), GREEN(0, 1, 0), BLUE(0, 0, 1), GREY(0.5, 0.5, 0.5);

// Hand-made lists: fragment i is triangle i; `objects` gives each triangle's object.
struct HandList {
  std::vector<Fragment> fragments;
  TriangleSoup soup;
  std::vector<ShadedFragment> shades;

  void add(float zmin, float zmax, CoverageMask mask, uint32_t object, const dvec3& colour, double opacity = 1.0) {
    const uint32_t t = static_cast<uint32_t>(fragments.size());
    fragments.push_back({zmin, zmax, mask, t, 0});
    soup.object_id.push_back(object);
    soup.material_id.push_back(0);
    shades.push_back({colour, opacity});
  }
  FragmentList list() const { return {fragments.data(), fragments.data() + fragments.size()}; }
  dvec3 pack(CoverageMask search = FULL_MASK, const dvec3& background = GREY) const {
    const FragmentShader shade = [this](const Fragment& f) { return shades[f.triangle()]; };
    return pack_under_mask(list(), search, shade, soup, background);
  }
};

void expect_colour(const dvec3& got, const dvec3& want, double tol = 0.0) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], tol) << "channel " << c;
}

TEST(Resolve, NothingUnderTheMaskIsTheBackground) {
  HandList h;
  expect_colour(h.pack(), GREY);
  h.add(1, 2, 0x0000ffffu, 0, RED);
  expect_colour(h.pack(0xffff0000u), GREY);
  expect_colour(h.pack(0), GREY);
}

TEST(Resolve, CoverageIsWeightedByMaskArea) {
  HandList h;
  h.add(1, 2, 0x000000ffu, 0, RED);    // 8 samples
  h.add(3, 4, 0x0000ffffu, 1, GREEN);  // 8 more visible behind it
  h.add(5, 6, FULL_MASK, 2, BLUE);     // the remaining 16
  expect_colour(h.pack(), 0.25 * RED + 0.25 * GREEN + 0.5 * BLUE);
  expect_colour(h.pack(0x0000ff00u), GREEN);  // a search mask restricts the area
  HandList partial;
  partial.add(1, 2, 0x0f0f0f0fu, 0, RED);  // half of the pixel
  expect_colour(partial.pack(), 0.5 * RED + 0.5 * GREY);
}

TEST(Resolve, TransparentVeilBlendsWithWhatIsBehind) {
  HandList h;
  h.add(1, 1.5f, FULL_MASK, 0, RED, 0.25);
  h.add(3, 4, FULL_MASK, 1, BLUE);
  // thesis 5.2.1.1: C_in = Op_f C_f + (1 - Op_f) C_behind
  EXPECT_EQ(h.pack(), 0.25 * RED + 0.75 * BLUE);
  HandList half;
  half.add(1, 1.5f, 0x0000ffffu, 0, RED, 0.25);  // the veil covers half the pixel
  half.add(3, 4, FULL_MASK, 1, BLUE);
  EXPECT_EQ(half.pack(), 0.5 * (0.25 * RED + 0.75 * BLUE) + 0.5 * BLUE);
  HandList alone;
  alone.add(1, 1.5f, FULL_MASK, 0, RED, 0.25);  // nothing behind: the background shows
  EXPECT_EQ(alone.pack(), 0.25 * RED + 0.75 * GREY);
}

TEST(Resolve, IntersectingFragmentsShareTheInsideByTheVisibleFraction) {
  HandList h;
  h.add(1, 3, FULL_MASK, 0, RED);
  h.add(2, 4, FULL_MASK, 1, GREEN);
  // thesis 5.2.1.2: Vis = (4 - 1) / ((3 - 1) + (4 - 2)) = 0.75, alpha_in = Vis for opaque fragments
  EXPECT_EQ(h.pack(), 0.75 * RED + 0.25 * GREEN);
  HandList veil;  // a transparent front fragment: alpha = op (Vis + (1 - Vis)(1 - op_next))
  veil.add(1, 3, FULL_MASK, 0, RED, 0.5);
  veil.add(2, 4, FULL_MASK, 1, GREEN, 0.5);
  const double alpha = 0.5 * (0.75 + 0.25 * 0.5);
  expect_colour(veil.pack(), alpha * RED + (1 - alpha) * (0.5 * GREEN + 0.5 * GREY), 1e-15);
  HandList same;  // the same object overlapping in z is not an intersection
  same.add(1, 3, FULL_MASK, 0, RED);
  same.add(2, 4, FULL_MASK, 0, GREEN);
  EXPECT_EQ(same.pack(), RED);
  HandList apart;  // no overlap in z
  apart.add(1, 2, FULL_MASK, 0, RED);
  apart.add(2.5f, 4, FULL_MASK, 1, GREEN);
  EXPECT_EQ(apart.pack(), RED);
}

TEST(Resolve, EachFragmentIsShadedOnceAndLongListsNeedNoRecursion) {
  HandList h;
  const int layers = 200000;
  for (int i = 0; i < layers; ++i) {
    const CoverageMask m = (i % 3 == 0) ? FULL_MASK : (i % 3 == 1 ? 0x00ff00ffu : 0xff00ff00u);
    h.add(float(i), float(i) + 0.5f, m, static_cast<uint32_t>(i), i % 2 ? RED : BLUE, 0.5);
  }
  std::vector<int> calls(static_cast<size_t>(layers), 0);
  const FragmentShader shade = [&](const Fragment& f) {
    ++calls[f.triangle()];
    return h.shades[f.triangle()];
  };
  PackScratch scratch;
  const dvec3 c = pack_under_mask(h.list(), FULL_MASK, shade, h.soup, GREY, &scratch);
  EXPECT_TRUE(std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z));
  EXPECT_NEAR(c.x + c.y + c.z, 1.0, 1e-9);  // every colour here sums to 1
  int most = 0, shaded = 0;
  for (int n : calls) {
    most = std::max(most, n);
    shaded += n > 0;
  }
  EXPECT_EQ(most, 1);
  EXPECT_GT(shaded, 100);
}

// Material colour and opacity, no lighting: what the resolve tests shade with.
PixelShader material_shader(const SceneData& s) {
  return [&s](const Fragment& f, int, int) {
    const Material& m = s.materials[s.triangles->material_id[f.triangle()]];
    return ShadedFragment{m.color, m.opacity};
  };
}

TEST(Resolve, VeilOverAQuadInTheImage) {
  SceneData s = empty_scene({0, 0, 0}, {0, 0, -1}, 60, 16, 12);
  Material veil = emissive(RED);
  veil.opacity = 0.25;
  const uint32_t mv = add_material(s, veil), mb = add_material(s, emissive(BLUE));
  add_quad(s, {-1, -1, -2}, {1, -1, -2}, {1, 1, -2}, {-1, 1, -2}, mv);
  add_quad(s, {-9, -9, -5}, {9, -9, -5}, {9, 9, -5}, {-9, 9, -5}, mb);
  const ABuffer b = build_camera_abuffer(s, test_options(true));
  const Image img = resolve_image(b, *s.triangles, material_shader(s), GREY);
  const dvec3 want = 0.25 * RED + 0.75 * BLUE;
  for (int c = 0; c < 3; ++c) {
    EXPECT_FLOAT_EQ(img.at(8, 6)[c], static_cast<float>(want[c]));  // under the veil
    EXPECT_FLOAT_EQ(img.at(0, 0)[c], static_cast<float>(BLUE[c]));  // beside it
  }
}

// Two quads crossing along x = 0, mirror images of each other (planes z = -3 +- x/2): in
// the pixel column centred on x = 0 their z ranges coincide, so Vis = 1/2.
TEST(Resolve, IntersectingQuadsMeetHalfAndHalf) {
  SceneData s = empty_scene({0, 0, 0}, {0, 0, -1}, 40, 15, 9);
  const uint32_t mr = add_material(s, emissive(RED)), mg = add_material(s, emissive(GREEN));
  add_quad(s, {-1, -1, -3.5}, {1, -1, -2.5}, {1, 1, -2.5}, {-1, 1, -3.5}, mr);
  add_quad(s, {-1, -1, -2.5}, {1, -1, -3.5}, {1, 1, -3.5}, {-1, 1, -2.5}, mg);
  const ABuffer b = build_camera_abuffer(s, test_options(true));
  const Image img = resolve_image(b, *s.triangles, material_shader(s), GREY);
  for (int y = 2; y < 7; ++y) {
    ASSERT_EQ(b.list(7, y).size(), 2u);
    EXPECT_NEAR(img.at(7, y)[0], 0.5, 1e-5) << "row " << y;
    EXPECT_NEAR(img.at(7, y)[1], 0.5, 1e-5) << "row " << y;
    for (int x : {4, 10}) {  // away from the intersection: the nearer quad alone
      const float r = img.at(x, y)[0], g = img.at(x, y)[1];
      EXPECT_TRUE((r == 1.f && g == 0.f) || (r == 0.f && g == 1.f)) << x << ", " << y << ": " << r << " " << g;
    }
  }
  EXPECT_EQ(img.at(4, 4)[1], 1.f);  // left: green (z = -2.5 + ...) is nearer
  EXPECT_EQ(img.at(10, 4)[0], 1.f);
}

// Thesis figures 11.1-11.2: a white triangle on black; edge pixels take the covered share
// of their 32 samples, which follows the exact covered area.
TEST(Resolve, AntialiasedEdgesFollowTheCoveredArea) {
  SceneData s = empty_scene({0, 0, 0}, {0, 0, -1}, 50, 40, 32);
  const uint32_t m = add_material(s, emissive(dvec3(1.0)));
  begin_object(s, "triangle", m, false);
  const dvec3 a(-1.3, -0.9, -3), b(1.4, -0.5, -3), c(-0.2, 1.2, -3);
  add_flat_triangle(s, a, b, c);
  const ABuffer buf = build_camera_abuffer(s, test_options(true));
  const Image img = resolve_image(buf, *s.triangles, material_shader(s), dvec3(0.0));
  std::vector<glm::dvec2> tri;
  for (const dvec3& p : {a, b, c}) tri.push_back(buf.view.project(p));
  int edge = 0, intermediate = 0;
  double worst = 0, sum = 0;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const FragmentList l = buf.list(x, y);
      const double v = img.at(x, y)[0];
      EXPECT_EQ(v, l.empty() ? 0.0 : mask_count(l[0].mask) / 32.0) << x << ", " << y;
      const double area = pixel_area(tri, x, y);
      if (area <= 1e-9 || area >= 1 - 1e-9) {
        EXPECT_EQ(v, area > 0.5 ? 1.0 : 0.0) << x << ", " << y;
        continue;
      }
      ++edge;
      intermediate += v > 0 && v < 1;
      worst = std::max(worst, std::fabs(v - area));
      sum += std::fabs(v - area);
    }
  }
  EXPECT_GT(edge, 60);
  EXPECT_GT(intermediate, edge * 3 / 4);
  EXPECT_LT(worst, 0.2);
  EXPECT_LT(sum / edge, 0.05) << "mean |A-buffer - area| over " << edge << " edge pixels";
}

TEST(Resolve, ImageIdenticalForAnyThreadCount) {
  SceneData s = load_scene(std::string(ABCUBE_SOURCE_DIR) + "/scenes/default.json");
  s.camera.width = 64;
  s.camera.height = 48;
  const ABuffer b = build_camera_abuffer(s, test_options(true));
  const PixelShader shade = [&s](const Fragment& f, int x, int y) {
    const Material& m = s.materials[s.triangles->material_id[f.triangle()]];
    const double lambert = std::fabs(glm::dot(f.shading_normal(), glm::normalize(dvec3(1, 2, 3))));
    return ShadedFragment{m.color * lambert + 0.01 * dvec3(x % 3, y % 5, 0), m.opacity};
  };
  ResolveOptions one, three;
  one.threads = 1;
  three.threads = 3;
  const Image a = resolve_image(b, *s.triangles, shade, GREY, one);
  const Image c = resolve_image(b, *s.triangles, shade, GREY, three);
  ASSERT_EQ(a.data.size(), c.data.size());
  EXPECT_EQ(std::memcmp(a.data.data(), c.data.data(), a.data.size() * sizeof(float)), 0);
}

}  // namespace
}  // namespace abcube
