// DEFERRED SEARCHES (search/deferred_searches.hpp): a render whose searches are answered in
// batches from a scanner's candidates is the render whose searches walk the map themselves,
// bit for bit, with the CPU's scan_candidates as the scanner (the GPU's is checked against it
// in the GL tests).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "base/error.hpp"
#include "raster/abuffer.hpp"
#include "scene/scene_load.hpp"
#include "search/deferred_searches.hpp"
#include "shading/map_shading.hpp"

namespace abcube {
namespace {

// The sanitizers' builds (tools/sanitize.sh sets ABCUBE_CHECKED_BUILD).
bool checked_build() {
  const char* env = std::getenv("ABCUBE_CHECKED_BUILD");
  return env && std::string(env) == "1";
}

SceneData deferred_scene(const std::string& path, int width, int cube_n) {
  SceneData s = load_scene(std::string(ABCUBE_SOURCE_DIR) + "/" + path);
  const double aspect = static_cast<double>(s.camera.width) / s.camera.height;
  s.camera.width = width;
  s.camera.height = std::max(1, static_cast<int>(width / aspect + 0.5));
  s.render.cube_resolution = cube_n;
  return s;
}

// Every repository scene and kept hard case with mirrors, glass, nested media, shadows and
// textures, under each shading plan whose passes depend on earlier answers (the quarters split
// on the first quarters' colours, shadow and secondary edges, the sparse pass): the image and
// the searches' counts are the CPU searches', whether each batch is scanned whole or over its
// rays' first texels first (THE WINDOW).
TEST(DeferredSearches, RenderIsTheWalkedSearchesImageBitForBit) {
  std::vector<std::string> scenes = {"scenes/cornell.json",
                                     "tests/hard/regressions/nested_glass_5000_78.json",
                                     "scenes/shadows.json",
                                     "scenes/textured.json",
                                     "scenes/hidden_point.json",
                                     "tests/hard/regressions/grazing_mirror_5000_121.json",
                                     "tests/hard/regressions/light_on_surface_5000_72.json"};
  std::vector<ShadingPlan> plans = {
      ShadingPlan(),
      ShadingPlan(ShadingPoints::sparse, false, false),
      ShadingPlan(ShadingPoints::one, false, false),
  };
  // The checked builds (tools/sanitize.sh) check the code: mirrors, glass and shadows, the
  // quarters and the sparse pass, on fewer pixels.
  const bool checked = checked_build();
  if (checked) {
    scenes.resize(2);
    plans.resize(2);
  }
  uint64_t most_passes = 0, rays = 0, rescanned = 0, stopped = 0, shaded_rows = 0, pass_rows = 0, edge_rows = 0;
  for (const std::string& file : scenes) {
    const SceneData s = deferred_scene(file, checked ? 20 : 48, 40);
    const CubeABuffer cube = build_cube_abuffer(s, s.camera.position, s.render.cube_resolution);
    const ABuffer camera = build_camera_abuffer(s);
    for (const ShadingPlan& plan : plans) {
      MapShadingOptions o;
      o.plan = plan;
      const MapShader walked(s, cube, o);
      MapShadingStats walked_stats, deferred_stats;
      Image walked_fallback, deferred_fallback;  // the "fallback" AOV, kept rows and all
      const Image a = render_with_map(s, camera, walked, 2, &walked_stats, &walked_fallback);
      MapShader shader(s, cube, o);
      DeferredSearchOptions small;
      small.threads = 2;
      small.batch_rays = 97;  // many small batches
      // STOP HINTS, but in the sparse plan (whole walks).
      small.stop_hints = &plan - plans.data() != 1;
      DeferredSearches deferred(shader.context(), shader.options().search, cpu_candidate_scanner(shader.context(), 2),
                                small);
      shader.defer_searches(&deferred);
      const Image b = render_with_map(s, camera, shader, 2, &deferred_stats, &deferred_fallback);
      const DeferredSearchStats d = deferred.stats();
      const std::string what = file + " plan " + std::to_string(&plan - plans.data());
      EXPECT_EQ(a.data, b.data) << what;
      EXPECT_EQ(walked_fallback.data, deferred_fallback.data) << what;
      // The edge and sparse passes' figures, kept rows and all.
      EXPECT_EQ(walked_stats.multi_point_fragments, deferred_stats.multi_point_fragments) << what;
      EXPECT_EQ(walked_stats.shadow_edge_fragments, deferred_stats.shadow_edge_fragments) << what;
      EXPECT_EQ(walked_stats.shadow_edge_samples, deferred_stats.shadow_edge_samples) << what;
      EXPECT_EQ(walked_stats.shadow_edge_pixels, deferred_stats.shadow_edge_pixels) << what;
      EXPECT_EQ(walked_stats.secondary_edge_samples, deferred_stats.secondary_edge_samples) << what;
      EXPECT_EQ(walked_stats.secondary_edge_pixels, deferred_stats.secondary_edge_pixels) << what;
      EXPECT_EQ(walked_stats.sparse_pixels, deferred_stats.sparse_pixels) << what;
      const SearchStats &x = walked_stats.searches, &y = deferred_stats.searches;
      EXPECT_EQ(x.reflection.rays, y.reflection.rays) << what;
      EXPECT_EQ(x.reflection.hits, y.reflection.hits) << what;
      EXPECT_EQ(x.refraction_exit.rays, y.refraction_exit.rays) << what;
      EXPECT_EQ(x.shadow.rays, y.shadow.rays) << what;
      EXPECT_EQ(x.shadow.known_blockers, y.shadow.known_blockers) << what;
      EXPECT_EQ(y.reflection.texels, 0u) << what;  // no walk: candidates only
      // Every search the last pass asked was answered by a batch (the known blockers' aside).
      const uint64_t walks = x.reflection.rays + x.refraction_exit.rays + x.shadow.rays - x.shadow.known_blockers;
      EXPECT_EQ(d.answers_used, walks) << what;
      EXPECT_EQ(d.walked_now, 0u) << what;
      EXPECT_GT(d.rays, walks > 0 ? 0u : d.rays) << what;
      std::printf("[ deferred ] %s: %llu passes, %llu rays scanned, %llu answers used\n", what.c_str(),
                  static_cast<unsigned long long>(d.passes), static_cast<unsigned long long>(d.rays),
                  static_cast<unsigned long long>(walks));
      EXPECT_GE(d.passes, walks > 0 ? 2u : 1u) << what;
      // Each pass after the first shades again only the rows that took a stand-in.
      const uint64_t rows = static_cast<uint64_t>(camera.height());
      EXPECT_GE(d.rows_shaded, rows) << what;
      if (d.passes > 2) EXPECT_LT(d.rows_shaded, d.passes * rows) << what;
      shaded_rows += d.rows_shaded;
      pass_rows += d.passes * rows;
      edge_rows += d.edge_rows_shaded;
      most_passes = std::max(most_passes, d.passes);
      rescanned += d.rescanned;
      stopped += d.stopped;
      rays += d.rays;
    }
  }
  std::printf(
      "[ deferred ] %llu rays scanned, %llu ended by their stop hint, %llu of them again whole; at most %llu "
      "passes\n",
      static_cast<unsigned long long>(rays), static_cast<unsigned long long>(stopped),
      static_cast<unsigned long long>(rescanned), static_cast<unsigned long long>(most_passes));
  EXPECT_GT(rays, checked ? 1000u : 10000u);
  EXPECT_GT(stopped, rays / 10);  // STOP HINTS cut that many walks, and kept every image
  EXPECT_LT(rescanned, stopped);
  std::printf("[ deferred ] %llu rows shaded of the %llu the passes hold\n",
              static_cast<unsigned long long>(shaded_rows), static_cast<unsigned long long>(pass_rows));
  EXPECT_LT(shaded_rows, pass_rows * 3 / 4);
  // The edge and sparse passes keep the rows whose pixels, force bits and answers held.
  std::printf("[ deferred ] %llu rows with pixels shaded by the edge and sparse passes\n",
              static_cast<unsigned long long>(edge_rows));
  EXPECT_GT(edge_rows, 0u);
}

// A store with room for a few hundred rays: the searches past it are walked at once by the
// CPU, each pass, and the image is still the walked searches', bit for bit, in bounded memory.
TEST(DeferredSearches, AFullStoreWalksTheRestAndKeepsTheImage) {
  const SceneData s = deferred_scene("scenes/cornell.json", checked_build() ? 20 : 40, 32);
  const CubeABuffer cube = build_cube_abuffer(s, s.camera.position, s.render.cube_resolution);
  const ABuffer camera = build_camera_abuffer(s);
  const MapShader walked(s, cube, MapShadingOptions{});
  const Image a = render_with_map(s, camera, walked, 2, nullptr);
  MapShader shader(s, cube, MapShadingOptions{});
  DeferredSearchOptions small;
  small.max_bytes = (checked_build() ? 100 : 300) * DEFERRED_ENTRY_BYTES;
  DeferredSearches deferred(shader.context(), shader.options().search, cpu_candidate_scanner(shader.context(), 2),
                            small);
  shader.defer_searches(&deferred);
  MapShadingStats stats;
  const Image b = render_with_map(s, camera, shader, 2, &stats);
  const DeferredSearchStats d = deferred.stats();
  EXPECT_EQ(a.data, b.data);
  EXPECT_LE(d.bytes, small.max_bytes);
  EXPECT_GT(d.answers_used, 50u);
  EXPECT_GT(d.walked_now, checked_build() ? 200u : 1000u);
  const SearchStats& x = stats.searches;
  EXPECT_EQ(d.answers_used + d.walked_now,
            x.reflection.rays + x.refraction_exit.rays + x.shadow.rays - x.shadow.known_blockers);
}

// The crossing mode over all layers only: the thesis mode and the Z-buffer's nearest layer
// choose otherwise than search_from_candidates.
TEST(DeferredSearches, RefusesTheThesisModeAndTheNearestLayer) {
  const SceneData s = deferred_scene("scenes/cornell.json", 16, 8);
  const CubeABuffer cube = build_cube_abuffer(s, s.camera.position, 8);
  const MapShader shader(s, cube, MapShadingOptions{});
  SearchOptions thesis;
  thesis.mode = SearchMode::thesis;
  SearchOptions nearest;
  nearest.layers = SearchLayers::nearest;
  const CandidateScanner scanner = cpu_candidate_scanner(shader.context(), 1);
  EXPECT_THROW(DeferredSearches(shader.context(), thesis, scanner), InputError);
  EXPECT_THROW(DeferredSearches(shader.context(), nearest, scanner), InputError);
}

// A scanner that answers fewer rays than it was given is refused, not read past its end.
TEST(DeferredSearches, AScannerShortOfRaysFails) {
  const SceneData s = deferred_scene("scenes/cornell.json", 16, 8);
  const CubeABuffer cube = build_cube_abuffer(s, s.camera.position, 8);
  MapShader shader(s, cube, MapShadingOptions{});
  DeferredSearches deferred(shader.context(), shader.options().search,
                            [](const std::vector<SearchRay>& r, const SearchOptions&, const std::vector<ScanStop>&) {
                              return std::vector<CandidateScan>(r.size() / 2);
                            });
  shader.defer_searches(&deferred);
  const ABuffer camera = build_camera_abuffer(s);
  EXPECT_THROW(render_with_map(s, camera, shader, 1, nullptr), RuntimeFailure);
}

}  // namespace
}  // namespace abcube
