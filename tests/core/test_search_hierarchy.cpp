// The searches' HIERARCHICAL SKIP (search_scan.hpp) gives the plain walk's answers bit for
// bit: CubeWalk::square_exit against the full walk on random and degenerate rays, then the
// searches and whole renders with SearchOptions::hierarchy on and off on the repository
// scenes, the kept hard-case regressions and seeded scenes of tools/hard_scenes.py.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <algorithm>
#include <filesystem>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "raster/abuffer.hpp"
#include "reference/raytrace.hpp"
#include "scene/camera.hpp"
#include "scene/scene_load.hpp"
#include "search/cube_walk.hpp"
#include "search/search.hpp"
#include "shading/map_shading.hpp"

namespace abcube {
namespace {

namespace fs = std::filesystem;
constexpr double INF = std::numeric_limits<double>::infinity();

// ---- The walk ------------------------------------------------------------------------

struct WalkRay {
  glm::dvec3 w, d;
  double l_max = INF, skip = 0.0;
};

std::string describe(const WalkRay& r, int n) {
  char s[400];
  std::snprintf(s, sizeof s, "n=%d W=(%.17g,%.17g,%.17g) D=(%.17g,%.17g,%.17g) l_max=%.17g skip=%.17g", n, r.w.x, r.w.y,
                r.w.z, r.d.x, r.d.y, r.d.z, r.l_max, r.skip);
  return s;
}

// Random rays and the walk's degenerate ones (test_cube_walk.cpp): through texel corners,
// along seams and cube edges, D = +-[[W]], near the centre, from the centre, segments.
std::vector<WalkRay> walk_rays(int n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.0, 1.0);
  const auto unit = [&] {
    for (;;) {
      const glm::dvec3 v(u(rng), u(rng), u(rng));
      if (glm::length(v) > 0.1 && glm::length(v) <= 1.0) return glm::normalize(v);
    }
  };
  std::vector<WalkRay> rays;
  for (int k = 0; k < 300; ++k) {
    WalkRay r{unit() * (0.1 + 5.0 * pos(rng)), unit()};
    if (k % 3 == 1) r.l_max = 10.0 * pos(rng);
    if (k % 5 == 2) r.skip = 0.5 * glm::length(r.w) * pos(rng);
    rays.push_back(r);
  }
  // Texel corners of the +z face: W and W + D through grid points (diagonal steps, ties).
  for (int k = 0; k < 60; ++k) {
    const auto corner = [&] {
      const double s = 2.0 * std::floor(pos(rng) * n) / n - 1.0, t = 2.0 * std::floor(pos(rng) * n) / n - 1.0;
      return glm::dvec3(s, t, 1.0);
    };
    const glm::dvec3 a = corner() * (1.0 + 3.0 * pos(rng)), b = corner() * (1.0 + 3.0 * pos(rng));
    if (glm::length(b - a) > 0.0) rays.push_back({a, glm::normalize(b - a)});
  }
  // Along seams and cube edges, and in their planes.
  for (int k = 0; k < 40; ++k) {
    const double a = 1.0 + pos(rng);
    rays.push_back({glm::dvec3(a, a, u(rng)), glm::normalize(glm::dvec3(u(rng) * 0.01, u(rng) * 0.01, 1.0))});
    rays.push_back({glm::dvec3(a, a * u(rng), a), glm::normalize(glm::dvec3(1.0, u(rng), 1.0))});
  }
  // D = +-[[W]], rays passing within 1e-12 .. 1e-2 of the centre, a ray from the centre.
  for (int k = 0; k < 40; ++k) {
    const glm::dvec3 w = unit() * (0.5 + 3.0 * pos(rng));
    rays.push_back({w, glm::normalize(w)});
    rays.push_back({w, -glm::normalize(w)});
    const glm::dvec3 side = glm::normalize(glm::cross(w, unit()));
    rays.push_back({w, glm::normalize(-glm::normalize(w) + std::pow(10.0, -12.0 + 10.0 * pos(rng)) * side)});
  }
  rays.push_back({glm::dvec3(0.0), unit()});
  return rays;
}

struct WalkTotals {
  long jumps = 0, refused = 0, texels = 0;
};

bool same(const WalkTexel& a, const WalkTexel& b) {
  return a.face == b.face && a.i == b.i && a.j == b.j && a.l0 == b.l0 && a.l1 == b.l1 && a.after_gap == b.after_gap;
}

// Walks `r` jumping over random squares holding the pending texel; every texel reported
// must be the full walk's next one, and the full walk's texels jumped over must lie in the
// square, before the exit.
void check_jumps(const WalkRay& r, int n, std::mt19937_64& rng, WalkTotals* totals) {
  std::vector<WalkTexel> full;
  CubeWalk plain(r.w, r.d, n, r.l_max, r.skip);
  for (WalkTexel t; plain.next(&t);) full.push_back(t);
  totals->texels += static_cast<long>(full.size());
  CubeWalk walk(r.w, r.d, n, r.l_max, r.skip);
  int max_log = 0;
  while ((1 << max_log) < n) ++max_log;
  std::uniform_int_distribution<int> log_size(0, max_log), coin(0, 3);
  size_t p = 0;
  for (WalkTexel pend; walk.pending(&pend);) {
    if (pend.l1 > pend.l0) {
      ASSERT_LT(p, full.size()) << describe(r, n);
      ASSERT_TRUE(pend.face == full[p].face && pend.i == full[p].i && pend.j == full[p].j && pend.l0 == full[p].l0)
          << describe(r, n) << " pending texel " << p;
    }
    const int size = 1 << log_size(rng);
    const int i0 = pend.i / size * size, j0 = pend.j / size * size;
    CubeWalk::SquareExit e;
    if (coin(rng) != 0) {
      if (walk.square_exit(i0, j0, size, &e)) {
        ++totals->jumps;
        ASSERT_EQ(walk.square_end(i0, j0, size), e.l_end) << describe(r, n);
        const auto in_square = [&](const WalkTexel& t) {
          return t.face == pend.face && t.i >= i0 && t.i < i0 + size && t.j >= j0 && t.j < j0 + size;
        };
        for (size_t q = p; p < full.size() && in_square(full[p]) && !(p > q && full[p].after_gap); ++p) {
          ASSERT_GE(full[p].l0, pend.l0) << describe(r, n);
          ASSERT_LE(full[p].l1, e.l_end) << describe(r, n) << " texel " << p << " past the square's exit";
        }
        walk.jump(e);
        continue;
      }
      ++totals->refused;
    }
    WalkTexel t;
    if (!walk.next(&t)) break;
    ASSERT_LT(p, full.size()) << describe(r, n) << " a texel past the full walk";
    ASSERT_TRUE(same(t, full[p])) << describe(r, n) << " texel " << p << ": (" << t.face << " " << t.i << " " << t.j
                                  << " " << t.l0 << " " << t.l1 << ") vs (" << full[p].face << " " << full[p].i << " "
                                  << full[p].j << " " << full[p].l0 << " " << full[p].l1 << ")";
    ++p;
  }
  EXPECT_EQ(p, full.size()) << describe(r, n) << " the jumping walk ended early";
  EXPECT_EQ(walk.aborted(), plain.aborted()) << describe(r, n);
}

TEST(SearchHierarchy, SquareExitIsWhereTheFullWalkLeaves) {
  std::mt19937_64 rng(14);
  WalkTotals totals;
  for (const int n : {1, 7, 8, 16, 100, 512, 2048}) {
    for (const WalkRay& r : walk_rays(n, rng)) {
      check_jumps(r, n, rng, &totals);
      if (::testing::Test::HasFatalFailure()) return;
    }
  }
  std::printf("square exits: %ld jumps, %ld refused, over walks of %ld texels\n", totals.jumps, totals.refused,
              totals.texels);
  EXPECT_GT(totals.jumps, 10000);
  // Refused only where the proof fails (crossings within the roundings' bound): rare.
  EXPECT_LT(totals.refused * 50, totals.jumps);
}

// A lowered cap counts steps: no jumps then.
TEST(SearchHierarchy, NoJumpUnderALoweredCap) {
  CubeWalk walk(glm::dvec3(1.0, 0.2, 0.3), glm::normalize(glm::dvec3(-0.3, 1.0, 0.2)), 64, INF, 0.0, 40);
  WalkTexel t;
  ASSERT_TRUE(walk.pending(&t));
  CubeWalk::SquareExit e;
  EXPECT_FALSE(walk.can_jump());
  EXPECT_FALSE(walk.square_exit(t.i / 8 * 8, t.j / 8 * 8, 8, &e));
}

// ---- The pyramid -----------------------------------------------------------------------

TEST(SearchHierarchy, PyramidNodesBoundTheirFragments) {
  const SceneData scene = load_scene(std::string(ABCUBE_SOURCE_DIR) + "/scenes/cornell.json");
  for (const int n : {20, 64}) {
    const CubeABuffer cube = build_cube_abuffer(scene, scene.camera.position, n);
    const SearchContext ctx(scene, cube);
    int levels = 0;
    while ((SearchContext::BOUNDS_BLOCK << levels) < n) ++levels;
    ASSERT_EQ(ctx.pyramid_levels(), levels + 1);
    for (int face = 0; face < CUBE_FACES; ++face) {
      for (int k = 0; k < ctx.pyramid_levels(); ++k) {
        const int size = SearchContext::BOUNDS_BLOCK << k;
        for (int j0 = 0; j0 < n; j0 += size) {
          for (int i0 = 0; i0 < n; i0 += size) {
            float lo = INFINITY, hi = -INFINITY;
            for (int j = j0; j < std::min(j0 + size, n); ++j) {
              for (int i = i0; i < std::min(i0 + size, n); ++i) {
                for (const Fragment& f : cube.faces[static_cast<size_t>(face)].list(i, j)) {
                  lo = std::min(lo, f.zmin);
                  hi = std::max(hi, f.zmax);
                }
                const glm::vec2 z = ctx.node_bounds(face, k, i, j);
                ASSERT_EQ(z, ctx.node_bounds(face, k, i0, j0));  // one node for the square
              }
            }
            EXPECT_EQ(ctx.node_bounds(face, k, i0, j0), glm::vec2(lo, hi))
                << face << " " << k << " " << i0 << " " << j0;
          }
        }
      }
    }
    EXPECT_GT(ctx.pyramid_bytes(), 0u);
    // Levels of 2 x 2: a third of the block level when its width is a power of 2 (n = 64:
    // 16 + 4 + 1 nodes over 64 blocks), a little more otherwise.
    EXPECT_LT(ctx.pyramid_bytes(), ctx.block_bounds_bytes());
    if (n == 64) EXPECT_EQ(ctx.pyramid_bytes() * 64, ctx.block_bounds_bytes() * 21);
  }
}

// ---- The searches ---------------------------------------------------------------------

struct Tally {
  long searches = 0, differ = 0;
  uint64_t texels_plain = 0, texels_hier = 0, nodes = 0;
  template <class Result>
  void add(const Result& plain, const Result& hier, const std::string& what) {
    ++searches;
    texels_plain += plain.texels_visited;
    texels_hier += hier.texels_visited;
    nodes += hier.nodes_skipped;
    EXPECT_EQ(plain.nodes_skipped, 0u);
    EXPECT_LE(hier.texels_visited, plain.texels_visited) << what;
    if (!same_answer(plain, hier)) {
      ++differ;
      ADD_FAILURE() << what << ": the hierarchical walk's answer differs from the plain walk's";
    }
  }
};

std::string ray_text(const char* kind, const glm::dvec3& w, const glm::dvec3& d) {
  char s[300];
  std::snprintf(s, sizeof s, "%s W=(%.17g,%.17g,%.17g) D=(%.17g,%.17g,%.17g)", kind, w.x, w.y, w.z, d.x, d.y, d.z);
  return s;
}

// Reflection, refraction exit and shadow searches from camera-visible points (every
// surface, whatever its material, mirrored about its normal and bent into it) and random
// rays and segments across the scene, each with the hierarchy on and off.
void compare_searches(const SceneData& scene, const SearchContext& ctx, const RayTracer& tracer, SearchOptions o,
                      int rays, unsigned seed, Tally* tally, const std::string& name) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.0, 1.0);
  SearchOptions off = o;
  off.hierarchy = false;
  o.hierarchy = true;
  const CameraFrame frame = make_camera_frame(scene.camera);
  const glm::dvec3 c = ctx.cube().centre;
  double reach = 0;  // the farthest vertex from the centre
  for (const glm::vec3& v : scene.triangles->positions) reach = std::max(reach, glm::length(glm::dvec3(v) - c));
  const auto unit = [&] {
    for (;;) {
      const glm::dvec3 v(u(rng), u(rng), u(rng));
      if (glm::length(v) > 0.1 && glm::length(v) <= 1.0) return glm::normalize(v);
    }
  };
  for (int k = 0; k < rays; ++k) {
    const glm::dvec3 dir = glm::normalize(frame.direction(pos(rng) * frame.width, pos(rng) * frame.height));
    Hit h;
    if (tracer.intersect(frame.eye, dir, &h)) {
      const glm::dvec3 n = h.geometric_normal;
      const glm::dvec3 r = glm::normalize(dir - 2.0 * glm::dot(dir, n) * n);
      const std::string where = name + " " + ray_text("reflection", h.point, r);
      tally->add(reflection_search(ctx, h.point, r, off), reflection_search(ctx, h.point, r, o), where);
      const glm::dvec3 in = glm::normalize(glm::dot(dir, n) < 0.0 ? -n + 0.5 * unit() : n + 0.5 * unit());
      tally->add(refraction_exit_search(ctx, h.point, in, h.object_id, off),
                 refraction_exit_search(ctx, h.point, in, h.object_id, o),
                 name + " " + ray_text("refraction", h.point, in));
      for (const PointLight& light : scene.lights) {
        tally->add(shadow_search(ctx, h.point, light.position, off), shadow_search(ctx, h.point, light.position, o),
                   name + " " + ray_text("shadow", h.point, light.position));
      }
    }
    // A random ray and segment near the centre's scene.
    const glm::dvec3 w = c + unit() * reach * pos(rng), d = unit();
    tally->add(reflection_search(ctx, w, d, off), reflection_search(ctx, w, d, o),
               name + " " + ray_text("random", w, d));
    const glm::dvec3 to = c + unit() * reach * pos(rng);
    tally->add(shadow_search(ctx, w, to, off), shadow_search(ctx, w, to, o), name + " " + ray_text("segment", w, to));
  }
}

// The scenes: the repository's, the hard-case regressions, and seeded generated ones.
// `tag` names the folder the generated scenes go to: one per test, since ctest runs the
// tests of this file in parallel processes (one folder for both: one removed it while the
// other read it, a failure seen once in a -j2 run).
std::vector<std::string> scene_files(const std::string& tag) {
  const std::string src = ABCUBE_SOURCE_DIR;
  std::vector<std::string> files;
  for (const char* s : {"default.json", "cornell.json", "hidden_point.json", "shadows.json"}) {
    files.push_back(src + "/scenes/" + s);
  }
  std::vector<std::string> more;
  for (const auto& e : fs::directory_iterator(src + "/tests/hard/regressions")) {
    if (e.path().extension() == ".json") more.push_back(e.path().string());
  }
  // tools/hard_scenes.py, seed 1414: one scene of each template.
  const std::string out = std::string(ABCUBE_BINARY_DIR) + "/test_search_hierarchy_scenes_" + tag;
  fs::remove_all(out);
  const std::string gen = "/usr/bin/python3 " + src + "/tools/hard_scenes.py --seed 1414 --count 11 --out " + out +
                          " --size 64x48 > /dev/null";
  EXPECT_EQ(std::system(gen.c_str()), 0) << gen;
  if (fs::is_directory(out)) {
    for (const auto& e : fs::directory_iterator(out)) {
      if (e.path().extension() == ".json") more.push_back(e.path().string());
    }
  }
  std::sort(more.begin(), more.end());
  files.insert(files.end(), more.begin(), more.end());
  return files;
}

// ORDER (abuffer.hpp), which the scan's z-interval test relies on to stop at the first
// fragment starting past the ray's range: every list runs by zmin after its merges.
void expect_lists_in_order(const CubeABuffer& cube, const std::string& name) {
  long out_of_order = 0;
  for (const ABuffer& face : cube.faces) {
    for (int j = 0; j < face.height(); ++j) {
      for (int i = 0; i < face.width(); ++i) {
        const FragmentList list = face.list(i, j);
        for (size_t k = 1; k < list.size(); ++k) out_of_order += list[k - 1].zmin > list[k].zmin;
      }
    }
  }
  EXPECT_EQ(out_of_order, 0) << name << ": fragments out of zmin order";
}

TEST(SearchHierarchy, SearchesGiveThePlainWalksAnswers) {
  const std::vector<std::string> files = scene_files("searches");
  EXPECT_GE(files.size(), 4u + 12u + 11u);
  Tally tally;
  unsigned seed = 1;
  for (const std::string& file : files) {
    const SceneData scene = load_scene(file);
    const RayTracer tracer(scene);
    for (const int n : {64, 100, 256}) {
      const CubeABuffer cube = build_cube_abuffer(scene, scene.camera.position, n);
      const SearchContext ctx(scene, cube);
      const std::string name = fs::path(file).filename().string() + " N=" + std::to_string(n);
      expect_lists_in_order(cube, name);
      SearchOptions o;
      compare_searches(scene, ctx, tracer, o, 60, ++seed, &tally, name + " crossing");
      if (n == 100) {
        o.mode = SearchMode::thesis;
        compare_searches(scene, ctx, tracer, o, 30, ++seed, &tally, name + " thesis");
        o = SearchOptions{};
        o.layers = SearchLayers::nearest;
        compare_searches(scene, ctx, tracer, o, 30, ++seed, &tally, name + " nearest");
        o = SearchOptions{};
        o.refine = SearchRefine::plane;
        o.side_structure = false;
        compare_searches(scene, ctx, tracer, o, 30, ++seed, &tally, name + " plane, map only");
      }
      if (tally.differ > 10) return;
    }
  }
  std::printf("searches: %ld compared, %ld differ; texels per search %.1f plain, %.1f + %.1f nodes hierarchical\n",
              tally.searches, tally.differ, static_cast<double>(tally.texels_plain) / tally.searches,
              static_cast<double>(tally.texels_hier) / tally.searches,
              static_cast<double>(tally.nodes) / tally.searches);
  EXPECT_GT(tally.searches, 10000);
  EXPECT_EQ(tally.differ, 0);
  EXPECT_GT(tally.nodes, 0u);
  EXPECT_LT(tally.texels_hier + tally.nodes, tally.texels_plain);  // the point of it
}

// ---- Whole renders ----------------------------------------------------------------------

Image render(const SceneData& s, const CubeABuffer& cube, const ABuffer& camera, bool hierarchy, MapVariant variant,
             MapShadingStats* stats, int threads = 2) {
  MapShadingOptions o;
  o.variant = variant;
  o.search.hierarchy = hierarchy;
  const MapShader shader(s, cube, o, nullptr);
  return render_with_map(s, camera, shader, threads, stats);
}

// MEMO (search_context.cpp): each thread keeps the refinement's per-triangle geometry of the
// context it searched last. A render's answers must not depend on what its thread searched
// before: the same render on a fresh thread, and on this one after a map of the same
// triangles around another centre (other values for the same triangle ids), one thread
// each, so that the calling thread does all the work.
TEST(SearchMemo, AnswersDoNotDependOnWhatTheThreadSearchedBefore) {
  SceneData s = load_scene(std::string(ABCUBE_SOURCE_DIR) + "/scenes/cornell.json");
  s.camera.width = 64;
  s.camera.height = 64;
  const ABuffer camera = build_camera_abuffer(s);
  const CubeABuffer here = build_cube_abuffer(s, s.camera.position, 96);
  const CubeABuffer there = build_cube_abuffer(s, s.camera.position + glm::dvec3(0.5, -0.3, 0.2), 96);
  MapShadingStats stats;
  Image fresh;
  std::thread([&] { fresh = render(s, here, camera, true, MapVariant::abuffer, &stats, 1); }).join();
  EXPECT_GT(stats.searches.shadow.candidates, 0u);
  const Image elsewhere = render(s, there, camera, true, MapVariant::abuffer, nullptr, 1);
  const Image after = render(s, here, camera, true, MapVariant::abuffer, nullptr, 1);
  ASSERT_EQ(fresh.data.size(), after.data.size());
  EXPECT_NE(std::memcmp(fresh.data.data(), elsewhere.data.data(), fresh.data.size() * sizeof(float)), 0);
  EXPECT_EQ(std::memcmp(fresh.data.data(), after.data.data(), fresh.data.size() * sizeof(float)), 0);
}

// Two halves of the scenes (even and odd places in scene_files' order), two ctest tests that
// run side by side: under the sanitizers this is the suite's longest test. There
// (ABCUBE_CHECKED_BUILD, tools/sanitize.sh) the images are 40 pixels wide instead of 80:
// every scene's maps, searches and shading paths still run, on a quarter of the pixels.
class SearchHierarchyRenders : public ::testing::TestWithParam<int> {};

int image_width() {
  const char* checked = std::getenv("ABCUBE_CHECKED_BUILD");
  return checked && std::string(checked) == "1" ? 40 : 80;
}

TEST_P(SearchHierarchyRenders, AreIdentical) {
  const int half = GetParam();
  const std::vector<std::string> all = scene_files("renders_" + std::to_string(half));
  EXPECT_GE(all.size(), 27u);
  std::vector<std::string> files;
  for (size_t k = static_cast<size_t>(half); k < all.size(); k += 2) files.push_back(all[k]);
  int compared = 0;
  for (const std::string& file : files) {
    SceneData s = load_scene(file);
    const double aspect = static_cast<double>(s.camera.width) / s.camera.height;
    s.camera.width = image_width();
    s.camera.height = std::max(1, static_cast<int>(s.camera.width / aspect + 0.5));
    for (const int n : {96, 200}) {
      const CubeABuffer cube = build_cube_abuffer(s, s.camera.position, n);
      const ABuffer camera = build_camera_abuffer(s);
      for (const MapVariant variant : {MapVariant::abuffer, MapVariant::zbuffer}) {
        if (variant == MapVariant::zbuffer && n != 96) continue;
        MapShadingStats plain_stats, hier_stats;
        const Image plain = render(s, cube, camera, false, variant, &plain_stats);
        const Image hier = render(s, cube, camera, true, variant, &hier_stats);
        ASSERT_EQ(plain.data.size(), hier.data.size());
        EXPECT_EQ(std::memcmp(plain.data.data(), hier.data.data(), plain.data.size() * sizeof(float)), 0)
            << file << " N=" << n << " variant " << static_cast<int>(variant) << ": the images differ";
        const SearchKindStats* a[] = {&plain_stats.searches.reflection, &plain_stats.searches.refraction_exit,
                                      &plain_stats.searches.shadow};
        const SearchKindStats* b[] = {&hier_stats.searches.reflection, &hier_stats.searches.refraction_exit,
                                      &hier_stats.searches.shadow};
        for (int k = 0; k < 3; ++k) {
          EXPECT_EQ(a[k]->rays, b[k]->rays) << file;
          EXPECT_EQ(a[k]->fragments, b[k]->fragments) << file;
          EXPECT_EQ(a[k]->candidates, b[k]->candidates) << file;
          EXPECT_EQ(a[k]->hits, b[k]->hits) << file;
          EXPECT_EQ(a[k]->misses, b[k]->misses) << file;
          EXPECT_LE(b[k]->texels, a[k]->texels) << file;
        }
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 3 * static_cast<int>(files.size()));
}

INSTANTIATE_TEST_SUITE_P(SearchHierarchyHalves, SearchHierarchyRenders, ::testing::Values(0, 1));

}  // namespace
}  // namespace abcube
