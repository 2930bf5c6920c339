// `abcube crosscheck`'s comparisons of the searches (crosscheck.hpp): the GPU's candidates
// against the CPU's scan, the answers made from them against the CPU's searches, and the
// image shaded with them against the image shaded with the CPU's searches.
#include <algorithm>
#include <cmath>

#include "base/timer.hpp"
#include "gl/gl_cube_scan.hpp"
#include "gl/gl_cube_walks.hpp"
#include "io/image_io.hpp"
#include "raster/abuffer.hpp"
#include "render/crosscheck.hpp"
#include "search/deferred_searches.hpp"
#include "search/search.hpp"
#include "shading/map_shading.hpp"

namespace abcube {

namespace {

// The searches' answers along `rays` (a shadow segment's light in `lights`, else -1) from the
// GPU's candidates, against the CPU's searches.
void compare_answers(const SearchContext& ctx, const std::vector<SearchRay>& rays, const std::vector<int>& lights,
                     const std::vector<CandidateScan>& gpu, CrosscheckResult::Answers* a) {
  const auto tally = [&](bool same, bool found, size_t k, const std::string& walked, const std::string& listed) {
    ++a->rays;
    a->found += found ? 1 : 0;
    if (same) {
      ++a->same;
    } else if (a->example.empty()) {
      a->example =
          "ray " + std::to_string(k) + ": the CPU's search " + walked + ", from the GPU's candidates " + listed;
    }
  };
  const auto hit = [](const SearchResult& r) {
    return r.hit ? "hits triangle " + std::to_string(r.triangle) : std::string("misses");
  };
  const auto shadow = [](const ShadowResult& r) { return std::to_string(r.blockers) + " blockers"; };
  for (size_t k = 0; k < rays.size(); ++k) {
    if (lights[k] >= 0) {
      const glm::dvec3 light = ctx.scene().lights[static_cast<size_t>(lights[k])].position;
      const ShadowResult walked = shadow_along(ctx, rays[k], light);
      const ShadowResult found = shadow_from_candidates(ctx, rays[k], light, {}, gpu[k]);
      tally(same_found(walked, found), found.blocked, k, shadow(walked), shadow(found));
    } else {
      const SearchResult walked = search_along(ctx, rays[k]);
      const SearchResult found = search_from_candidates(ctx, rays[k], {}, gpu[k]);
      tally(same_found(walked, found), found.hit, k, hit(walked), hit(found));
    }
  }
}

// The GPU's candidates for the searches' rays (scene_search_rays, from up to
// CROSSCHECK_WALK_TRIANGLES triangles) in `cube` against the CPU's, ray by ray.
void compare_candidates(const SceneData& scene, const CubeABuffer& cube, CrosscheckResult* r) {
  if (!gpu_walks_at(cube.n)) return;  // compare_cube_walks says why
  const SearchContext ctx(scene, cube);
  std::vector<int> lights;
  const std::vector<SearchRay> rays = scene_search_rays(ctx, CROSSCHECK_WALK_TRIANGLES, {}, &lights);
  std::vector<CandidateScan> cpu;
  for (const SearchRay& q : rays) cpu.push_back(scan_candidates(ctx, q));
  try {
    const Clock::time_point t0 = Clock::now();
    const std::vector<CandidateScan> gpu = GlCandidateScan(ctx).scan(rays);
    r->gpu_candidates_ms = ms_since(t0);
    r->candidates = compare_candidate_scans(cpu, gpu);
    compare_answers(ctx, rays, lights, gpu, &r->answers);
  } catch (const RuntimeFailure& e) {  // a list or a buffer beyond what the GL's scan takes
    r->candidates_skipped = std::string("not compared: ") + e.what();
  }
}

// The camera's image CROSSCHECK_IMAGE_WIDTH pixels wide (its aspect kept), shaded over the
// CPU's cube A-buffer twice: with the CPU's searches, and with the searches' candidates
// found on the GPU (DEFERRED SEARCHES, as gpu_abuffer --search-on gpu renders).
constexpr int CROSSCHECK_IMAGE_WIDTH = 64;
void compare_search_images(const SceneData& scene, const CubeABuffer& cube, int threads, CrosscheckResult* r) {
  if (!gpu_walks_at(cube.n) || !r->candidates_skipped.empty()) return;  // the candidates say why
  SceneData small = scene;
  small.camera.width = std::min(scene.camera.width, CROSSCHECK_IMAGE_WIDTH);
  small.camera.height =
      std::max(1, static_cast<int>(std::lround(static_cast<double>(scene.camera.height) * small.camera.width /
                                               static_cast<double>(scene.camera.width))));
  const ABuffer camera = build_camera_abuffer(small);
  const Clock::time_point t0 = Clock::now();
  const MapShader walked(small, cube, MapShadingOptions{});
  const Image cpu = render_with_map(small, camera, walked, threads, nullptr);
  MapShader shader(small, cube, MapShadingOptions{});
  const GlCandidateScan scan(shader.context());
  DeferredSearchOptions d;
  d.threads = threads;
  DeferredSearches deferred(
      shader.context(), shader.options().search,
      [&scan](const std::vector<SearchRay>& rays, const SearchOptions& o, const std::vector<ScanStop>& stops) {
        return scan.scan(rays, o, {}, stops);
      },
      d);
  shader.defer_searches(&deferred);
  const Image gpu = render_with_map(small, camera, shader, threads, nullptr);
  CrosscheckResult::SearchImages& c = r->search_images;
  c.width = small.camera.width, c.height = small.camera.height;
  c.ms = ms_since(t0);
  c.passes = deferred.stats().passes;
  c.same_bytes = cpu.data == gpu.data;
  const size_t channels = static_cast<size_t>(std::min(cpu.channels, 3));
  for (size_t p = 0; p < static_cast<size_t>(c.width) * static_cast<size_t>(c.height); ++p) {
    double most = 0;
    for (size_t k = 0; k < channels; ++k) {
      const auto encoded = [&](const Image& i) {
        return srgb_encode(std::clamp(i.data[p * static_cast<size_t>(i.channels) + k], 0.f, 1.f));
      };
      most = std::max(most, std::fabs(static_cast<double>(encoded(cpu)) - encoded(gpu)));
    }
    c.max_diff = std::max(c.max_diff, most);
    c.differing += most > 1.0 / 255.0 ? 1 : 0;
  }
}

}  // namespace

void compare_searches(const SceneData& scene, const CubeABuffer& cube, int threads, CrosscheckResult* r) {
  compare_candidates(scene, cube, r);
  compare_search_images(scene, cube, threads, r);
}

nlohmann::json search_candidates_json(const CrosscheckResult& r) {
  using nlohmann::json;
  const CrosscheckResult::SearchImages& i = r.search_images;
  return json{{"rays", r.candidates.rays},
              {"identical", r.candidates.identical},
              {"within_rounding", r.candidates.within_rounding},
              {"differing", r.candidates.differing},
              {"candidates", r.candidates.candidates},
              {"first_not_identical", r.candidates.example},
              {"not_compared", r.walks_skipped.empty() ? r.candidates_skipped : r.walks_skipped},
              {"gpu_ms", r.gpu_candidates_ms},
              {"answers",
               {{"rays", r.answers.rays},
                {"same", r.answers.same},
                {"hits_or_blocked", r.answers.found},
                {"first_not_same", r.answers.example}}},
              {"image",
               {{"width", i.width},
                {"height", i.height},
                {"passes", i.passes},
                {"same_bytes", i.same_bytes},
                {"pixels_over_1_255", i.differing},
                {"max_diff_srgb", i.max_diff},
                {"ms", i.ms}}}};
}

}  // namespace abcube
