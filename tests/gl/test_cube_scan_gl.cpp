// The searches' candidates found on the GPU (host/gl/gl_cube_scan.hpp) against the CPU core's
// (search/search.hpp scan_candidates): the same fragments of the same texels in the same
// order, each with the same crossing test and MESH REFINEMENT, ray by ray, on every kept
// scene, for the searches' own rays (reflections, shadow segments, refraction exits
// restricted to their object), for the self offsets of both modes, and with walks the cap
// stops.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/error.hpp"
#include "gl/gl_cube_scan.hpp"
#include "gl/gl_cube_walks.hpp"
#include "gl_test_support.hpp"
#include "raster/abuffer.hpp"
#include "scene/scene_load.hpp"

namespace abcube {
namespace {

// The searches' rays of `ctx`'s scene, and as many more from random points of the scene's
// triangles in random directions, half of them restricted to the triangle's object.
// `lights` (optional): per ray, the light of a shadow segment, else -1.
std::vector<SearchRay> rays_of(const SearchContext& ctx, const SearchOptions& o, unsigned seed,
                               std::vector<int>* lights = nullptr) {
  std::vector<int> light_of;
  std::vector<SearchRay> rays = scene_search_rays(ctx, 200, o, &light_of);
  const TriangleSoup& soup = *ctx.scene().triangles;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0), s(-1.0, 1.0);
  const size_t count = rays.size();
  for (size_t k = 0; k < count && soup.triangle_count() > 0; ++k) {
    const size_t t = static_cast<size_t>(rng() % soup.triangle_count());
    double a = u(rng), b = u(rng);
    if (a + b > 1.0) a = 1.0 - a, b = 1.0 - b;
    const glm::dvec3 p0(soup.positions[3 * t]), p1(soup.positions[3 * t + 1]), p2(soup.positions[3 * t + 2]);
    const glm::dvec3 x = p0 + a * (p1 - p0) + b * (p2 - p0);
    glm::dvec3 d(s(rng), s(rng), s(rng));
    if (!(glm::length(d) > 1e-3)) continue;
    d = glm::normalize(d);
    rays.push_back(k % 2 ? refraction_exit_ray(ctx, x, d, soup.object_id[t], o) : reflection_ray(ctx, x, d, o));
    light_of.push_back(-1);
  }
  if (lights) *lights = light_of;
  return rays;
}

// Cornell's cube A-buffer at N from its camera, and its search context.
struct Cornell {
  explicit Cornell(int n)
      : scene(load_scene(std::string(ABCUBE_SOURCE_DIR) + "/scenes/cornell.json")),
        cube(build_cube_abuffer(scene, scene.camera.position, n)),
        ctx(scene, cube) {}
  const SceneData scene;
  const CubeABuffer cube;
  const SearchContext ctx;
};

size_t restricted(const std::vector<SearchRay>& rays) {
  size_t k = 0;
  for (const SearchRay& q : rays) k += q.restrict_object ? 1 : 0;
  return k;
}

std::vector<CandidateScan> cpu_scans(const SearchContext& ctx, const std::vector<SearchRay>& rays,
                                     const SearchOptions& o, const std::vector<ScanStop>& stops = {}) {
  std::vector<CandidateScan> out;
  for (size_t k = 0; k < rays.size(); ++k) {
    out.push_back(scan_candidates(ctx, rays[k], o, stops.empty() ? ScanStop::none : stops[k]));
  }
  return out;
}

// Each ray's STOP HINT as the deferred searches give it: a shadow segment's, else a crossing's.
std::vector<ScanStop> stops_of(const std::vector<int>& lights) {
  std::vector<ScanStop> stops;
  for (const int l : lights) stops.push_back(l >= 0 ? ScanStop::shadow : ScanStop::crossing);
  return stops;
}

// The answers from scans their STOP HINTS ended: each one that search_from_candidates or
// shadow_from_candidates calls complete is the walked search's (same_found). Returns how many
// were complete.
size_t expect_complete_answers(const SearchContext& ctx, const std::vector<SearchRay>& rays,
                               const std::vector<int>& lights, const SearchOptions& o,
                               const std::vector<CandidateScan>& scans, const std::string& what) {
  size_t complete_ones = 0;
  for (size_t k = 0; k < rays.size(); ++k) {
    bool complete = false;
    if (lights[k] >= 0) {
      const glm::dvec3 light = ctx.scene().lights[static_cast<size_t>(lights[k])].position;
      const ShadowResult found = shadow_from_candidates(ctx, rays[k], light, o, scans[k], &complete);
      if (complete)
        EXPECT_TRUE(same_found(shadow_along(ctx, rays[k], light, o), found)) << what << ": shadow ray " << k;
    } else {
      const SearchResult found = search_from_candidates(ctx, rays[k], o, scans[k], &complete);
      if (complete) EXPECT_TRUE(same_found(search_along(ctx, rays[k], o), found)) << what << ": ray " << k;
    }
    complete_ones += complete ? 1 : 0;
  }
  return complete_ones;
}

// The searches' answers from the GPU's candidates (search_from_candidates for reflections and
// refraction exits, shadow_from_candidates for shadow segments): each the walked search's
// (same_found). Returns the hits and the blocked segments.
size_t expect_same_answers(const SearchContext& ctx, const std::vector<SearchRay>& rays, const std::vector<int>& lights,
                           const SearchOptions& o, const std::vector<CandidateScan>& on_gpu, const std::string& what) {
  size_t found_some = 0;
  for (size_t k = 0; k < rays.size(); ++k) {
    if (lights[k] >= 0) {
      const glm::dvec3 light = ctx.scene().lights[static_cast<size_t>(lights[k])].position;
      const ShadowResult walked = shadow_along(ctx, rays[k], light, o);
      const ShadowResult found = shadow_from_candidates(ctx, rays[k], light, o, on_gpu[k]);
      EXPECT_TRUE(same_found(walked, found))
          << what << ": shadow ray " << k << " blockers " << walked.blockers << " / " << found.blockers;
      found_some += walked.blocked ? 1 : 0;
      continue;
    }
    const SearchResult walked = search_along(ctx, rays[k], o);
    const SearchResult found = search_from_candidates(ctx, rays[k], o, on_gpu[k]);
    EXPECT_TRUE(same_found(walked, found)) << what << ": ray " << k << " hit " << walked.hit << " / " << found.hit
                                           << ", triangle " << walked.triangle << " / " << found.triangle;
    found_some += walked.hit ? 1 : 0;
  }
  return found_some;
}

// Every repository scene and kept hard case (nested glass, coplanar ties, thin features,
// kilometre scales), from its camera and from a point off it, at two resolutions, with the
// crossing mode's self offset, and from the camera with the thesis mode's.
TEST(CubeScanGl, CandidatesAreTheCpusOnEveryKeptScene) {
  test::test_context();
  uint64_t candidates = 0;
  size_t restricted_rays = 0;
  // Candidates by their crossing's verdicts: untested; tested only; tested and valid or exact;
  // all three.
  std::array<uint64_t, 4> verdicts{};
  // MESH REFINEMENT: candidates refined, found crossing another triangle of the mesh, and
  // found passing the mesh by.
  uint64_t refined = 0, crossed_elsewhere = 0, passed_by = 0;
  size_t hits = 0;                               // searches answered from the GPU's candidates with a hit or a blocker
  size_t hinted = 0, stopped = 0, complete = 0;  // rays scanned with STOP HINTS, ended by one, answered
  for (const std::string& file : test::scene_files()) {
    const SceneData scene = load_scene(file);
    const std::vector<std::pair<glm::dvec3, int>> views = test::cube_views(scene);
    for (const auto& [centre, n] : views) {
      const CubeABuffer cube = build_cube_abuffer(scene, centre, n);
      const SearchContext ctx(scene, cube);
      const GlCandidateScan gpu(ctx);
      // The thesis mode's self offset from the camera's view: its scan is the crossing mode's
      // code with another offset.
      const bool camera_view = centre == views.front().first;
      for (const SearchMode mode : {SearchMode::crossing, SearchMode::thesis}) {
        if (mode == SearchMode::thesis && !camera_view) continue;
        SearchOptions o;
        o.mode = mode;
        std::vector<int> lights;
        const std::vector<SearchRay> rays = rays_of(ctx, o, static_cast<unsigned>(n), &lights);
        const std::vector<CandidateScan> cpu = cpu_scans(ctx, rays, o);
        const std::vector<CandidateScan> on_gpu = gpu.scan(rays, o);
        const CandidateComparison c = compare_candidate_scans(cpu, on_gpu);
        const std::string what = std::filesystem::path(file).filename().string() + " at N = " + std::to_string(n) +
                                 " (" + search_mode_name(mode) + ")";
        EXPECT_EQ(c.identical, rays.size()) << what << ": " << c.example;
        candidates += c.candidates;
        restricted_rays += restricted(rays);
        if (mode == SearchMode::crossing) {
          hits += expect_same_answers(ctx, rays, lights, o, on_gpu, what);
          // STOP HINTS: the same cut scans as the CPU's, and their complete answers the walked.
          const std::vector<ScanStop> stops = stops_of(lights);
          const std::vector<CandidateScan> cut = gpu.scan(rays, o, {}, stops);
          const CandidateComparison h = compare_candidate_scans(cpu_scans(ctx, rays, o, stops), cut);
          EXPECT_EQ(h.identical, rays.size()) << what << " (stop hints): " << h.example;
          for (const CandidateScan& x : cut) stopped += x.stopped ? 1 : 0;
          hinted += rays.size();
          complete += expect_complete_answers(ctx, rays, lights, o, cut, what + " (stop hints)");
        }
        for (const CandidateScan& scan : cpu) {
          for (const ScanCandidate& x : scan.candidates) {
            ++verdicts[(x.tested ? 1 : 0) + (x.exact ? 1 : 0) + (x.valid ? 1 : 0)];
            const uint32_t own = cube.faces[x.face].fragments[x.fragment].triangle();
            refined += x.mesh_triangles > 0 ? 1 : 0;
            crossed_elsewhere += x.valid && x.triangle != own ? 1 : 0;
            passed_by += x.mesh_triangles > 0 && std::isinf(x.outside) ? 1 : 0;
          }
        }
      }
    }
  }
  EXPECT_GT(candidates, 10000u);
  EXPECT_GT(restricted_rays, 1000u);
  for (const uint64_t v : verdicts) EXPECT_GT(v, 100u);
  EXPECT_GT(refined, 1000u);
  EXPECT_GT(crossed_elsewhere, 100u);
  EXPECT_GT(passed_by, 100u);
  EXPECT_GT(hits, test::checked_build() ? 2000u : 5000u);  // the checked builds: fewer scenes
  std::printf("[ stop hints ] %zu rays: %zu scans ended early, %zu answers complete\n", hinted, stopped, complete);
  EXPECT_GT(stopped, hinted / 4);
  EXPECT_GT(complete, hinted * 9 / 10);
}

// Walks the cap stops (the candidates up to it); the work cut in batches of a few rays, each
// first given room for one candidate (so that each pass runs again); walks of no texel at all
// (segments inside the ball the map does not hold) among the others, and a batch of them alone.
TEST(CubeScanGl, CappedWalksSmallBatchesAndEmptyWalksAsTheCpu) {
  test::test_context();
  const Cornell cornell(32);
  const SearchContext& ctx = cornell.ctx;
  const GlCandidateScan gpu(ctx);
  SearchOptions o;
  o.max_texels = 6;
  const std::vector<SearchRay> rays = rays_of(ctx, o, 7);
  std::vector<CandidateScan> cpu = cpu_scans(ctx, rays, o);
  CandidateComparison c = compare_candidate_scans(cpu, gpu.scan(rays, o));
  EXPECT_EQ(c.identical, rays.size()) << c.example;
  size_t aborted = 0;
  for (const CandidateScan& s : cpu) aborted += s.aborted ? 1 : 0;
  EXPECT_GT(aborted, rays.size() / 2);
  EXPECT_GT(c.candidates, 0u);

  std::vector<SearchRay> mixed = scene_search_rays(ctx, 64);
  const glm::dvec3 centre = ctx.cube().centre;
  const double inside = 0.25 * ctx.cube().near_distance;
  SearchRay empty;
  ASSERT_TRUE(shadow_ray(ctx, centre + glm::dvec3(inside, 0, 0), centre + glm::dvec3(0, inside, 0), {}, &empty));
  for (size_t k = 0; k < mixed.size(); k += 5) mixed.insert(mixed.begin() + static_cast<std::ptrdiff_t>(k), empty);
  cpu = cpu_scans(ctx, mixed, {});
  ScanBatching small;
  small.batch_bytes = 2048;  // 64 texels
  small.first_room = 1;
  c = compare_candidate_scans(cpu, gpu.scan(mixed, {}, small));
  EXPECT_EQ(c.identical, mixed.size()) << c.example;
  EXPECT_EQ(cpu[0].texels, 0u);
  EXPECT_GT(c.candidates, mixed.size());
  c = compare_candidate_scans(cpu_scans(ctx, {empty, empty}, {}), gpu.scan({empty, empty}, {}, small));
  EXPECT_EQ(c.identical, 2u) << c.example;
  EXPECT_TRUE(gpu.scan({}).empty());

  // The rays past the loop budget of the scan that walks go through the walks left on the GPU:
  // every ray (budget 0), and some (a budget a few texels' worth), with and without STOP HINTS.
  std::vector<int> lights;
  const std::vector<SearchRay> searches = rays_of(ctx, {}, 11, &lights);
  for (const uint32_t budget : {0u, 400u}) {
    for (const bool hints : {false, true}) {
      const std::vector<ScanStop> stops = hints ? stops_of(lights) : std::vector<ScanStop>{};
      ScanBatching b;
      b.loop_budget = budget;
      const std::vector<CandidateScan> on_gpu = gpu.scan(searches, {}, b, stops);
      // A ray walked first is scanned whole: the CPU's hinted scan where the GPU's stopped.
      const std::vector<CandidateScan> whole = cpu_scans(ctx, searches, {}), cut = cpu_scans(ctx, searches, {}, stops);
      std::vector<CandidateScan> expected;
      size_t stopped = 0;
      for (size_t k = 0; k < searches.size(); ++k) {
        expected.push_back(on_gpu[k].stopped ? cut[k] : whole[k]);
        stopped += on_gpu[k].stopped ? 1 : 0;
      }
      if (budget == 0 || !hints) EXPECT_EQ(stopped, 0u);
      if (budget > 0 && hints) EXPECT_GT(stopped, 0u);
      c = compare_candidate_scans(expected, on_gpu);
      EXPECT_EQ(c.identical, searches.size()) << "budget " << budget << (hints ? " with hints: " : ": ") << c.example;
    }
  }
}

TEST(CubeScanGl, RefusesTheNearestLayerAndCapsAboveTheGpusBound) {
  test::test_context();
  const Cornell cornell(16);
  const SearchContext& ctx = cornell.ctx;
  const GlCandidateScan gpu(ctx);
  const std::vector<SearchRay> rays = scene_search_rays(ctx, 4);
  ASSERT_FALSE(rays.empty());
  SearchOptions nearest;
  nearest.layers = SearchLayers::nearest;
  EXPECT_THROW(gpu.scan(rays, nearest), InputError);
  SearchOptions capped;
  capped.max_texels = GPU_WALK_MAX_TEXELS + 1;
  EXPECT_THROW(gpu.scan(rays, capped), InputError);
}

// compare_candidate_scans' classes: an l or outside moved by an ulp is within rounding; a
// candidate missing, moved to another texel or fragment, or with another verdict, or the
// walk's length or cap differing, is a ray differing; each named.
TEST(CubeScanGl, ComparisonNamesTheFirstDifference) {
  const Cornell cornell(16);
  const SearchContext& ctx = cornell.ctx;
  const std::vector<SearchRay> rays = scene_search_rays(ctx, 64);
  const std::vector<CandidateScan> cpu = cpu_scans(ctx, rays, {});
  CandidateComparison c = compare_candidate_scans(cpu, cpu);
  EXPECT_EQ(c.identical, cpu.size());
  EXPECT_TRUE(c.example.empty());
  size_t k = 0;  // a ray with two candidates at least, the first tested
  while (k < cpu.size() && (cpu[k].candidates.size() < 2 || !cpu[k].candidates[0].tested)) ++k;
  ASSERT_LT(k, cpu.size());
  const auto differs = [&](std::vector<CandidateScan> other, const std::string& expected) {
    const CandidateComparison d = compare_candidate_scans(cpu, other);
    EXPECT_EQ(d.differing, 1u) << expected;
    EXPECT_EQ(d.identical, cpu.size() - 1) << expected;
    EXPECT_NE(d.example.find("ray " + std::to_string(k) + ": "), std::string::npos) << d.example;
    EXPECT_NE(d.example.find(expected), std::string::npos) << d.example;
  };
  std::vector<CandidateScan> other = cpu;
  other[k].candidates.erase(other[k].candidates.begin() + 1);
  differs(other, "candidate 1: ");
  other = cpu;
  other[k].candidates[1].texel += 1;
  differs(other, "candidate 1: texel");
  other = cpu;
  other[k].candidates[0].fragment += 1;
  differs(other, "candidate 0: ");
  other = cpu;
  other[k].candidates[0].valid = !other[k].candidates[0].valid;
  differs(other, "candidate 0: ");
  other = cpu;
  other[k].candidates[0].l = std::nextafter(other[k].candidates[0].l, 0.0);
  c = compare_candidate_scans(cpu, other);
  EXPECT_EQ(c.within_rounding, 1u);
  EXPECT_EQ(c.differing, 0u);
  EXPECT_NE(c.example.find("ray " + std::to_string(k) + " (within rounding): "), std::string::npos) << c.example;
  other = cpu;
  other[k].aborted = !other[k].aborted;
  differs(other, "(aborted)");
  other = cpu;
  other.pop_back();
  k = cpu.size() - 1;
  differs(other, "missing from the second set");
}

}  // namespace
}  // namespace abcube
