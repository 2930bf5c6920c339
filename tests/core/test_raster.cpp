// Known-answer tests of the rasterizer (raster.hpp): the view convention, watertight
// coverage (closed meshes around the centre, shared edges through samples), coverage
// against area, zmin/zmax against exact distances, and degenerate input.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "raster/abuffer.hpp"
#include "abuffer_testkit.hpp"
#include "scene/camera.hpp"
#include "raster/cube_map.hpp"
#include "raster/raster.hpp"

namespace abcube {
namespace {

using glm::dvec2;
using glm::dvec3;
using namespace testkit;
using namespace abtest;

TEST(Raster, ViewsFollowTheCubeAndCameraConventions) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const dvec3 centre(0.3, -1.0, 2.0);
  const int n = 64;
  int checked = 0;
  for (int i = 0; i < 2000; ++i) {
    const dvec3 r(u(rng), u(rng), u(rng));
    const CubeCoord c = direction_to_cube(r);
    const RasterView v = cube_face_view(c.face, centre, n, 1e-4);
    const dvec2 p = v.project(r);
    EXPECT_NEAR(p.x, n * c.s, 1e-9);
    EXPECT_NEAR(p.y, n * c.t, 1e-9);
    const dvec3 d = v.direction(p.x, p.y);
    EXPECT_NEAR(glm::length(glm::cross(glm::normalize(d), glm::normalize(r))), 0.0, 1e-12);
    EXPECT_GT(glm::dot(d, r), 0.0);
    ++checked;
  }
  Camera cam;
  cam.position = {1, 2, 3};
  cam.look_at = {0, 0.5, -1};
  cam.width = 40;
  cam.height = 30;
  const CameraFrame f = make_camera_frame(cam);
  const RasterView v = camera_view(f, 1e-4);
  for (double x : {0.0, 3.25, 39.9}) {
    for (double y : {0.0, 17.5, 29.9}) {
      const dvec2 p = v.project(f.direction(x, y));
      EXPECT_NEAR(p.x, x, 1e-9);
      EXPECT_NEAR(p.y, y, 1e-9);
      EXPECT_NEAR(glm::length(v.direction(x, y) - f.direction(x, y)), 0.0, 1e-12);
    }
  }
  EXPECT_EQ(checked, 2000);
}

// Star-shaped closed mesh around `c`: a sphere whose radius varies with direction (the same
// function of each shared vertex, so the mesh stays closed).
void add_bumpy_sphere(SceneData& s, const dvec3& c, int segments, uint32_t material) {
  const size_t first = s.triangles->positions.size();
  add_sphere(s, c, 1.0, segments, material);
  for (size_t i = first; i < s.triangles->positions.size(); ++i) {
    const dvec3 d = dvec3(s.triangles->positions[i]) - c;
    const double k = 1.5 + 0.6 * std::sin(3.0 * d.x + 1.0) * std::cos(2.0 * d.y) + 0.3 * d.z;
    s.triangles.edit().positions[i] = glm::vec3(c + k * d);
  }
}

// Every sample of every pixel is covered exactly once (the mesh encloses the centre).
void expect_each_sample_once(const ABuffer& b, const char* what) {
  int bad = 0;
  for (int y = 0; y < b.height(); ++y) {
    for (int x = 0; x < b.width(); ++x) {
      CoverageMask all = 0;
      for (const Fragment& f : b.list(x, y)) all |= f.mask;
      const auto counts = sample_cover_counts(b.list(x, y));
      const bool once = std::all_of(counts.begin(), counts.end(), [](int c) { return c == 1; });
      if ((all != FULL_MASK || !once) && bad++ < 5) {
        ADD_FAILURE() << what << " pixel (" << x << ", " << y << "): union " << std::hex << all << std::dec
                      << ", fragments " << b.list(x, y).size();
      }
    }
  }
  EXPECT_EQ(bad, 0) << what;
}

TEST(Raster, ClosedMeshesAroundTheCentreCoverEverySampleOnce) {
  SceneData s = empty_scene({0.05, 0.1, -0.02}, {0, 0, -1}, 90, 24, 20);
  const uint32_t m = add_material(s, Material{});
  add_box(s, {-1.0, -0.7, -1.3}, {1.4, 0.9, 0.8}, m);
  add_sphere(s, {0.1, -0.05, 0.07}, 3.0, 24, m);
  add_bumpy_sphere(s, s.camera.position, 40, m);  // star-shaped around the centre
  const dvec3 centre = s.camera.position;
  // Each closed surface alone: one layer per sample, whatever the face and the clipping.
  for (uint32_t object = 0; object < 3; ++object) {
    SceneData one = s;
    one.triangles = SharedTriangles{};
    for (size_t t = 0; t < s.triangles->triangle_count(); ++t) {
      if (s.triangles->object_id[t] != object) continue;
      for (size_t k = 0; k < 3; ++k) {
        one.triangles.edit().positions.push_back(s.triangles->positions[3 * t + k]);
        one.triangles.edit().normals.push_back(s.triangles->normals[3 * t + k]);
      }
      one.triangles.edit().object_id.push_back(object);
      one.triangles.edit().material_id.push_back(m);
    }
    for (bool merge : {false, true}) {
      ABufferStats st;
      const CubeABuffer cube = build_cube_abuffer(one, centre, 24, test_options(merge), &st);
      for (const ABuffer* b : rasters(cube)) expect_each_sample_once(*b, merge ? "merged" : "raw");
      expect_each_sample_once(build_camera_abuffer(one, test_options(merge)), "camera");
      if (object == 0) EXPECT_GT(st.triangles_clipped, 0u);  // box triangles span several faces
      if (merge && object == 0) EXPECT_LT(st.fragments, st.raw_fragments);
    }
  }
}

// The cube build skips, for each triangle, the faces cube_faces_of leaves out: none of those
// may hold a covered sample. Seeded triangles of every size, many of them with corners on or
// a hair from the seams between faces (|s| = 1) and at the cube's corners, rasterised on
// all six faces without the skip.
TEST(Raster, FacesLeftOutOfATriangleCoverNoneOfItsSamples) {
  std::mt19937 rng(20261128);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const dvec3 centre(0.25, -0.5, 1.5);
  const int n = 16;
  SceneData s = empty_scene(centre, {0, 0, -1}, 90, 8, 8);
  begin_object(s, "triangles", add_material(s, Material{}), false);
  for (int k = 0; k < 3000; ++k) {
    // A corner on a seam or a cube corner, nudged by 0 or a few ulps, then two more nearby.
    const int face = k % CUBE_FACES;
    const CubeFaceBasis& b = cube_face_basis(face);
    const double a = k % 3 == 0 ? 1.0 : (k % 3 == 1 ? u(rng) : 1.0 - 1e-15 * (k % 7));
    const double c = k % 5 == 0 ? 1.0 : u(rng);
    const dvec3 corner = b.forward + a * b.s_axis + c * b.t_axis;
    const double size = std::pow(10.0, -3.0 + 3.0 * (0.5 + 0.5 * u(rng)));
    const double far = 0.5 + 5.0 * (0.5 + 0.5 * u(rng));
    const dvec3 p0 = centre + far * corner;
    const dvec3 p1 = p0 + size * dvec3(u(rng), u(rng), u(rng));
    const dvec3 p2 = p0 + size * dvec3(u(rng), u(rng), u(rng));
    add_flat_triangle(s, p0, p1, p2);
  }
  const TriangleSoup& soup = *s.triangles;
  int single = 0;
  for (uint32_t t = 0; t < soup.triangle_count(); ++t) {
    const uint8_t faces = cube_faces_of(centre, soup, t);
    single += (faces & (faces - 1)) == 0 ? 1 : 0;
    for (int f = 0; f < CUBE_FACES; ++f) {
      if ((faces >> f) & 1) continue;
      TriangleSetup setup;
      if (setup_triangle(cube_face_view(f, centre, n, 1e-3), soup, t, &setup) != SetupResult::visible) continue;
      int covered = 0;
      rasterize_rows(setup, 0, n, [&](int, int, CoverageMask mask) { covered += mask != 0; });
      EXPECT_EQ(covered, 0) << "triangle " << t << " face " << f;
    }
  }
  EXPECT_GT(single, 1000);  // the skip is exercised: most of them lie in one face
}

// A grid of triangles on face +Z whose vertices sit exactly on sample positions, so edges
// run through samples (ties). Winding alternates; each sample strictly inside the grid
// must be covered exactly once, samples outside never.
TEST(Raster, SharedEdgesThroughSamplesCoverEachSampleOnce) {
  const int n = 8;
  const RasterView v = cube_face_view(POS_Z, dvec3(0.0), n, 1e-4);
  // Pixel point (x, y) of face +Z at distance 1: direction (x/4 - 1, 1 - y/4, 1), exact.
  const auto at = [&](double x, double y) { return v.direction(x, y); };
  SceneData s = empty_scene({0, 0, 0}, {0, 0, 1}, 60, 8, 8);
  const uint32_t m = add_material(s, Material{});
  begin_object(s, "grid", m, false);
  const double x0 = 1 + 1.0 / 16, y0 = 1 + 1.0 / 8, step_x = 5.0 / 8, step_y = 3.0 / 4;
  const int cells = 8;
  for (int i = 0; i < cells; ++i) {
    for (int j = 0; j < cells; ++j) {
      const dvec3 a = at(x0 + i * step_x, y0 + j * step_y), b = at(x0 + (i + 1) * step_x, y0 + j * step_y);
      const dvec3 c = at(x0 + (i + 1) * step_x, y0 + (j + 1) * step_y), d = at(x0 + i * step_x, y0 + (j + 1) * step_y);
      const bool flip = (i + j) % 2 == 1;
      if ((i * 7 + j * 3) % 2 == 0) {  // diagonal a-c
        add_flat_triangle(s, a, flip ? c : b, flip ? b : c);
        add_flat_triangle(s, a, c, d);
      } else {  // diagonal b-d
        add_flat_triangle(s, a, b, d);
        add_flat_triangle(s, b, flip ? d : c, flip ? c : d);
      }
    }
  }
  const CubeABuffer cube = build_cube_abuffer(s, dvec3(0.0), n, test_options());
  const double x_end = x0 + cells * step_x, y_end = y0 + cells * step_y;
  int inside = 0, on_grid_lines = 0;
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const auto counts = sample_cover_counts(cube.faces[POS_Z].list(x, y));
      for (int k = 0; k < MASK_SAMPLES; ++k) {
        const double sx = x + sample_dx(k), sy = y + sample_dy(k);
        const bool in = sx > x0 && sx < x_end && sy > y0 && sy < y_end;
        const bool out = sx < x0 || sx > x_end || sy < y0 || sy > y_end;
        const int c = counts[static_cast<size_t>(k)];
        if (in) EXPECT_EQ(c, 1) << "sample " << sx << ", " << sy;
        if (out) EXPECT_EQ(c, 0) << "sample " << sx << ", " << sy;
        EXPECT_LE(c, 1) << "sample " << sx << ", " << sy;
        inside += in;
        on_grid_lines += in && (std::fmod(sx - x0, step_x) == 0.0 || std::fmod(sy - y0, step_y) == 0.0);
      }
    }
  }
  EXPECT_GT(inside, 800);
  EXPECT_GT(on_grid_lines, 100);  // the ties really happen
}

// The shortcuts (row spans, trivial accept and reject) give exactly the per-sample rule.
TEST(Raster, PixelMasksFollowThePerSampleRuleExactly) {
  std::mt19937 rng(19);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  SceneData s = empty_scene({0, 0, 0}, {0, 0, -1}, 60, 8, 8);
  add_material(s, Material{});
  begin_object(s, "random", 0, false);
  for (int t = 0; t < 60; ++t)
    add_flat_triangle(s, {u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)});
  int partial = 0, full = 0;
  for (int face = 0; face < CUBE_FACES; ++face) {
    const RasterView v = cube_face_view(face, dvec3(0.05, -0.1, 0.02), 20, 0.3);
    for (uint32_t t = 0; t < s.triangles->triangle_count(); ++t) {
      TriangleSetup st;
      if (setup_triangle(v, *s.triangles, t, &st) != SetupResult::visible) continue;
      for (int y = 0; y < v.height; ++y) {
        int xb = 0, xe = 0;
        row_span(st, y, &xb, &xe);
        for (int x = 0; x < v.width; ++x) {
          CoverageMask expect = 0;
          for (int k = 0; k < MASK_SAMPLES; ++k) {
            bool in = true;
            for (int e = 0; e < st.edge_count; ++e) {
              const dvec3& c = st.edge[static_cast<size_t>(e)];
              const double val = c.x * (x + sample_dx(k)) + (c.y * (y + sample_dy(k)) + c.z);
              in = in && (val > 0 || (val == 0 && st.owns_ties[static_cast<size_t>(e)]));
            }
            expect |= CoverageMask(in) << k;
          }
          const bool in_span = y >= st.y0 && y < st.y1 && x >= xb && x < xe;
          ASSERT_EQ(in_span ? pixel_mask(st, x, y) : 0u, expect)
              << "face " << face << " triangle " << t << " pixel " << x << ", " << y;
          partial += expect != 0 && expect != FULL_MASK;
          full += expect == FULL_MASK;
        }
      }
    }
  }
  EXPECT_GT(partial, 500);
  EXPECT_GT(full, 500);
}

TEST(Raster, OneTriangleCoverageMatchesItsProjectedArea) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.7, 0.7), z(2.0, 6.0);
  SceneData base = empty_scene({0, 0, 0}, {0, 0, -1}, 70, 48, 40);
  const uint32_t m = add_material(base, Material{});
  for (int trial = 0; trial < 12; ++trial) {
    SceneData s = base;
    begin_object(s, "triangle", m, false);
    std::array<dvec3, 3> p;
    for (dvec3& q : p) q = dvec3(u(rng), u(rng), -1.0) * z(rng);
    add_flat_triangle(s, p[0], p[1], p[2]);
    const ABuffer b = build_camera_abuffer(s, test_options());
    std::vector<dvec2> tri;
    for (const dvec3& q : p) tri.push_back(b.view.project(q - b.view.centre));
    double covered = 0, area = 0;
    int edge_pixels = 0;
    for (int y = 0; y < b.height(); ++y) {
      for (int x = 0; x < b.width(); ++x) {
        const double a = pixel_area(tri, x, y);
        const FragmentList l = b.list(x, y);
        ASSERT_LE(l.size(), 1u);
        const int bits = l.empty() ? 0 : mask_count(l[0].mask);
        if (a >= 1.0 - 1e-12) EXPECT_EQ(bits, MASK_SAMPLES) << x << ", " << y;
        if (a <= 1e-12) EXPECT_EQ(bits, 0) << x << ", " << y;
        edge_pixels += a > 1e-12 && a < 1.0 - 1e-12;
        covered += bits / double(MASK_SAMPLES);
        area += a;
      }
    }
    EXPECT_GT(area, 1.0);
    EXPECT_NEAR(covered, area, 0.5 * edge_pixels) << "trial " << trial;
    EXPECT_NEAR(covered, area, 0.05 * edge_pixels) << "trial " << trial;  // what 4x8 really achieves
  }
}

// zmin/zmax of a plane at distance 2 in front of face +Z: the texel's square on the plane
// gives them in closed form; and for random triangles they bracket the exact distance at
// every covered texel centre (what the GPU prepass stores).
TEST(Raster, DistanceRangeIsTheClippedPolygonsRange) {
  SceneData s = empty_scene({0, 0, 0}, {0, 0, 1}, 60, 8, 8);
  const uint32_t m = add_material(s, Material{});
  add_quad(s, {-5, -5, 2}, {5, -5, 2}, {5, 5, 2}, {-5, 5, 2}, m);
  const int n = 15;  // odd: the foot is inside texel (7, 7), so nearest points lie on texel edges
  const CubeABuffer cube = build_cube_abuffer(s, dvec3(0.0), n, test_options());
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      // Texel (x, y): plane points (2(2s - 1), -2(2t - 1), 2), s in [x/n, (x+1)/n].
      const double xa = 2 * (2.0 * x / n - 1), xb = 2 * (2.0 * (x + 1) / n - 1);
      const double ya = -2 * (2.0 * y / n - 1), yb = -2 * (2.0 * (y + 1) / n - 1);
      const double cx = std::clamp(0.0, std::min(xa, xb), std::max(xa, xb));
      const double cy = std::clamp(0.0, std::min(ya, yb), std::max(ya, yb));
      const double fx = std::max(std::fabs(xa), std::fabs(xb)), fy = std::max(std::fabs(ya), std::fabs(yb));
      const FragmentList l = cube.faces[POS_Z].list(x, y);
      CoverageMask all = 0;
      float zmin = HUGE_VALF, zmax = 0;
      for (const Fragment& f : l) {
        all |= f.mask;
        zmin = std::min(zmin, f.zmin);
        zmax = std::max(zmax, f.zmax);
      }
      ASSERT_EQ(all, FULL_MASK);
      EXPECT_NEAR(zmin, std::sqrt(cx * cx + cy * cy + 4.0), 1e-6) << x << ", " << y;
      EXPECT_NEAR(zmax, std::sqrt(fx * fx + fy * fy + 4.0), 1e-6) << x << ", " << y;
    }
  }
  EXPECT_EQ(cube.faces[POS_Z].list(n / 2, n / 2)[0].zmin, 2.0f);  // the foot of the perpendicular

  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  SceneData r = empty_scene({0, 0, 0}, {0, 0, 1}, 60, 8, 8);
  add_material(r, Material{});
  begin_object(r, "random", 0, false);
  for (int t = 0; t < 40; ++t)
    add_flat_triangle(r, {u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)});
  const CubeABuffer rc = build_cube_abuffer(r, dvec3(0.1, 0.0, -0.1), 24, test_options());
  int checked = 0;
  for (const ABuffer* b : rasters(rc)) {
    for (int y = 0; y < 24; ++y) {
      for (int x = 0; x < 24; ++x) {
        const dvec3 d = b->view.direction(x + 0.5, y + 0.5);
        for (const Fragment& f : b->list(x, y)) {
          const size_t t = f.triangle();
          const dvec3 a = dvec3(r.triangles->positions[3 * t]) - rc.centre;
          const dvec3 e1 = dvec3(r.triangles->positions[3 * t + 1]) - rc.centre - a;
          const dvec3 e2 = dvec3(r.triangles->positions[3 * t + 2]) - rc.centre - a;
          // Moller-Trumbore from the centre along d: is the texel centre on the triangle?
          const dvec3 pv = glm::cross(d, e2);
          const double det = glm::dot(e1, pv);
          const dvec3 tv = -a;
          const double bu = glm::dot(tv, pv) / det;
          const dvec3 qv = glm::cross(tv, e1);
          const double bv = glm::dot(d, qv) / det, tt = glm::dot(e2, qv) / det;
          if (bu < 1e-9 || bv < 1e-9 || bu + bv > 1 - 1e-9 || tt <= 0) continue;
          if (glm::dot(b->view.row_w, tt * d) < rc.near_distance) continue;
          const double dist = tt * glm::length(d);
          EXPECT_LE(f.zmin, dist * (1 + 1e-12));
          EXPECT_GE(f.zmax, dist * (1 - 1e-12));
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 300);
}

// A triangle cut by a (deliberately large) near plane: a sample is covered iff its ray
// meets the triangle at w >= near.
TEST(Raster, NearPlaneCutsTheTriangleWhereItIsNearer) {
  SceneData s = empty_scene({0, 0, 0}, {0, 0, 1}, 60, 8, 8);
  add_material(s, Material{});
  begin_object(s, "slanted", 0, false);
  // Plane y = z/2 - 0.1, passing 0.09 from the centre: its part with w = z < 0.5 is on face +Z.
  const dvec3 a(-3, -0.05, 0.1), b(3, -0.05, 0.1), c(0, 1.4, 3);
  add_flat_triangle(s, a, b, c);
  ABufferOptions o = test_options();
  o.near_distance = 0.5;
  ABufferStats st;
  const int n = 32;
  const CubeABuffer cube = build_cube_abuffer(s, dvec3(0.0), n, o, &st);
  EXPECT_GT(st.triangles_clipped, 0u);
  const ABuffer& face = cube.faces[POS_Z];
  int covered = 0, cut = 0;
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const FragmentList l = face.list(x, y);
      ASSERT_LE(l.size(), 1u);
      for (int k = 0; k < MASK_SAMPLES; ++k) {
        const dvec3 d = face.view.direction(x + sample_dx(k), y + sample_dy(k));
        // Ray-plane hit and whether it is inside the triangle (2D test in the plane's x, z-y).
        const dvec3 nrm = glm::cross(b - a, c - a);
        const dvec3 p = (glm::dot(nrm, a) / glm::dot(nrm, d)) * d;
        const double e0 = glm::dot(glm::cross(b - a, p - a), nrm), e1 = glm::dot(glm::cross(c - b, p - b), nrm),
                     e2 = glm::dot(glm::cross(a - c, p - c), nrm);
        const bool on = e0 > 0 && e1 > 0 && e2 > 0;
        const bool bit = !l.empty() && ((l[0].mask >> k) & 1u);
        if (!on || std::fabs(p.z - 0.5) < 1e-9) continue;
        EXPECT_EQ(bit, p.z >= 0.5) << "sample at w = " << p.z;
        covered += bit;
        cut += !bit;
      }
      if (!l.empty()) EXPECT_GE(l[0].zmin, 0.5f);
    }
  }
  EXPECT_GT(covered, 1000);
  EXPECT_GT(cut, 1000);
}

TEST(Raster, NormalIsPerspectiveCorrectAtTheCoveredCentroid) {
  SceneData s = empty_scene({0, 0, 0}, {0, 0, -1}, 60, 16, 16);
  add_material(s, Material{});
  begin_object(s, "tilted", 0, false);
  const dvec3 a(-2, -2, -2), b(3, -2, -8), c(-2, 3, -3);
  const dvec3 na = glm::normalize(dvec3(1, 0, 1)), nb = glm::normalize(dvec3(0, 1, 1)),
              nc = glm::normalize(dvec3(-1, -1, 2));
  add_triangle(s, a, b, c, na, nb, nc);
  const ABuffer buf = build_camera_abuffer(s, test_options());
  int checked = 0;
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) {
      for (const Fragment& f : buf.list(x, y)) {
        const dvec3 p = fragment_point(buf, *s.triangles, f, x, y);
        // Barycentrics of p in 3D: the perspective-correct weights.
        const dvec3 n = glm::cross(b - a, c - a);
        const double wa = glm::dot(glm::cross(c - b, p - b), n) / glm::dot(n, n);
        const double wb = glm::dot(glm::cross(a - c, p - c), n) / glm::dot(n, n);
        const dvec3 expect = glm::normalize(wa * na + wb * nb + (1 - wa - wb) * nc);
        EXPECT_NEAR(glm::length(f.shading_normal() - expect), 0.0, 2e-4) << x << ", " << y;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 50);
}

TEST(Raster, OctahedralNormalsRoundTrip) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  double worst = 0;
  for (int i = 0; i < 5000; ++i) {
    const dvec3 n = glm::normalize(dvec3(g(rng), g(rng), g(rng)));
    worst = std::max(worst, glm::length(decode_octahedral(encode_octahedral(n)) - n));
  }
  for (const dvec3& n : {dvec3(0, 0, 1), dvec3(0, 0, -1), dvec3(1, 0, 0), dvec3(0, -1, 0)}) {
    EXPECT_NEAR(glm::length(decode_octahedral(encode_octahedral(n)) - n), 0.0, 1e-4);
  }
  EXPECT_LT(worst, 1e-4);
}

TEST(Raster, DegenerateTrianglesAreCountedNotRasterised) {
  SceneData s = empty_scene({0, 0, 0}, {0, 0, -1}, 60, 16, 16);
  add_material(s, Material{});
  begin_object(s, "junk", 0, false);
  const double nan = std::nan("");
  add_flat_triangle(s, {0, 0, -1}, {1, 0, -1}, {0, 1, -1});                                // fine
  add_triangle(s, {nan, 0, -1}, {1, 0, -1}, {0, 1, -1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1});  // NaN
  add_triangle(s, {0, 0, -1}, {1, 1, -1}, {2, 2, -1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1});    // collinear
  add_triangle(s, {1, 1, -1}, {1, 1, -1}, {1, 1, -1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1});    // a point
  add_flat_triangle(s, {0, -1, -1}, {0, 1, -1}, {0, 0, -5});                               // plane x = 0: edge-on
  add_flat_triangle(s, {-3e37, -3e37, -1e37}, {3e37, -3e37, -1e37}, {0, 3e37, -1e37});     // enormous
  add_flat_triangle(s, {-1e-6, 0, 1e-6}, {1e-6, 0, 1e-6}, {0, 1e-6, 1e-6});                // inside the near distance
  add_flat_triangle(s, {-1e4, -1e4, 5}, {1e4, -1e4, 5}, {0, 1e4, 5});                      // behind the camera
  ABufferOptions o = test_options();
  o.near_distance = 1e-3;
  ABufferStats st;
  const CubeABuffer cube = build_cube_abuffer(s, dvec3(0.0), 16, o, &st);
  EXPECT_EQ(st.triangles_degenerate, 3u);
  EXPECT_EQ(st.triangles_edge_on, 1u);
  EXPECT_EQ(st.triangles_culled, 1u);  // the one inside the near distance
  for (const ABuffer* b : rasters(cube)) {
    for (const Fragment& f : b->fragments) {
      EXPECT_TRUE(std::isfinite(f.zmin) && std::isfinite(f.zmax)) << f.triangle();
      EXPECT_LE(f.zmin, f.zmax);
      EXPECT_NE(f.triangle(), 1u);
      EXPECT_NE(f.triangle(), 4u);
    }
  }
  ABufferStats cs;
  const ABuffer cam = build_camera_abuffer(s, o, &cs);
  EXPECT_EQ(cs.triangles_culled, 2u);  // also the one behind the camera
  EXPECT_GT(cs.fragments, 0u);
}

}  // namespace
}  // namespace abcube
